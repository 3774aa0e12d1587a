"""Vectorised evaluation of .vdsh streams: distances and shadows of many
vertices toward many lights at once, the same numbers as the C library.

Every function here computes in float32 with the operations of the C path
in the same order (formats/vdsh_sh.c: the closed forms of bands 0-4 and
the recurrence of bands 5-15; formats/vdsh_shadow.c: the sum, the
quantity, the clamp to max_distance, the comparison), so results equal
vdsh-eval's and the runtime's reference to the bit, but for exp: taken in
float64 and rounded to float32, it is glibc's expf but for about 1 value
in 2,500, one unit in the last place apart (tests/test_python_eval.py
counts them); numpy's own float32 exp differs in about a third.

    import vdsh
    f = vdsh.read("room.vdsh")
    s = f.streams[-1]
    lights = [[0, 3, 0], [2, 1, -4]]                  # L x 3, scene units
    d = vdsh.distances(f, s, lights)                  # V x L: distance toward each light
    v = vdsh.shadows(f, s, lights)                    # V x L: visibility in [0, 1]
    v = vdsh.shadows(f, s, lights, vertices=[0, 7])   # only those vertices
    t = vdsh.distances_toward(f, s, dirs)             # V x N toward unit directions
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Dict, Optional, Sequence, Union

import numpy as np

if TYPE_CHECKING:  # pragma: no cover
    from . import VdshFile

Stream = Dict[str, Any]
ArrayLike = Union[np.ndarray, Sequence[Sequence[float]], Sequence[float]]

# formats/vdsh_sh.h's constants: K_l^m with sqrt(2) folded in for m != 0.
_F = np.float32
C00, C1, C2A = _F(0.28209479177387814), _F(0.4886025119029199), _F(1.0925484305920792)
C20, C22, C33 = _F(0.31539156525252005), _F(0.5462742152960396), _F(0.5900435899266435)
C32, C31, C30 = _F(2.890611442640554), _F(0.4570457994644658), _F(0.3731763325901154)
C32B, C44, C43 = _F(1.445305721320277), _F(2.5033429417967046), _F(1.7701307697799304)
C42, C41, C40 = _F(0.9461746957575601), _F(0.6690465435572892), _F(0.10578554691520431)
C42B, C44B = _F(0.47308734787878004), _F(0.6258357354491761)
KERNEL_ORDER = 5
MAX_ORDER = 16
LOG_SUM_MAX = _F(80.0)
RAMP_SLOPE, RAMP_OFFSET = _F(1.5), _F(0.5)
COMPARES = ("smooth", "binary")
# Methods whose streams are compared with a light's distance (VDSH.md:
# paper, full, mirror, lsq, shadow, decision); a later method's must not be.
KNOWN_METHODS = 6
# Pairs of one block: Y holds order^2 x BLOCK float32 values.
_BLOCK_VALUES = 1 << 22


def _k_high() -> np.ndarray:
    """K_l^m of bands 5.. (sqrt(2) folded in for m != 0), index l(l+1)+m,
    computed in double as vdsh_sh.c's k_high_init, then rounded to f32."""
    k = np.zeros(MAX_ORDER * MAX_ORDER, np.float32)
    for l in range(KERNEL_ORDER, MAX_ORDER):
        for m in range(l + 1):
            kk = (2.0 * l + 1.0) / (4.0 * 3.14159265358979323846)
            for f in range(l - m + 1, l + m + 1):
                kk /= f
            k[l * (l + 1) + m] = np.float32(math.sqrt(2.0 * kk if m else kk))
    return k


_K_HIGH = _k_high()


def _sh_rows(order: int, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """order^2 x N float32: Y_i at directions (x, y, z) (float32 arrays),
    each value computed with vdsh_sh.c's operations in its order."""
    n = order * order
    out = np.empty((n, x.shape[0]), np.float32)
    out[0] = C00
    if order >= 2:
        out[1] = -C1 * y
        out[2] = C1 * z
        out[3] = -C1 * x
    if order >= 3:
        x2, y2, z2 = x * x, y * y, z * z
        out[4] = C2A * x * y
        out[5] = -C2A * y * z
        out[6] = C20 * (_F(3) * z2 - _F(1))
        out[7] = -C2A * x * z
        out[8] = C22 * (x2 - y2)
    if order >= 4:
        out[9] = -C33 * y * (_F(3) * x2 - y2)
        out[10] = C32 * x * y * z
        out[11] = -C31 * y * (_F(5) * z2 - _F(1))
        out[12] = C30 * z * (_F(5) * z2 - _F(3))
        out[13] = -C31 * x * (_F(5) * z2 - _F(1))
        out[14] = C32B * z * (x2 - y2)
        out[15] = -C33 * x * (x2 - _F(3) * y2)
    if order >= 5:
        out[16] = C44 * x * y * (x2 - y2)
        out[17] = -C43 * y * z * (_F(3) * x2 - y2)
        out[18] = C42 * x * y * (_F(7) * z2 - _F(1))
        out[19] = -C41 * y * z * (_F(7) * z2 - _F(3))
        out[20] = C40 * (_F(35) * z2 * z2 - _F(30) * z2 + _F(3))
        out[21] = -C41 * x * z * (_F(7) * z2 - _F(3))
        out[22] = C42B * (x2 - y2) * (_F(7) * z2 - _F(1))
        out[23] = -C43 * x * z * (x2 - _F(3) * y2)
        out[24] = C44B * (x2 * x2 - _F(6) * x2 * y2 + y2 * y2)
    if order > KERNEL_ORDER:
        # Bands 5..order-1: Y_l^m = K P_l^m(z) (Re or Im (x + iy)^m), P
        # without its (1 - z^2)^(m/2) factor (vdsh_sh.c, eval_high_bands).
        c = np.ones_like(x)
        sn = np.zeros_like(x)
        pmm = np.ones_like(x)
        for m in range(order):
            if m > 0:
                c, sn = x * c - y * sn, x * sn + y * c
                pmm = pmm * -_F(2 * m - 1)
            p0 = p1 = None
            for l in range(m, order):
                if l == m:
                    pl = pmm
                elif l == m + 1:
                    pl = z * _F(2 * m + 1) * pmm
                else:
                    a = _F(2 * l - 1) / _F(l - m)
                    b = _F(l + m - 1) / _F(l - m)
                    pl = a * z * p1 - b * p0
                p0, p1 = p1, pl
                if l < KERNEL_ORDER:
                    continue
                K = _K_HIGH[l * (l + 1) + m]
                if m == 0:
                    out[l * (l + 1)] = K * p1
                else:
                    kp = K * p1
                    out[l * (l + 1) + m] = kp * c
                    out[l * (l + 1) - m] = kp * sn
    return out


def sh_eval(order: int, dirs: ArrayLike) -> np.ndarray:
    """N x order^2 float32: the real SH basis (VDSH.md, Conventions) at
    directions `dirs` (N x 3, unit length; not normalised here), orders
    1..16, equal to formats/vdsh_sh.c's vdsh_sh_eval to the bit.
    `sh_basis` is the same functions in float64."""
    if not 1 <= order <= MAX_ORDER:
        raise ValueError("order %d: must be 1..%d" % (order, MAX_ORDER))
    d = np.asarray(dirs, np.float32).reshape(-1, 3)
    return _sh_rows(order, d[:, 0].copy(), d[:, 1].copy(), d[:, 2].copy()).T


def vertex_orders(stream: Stream) -> np.ndarray:
    """Each row's order (ints): the stream's order, or for a variable-order
    stream (VDSH.md) each vertex's own."""
    if stream["variable_order"]:
        return stream["orders"]
    return np.full(len(stream["stored"]), stream["order"], np.int64)


def _decoded(stream: Stream, offset: float) -> np.ndarray:
    """V x n^2 float32 coefficients, with vdsh-eval's --offsets rule for a
    log offset (c0 += offset / Y00 for log-distance; every coefficient
    times exp(offset), exp(2 offset) for distance2), in float32 as there."""
    from . import coefficients
    c = coefficients(stream)
    if offset == 0:
        return c
    c = c.copy()
    off = _F(offset)
    if stream["quantity"] == "log-distance":
        c[:, 0] += off / C00
    else:
        x = _F(2) * off if stream["quantity"] == "distance2" else off
        c *= _F(math.exp(float(x)))  # expf's value (see _from_sum)
    return c


def _from_sum(quantity: str, max_distance: np.float32, s: np.ndarray) -> np.ndarray:
    """The quantity's distance from SH sums, clamped to [0, max_distance]
    (vdsh_shadow.c, from_sum)."""
    with np.errstate(over="ignore", invalid="ignore"):
        if quantity == "distance2":
            d = np.where(s > 0, np.sqrt(np.where(s > 0, s, _F(0))), _F(0))
        elif quantity == "log-distance":
            # in float64, then rounded: glibc's expf is within 0.502 units
            # in the last place, so this is its value but for about 1 in
            # 2,500; numpy's own float32 exp differs in about a third
            d = np.exp(np.where(s < LOG_SUM_MAX, s, LOG_SUM_MAX).astype(np.float64))
            d = d.astype(np.float32)
        else:
            d = np.where(s > 0, s, _F(0))
    return np.where(d > max_distance, max_distance, d).astype(np.float32)


def _rows(f: "VdshFile", stream: Stream, vertices: Optional[ArrayLike]) -> tuple:
    """(vertex indices, stream rows) for `vertices` (None: every vertex the
    stream holds; a part's: its range's)."""
    from . import VdshError
    begin = f.part["range_begin"] if f.part else 0
    rows_held = len(stream["stored"])
    if vertices is None:
        v = np.arange(begin, begin + rows_held)
    else:
        v = np.asarray(vertices, np.int64).reshape(-1)
    r = v - begin
    bad = (r < 0) | (r >= rows_held)
    if bad.any():
        raise VdshError("vertex %d: not in the file's streams%s" % (
            int(v[np.argmax(bad)]), " (a part: receivers %d..%d)" % (
                f.part["range_begin"], f.part["range_end"]) if f.part else ""))
    return v, r


def _sums(order_of_rows: np.ndarray, c: np.ndarray, rows: np.ndarray,
          dx: np.ndarray, dy: np.ndarray, dz: np.ndarray) -> np.ndarray:
    """SH sums (float32, R x N) of rows `rows` of `c` toward directions
    (R x N arrays each), each row with its own order, summed in index
    order as vdsh_sh_reconstruct does."""
    R, N = dx.shape
    out = np.zeros((R, N), np.float32)
    orders = order_of_rows[rows]
    for k in np.unique(orders):
        k = int(k)
        n = k * k
        idx = np.nonzero(orders == k)[0]
        per = max(1, _BLOCK_VALUES // (n * max(N, 1)))  # rows per block
        for b0 in range(0, len(idx), per):
            ib = idx[b0:b0 + per]
            y = _sh_rows(k, dx[ib].reshape(-1), dy[ib].reshape(-1), dz[ib].reshape(-1))
            y = y.reshape(n, len(ib), N)
            cb = c[rows[ib]]
            s = np.zeros((len(ib), N), np.float32)
            for i in range(n):
                s += cb[:, i:i + 1] * y[i]
            out[ib] = s
    return out


def distances_toward(f: "VdshFile", stream: Stream, dirs: ArrayLike,
                     vertices: Optional[ArrayLike] = None, offset: float = 0.0) -> np.ndarray:
    """Distances (float32, V x N) the stream reconstructs at each vertex
    toward directions `dirs`: N x 3 shared by every vertex, or V x N x 3,
    one set per vertex (unit length; used as given, as
    vdsh_stream_distance does). `vertices`: indices into the file (None:
    all the stream holds); `offset`: a log offset as vdsh-eval --offsets
    adds. A variable-order stream evaluates each vertex at its own order."""
    v, r = _rows(f, stream, vertices)
    d = np.asarray(dirs, np.float32)
    if d.ndim == 2:
        d = np.broadcast_to(d[None], (len(v),) + d.shape)
    if d.ndim != 3 or d.shape[0] != len(v) or d.shape[2] != 3:
        raise ValueError("dirs: N x 3 or V x N x 3 (V = %d vertices)" % len(v))
    s = _sums(vertex_orders(stream), _decoded(stream, offset), r,
              np.ascontiguousarray(d[..., 0]), np.ascontiguousarray(d[..., 1]),
              np.ascontiguousarray(d[..., 2]))
    return _from_sum(stream["quantity"], _F(f.header["max_distance"]), s)


def _toward_lights(f: "VdshFile", v: np.ndarray, lights: ArrayLike) -> tuple:
    """Unit directions (3 arrays, V x L) and distances (V x L) from the
    vertices to the lights, in float32 as vdsh_shadow.c's toward()."""
    L = np.asarray(lights, np.float32)
    if L.size % 3 or (L.ndim > 1 and L.shape[-1] != 3) or L.ndim > 2:
        raise ValueError("lights: positions x, y, z (L x 3), not an array of shape %s"
                         % (L.shape,))
    L = L.reshape(-1, 3)
    p = f.positions[v]
    vx = L[None, :, 0] - p[:, 0:1]
    vy = L[None, :, 1] - p[:, 1:2]
    vz = L[None, :, 2] - p[:, 2:3]
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        dl = np.sqrt(vx * vx + vy * vy + vz * vz)
        pos = dl > 0
        safe = np.where(pos, dl, _F(1))
        dx, dy, dz = (np.where(pos, a / safe, _F(0)) for a in (vx, vy, vz))
    return dx, dy, dz, dl


def distances(f: "VdshFile", stream: Stream, lights: ArrayLike,
              vertices: Optional[ArrayLike] = None, offset: float = 0.0) -> np.ndarray:
    """Distances (float32, V x L) each vertex's stream reconstructs toward
    each light position (L x 3, scene units) from the vertex's position:
    vdsh_vertex_distance, 0 for a light at the vertex. `vertices`, `offset`
    as in distances_toward."""
    v, r = _rows(f, stream, vertices)
    dx, dy, dz, dl = _toward_lights(f, v, lights)
    s = _sums(vertex_orders(stream), _decoded(stream, offset), r, dx, dy, dz)
    d = _from_sum(stream["quantity"], _F(f.header["max_distance"]), s)
    return np.where(dl > 0, d, _F(0))


def compare(d_vis: ArrayLike, d_light: ArrayLike, compare: str = "smooth") -> np.ndarray:
    """Visibility (float32) of lights at distance d_light where the stream
    reconstructs d_vis (vdsh_shadow_compare): smooth, the paper's ramp
    saturate(1.5 d_vis / d_light - 0.5), +inf d_vis visible; binary,
    d_vis >= d_light. A light at the receiver (d_light = 0) is visible; NaN
    gives 0."""
    if compare not in COMPARES:
        raise ValueError("compare %r: one of %s" % (compare, ", ".join(COMPARES)))
    dv = np.asarray(d_vis, np.float32)
    dl = np.asarray(d_light, np.float32)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        if compare == "binary":
            s = np.where(dv >= dl, _F(1), _F(0))
        else:
            x = RAMP_SLOPE * (dv / np.where(dl > 0, dl, _F(1))) - RAMP_OFFSET
            s = np.fmin(np.fmax(x, _F(0)), _F(1))  # fmax: NaN gives 0, as vdsh_ramp
            inf = np.isposinf(dv)
            if inf.any():
                s = np.where(inf, _F(1), s)
    if (dl > 0).all():
        return s.astype(np.float32, copy=False)
    return np.where(dl > 0, s, np.where(dl == 0, _F(1), _F(0))).astype(np.float32)


def shadows(f: "VdshFile", stream: Stream, lights: ArrayLike,
            vertices: Optional[ArrayLike] = None, compare_with: str = "smooth",
            offset: float = 0.0) -> np.ndarray:
    """Visibility (float32 in [0, 1], V x L) of each light (L x 3, scene
    units) at each vertex: vdsh_shadow, the distance toward the light
    compared with the light's (`compare_with`: "smooth", the paper's ramp,
    or "binary"). A stream of a method this reader does not know is
    refused (VDSH.md: a reader must not guess how to compare it)."""
    from . import VdshError
    if stream["method_id"] >= KNOWN_METHODS:
        raise VdshError("stream of order %d: method %d unknown; its distances can be "
                        "read (distances), not compared" % (stream["order"], stream["method_id"]))
    v, r = _rows(f, stream, vertices)
    dx, dy, dz, dl = _toward_lights(f, v, lights)
    s = _sums(vertex_orders(stream), _decoded(stream, offset), r, dx, dy, dz)
    d = _from_sum(stream["quantity"], _F(f.header["max_distance"]), s)
    return compare(np.where(dl > 0, d, _F(0)), dl, compare_with)
