"""vdsh - read and validate .vdsh files, written from formats/VDSH.md alone.

    import vdsh
    f = vdsh.read("room.vdsh")          # raises vdsh.VdshError naming the problem
    f.header["vertex_count"], f.positions (V x 3), f.normals, f.triangles (T x 3)
    s = f.streams[0]                   # dict: order, encoding, method, quantity, ...
    c = vdsh.coefficients(s)           # V x order^2 float32 (stored x scale;
                                       # s8, s8s6: stored x float32(scale_i / levels_i))
    s["cpca"]                          # a cpca stream (VDSH.md "cpca streams"): dict clusters,
                                       # basis, bits (0: a width per vector), bases_s8 (the
                                       # bases stored s8, else f16), record_words,
                                       # widths (B ints), scales (K x B), means
                                       # (K x n^2), bases (K x B x n^2) float32, cluster (V),
                                       # levels (V x B ints); c is decoded as vdsh.c does
    s["variable_order"], s["orders"]   # a variable-order stream (VDSH.md): each vertex's
                                       # order (V ints, 1..order); c is 0 past it
    d = vdsh.reconstruct(f, s, v, dirs)    # distances of vertex v toward unit dirs (N x 3)
    f.part                             # None, or a part of a sharded bake (VDSH.md "Parts"):
                                       # dict index, count, range_begin, range_end, encoding;
                                       # its streams hold rows range_begin..range_end - 1 only
    f.adaptive                         # None, or what refined adaptive receivers (`adpt`):
                                       # dict tolerance, min_edge, max_receivers, lights,
                                       # max_rounds, start_receivers, rounds, candidates
    f.light_pool                       # None, or a cpca part's light pool (`lpol`): dict
                                       # mix (the light mix, 0 < mix <= 1), lights (L x 3),
                                       # margin (--cpca margin:S, 0: none), starts (0: one)
    f.light_region                     # None, or where the bake's lights went (`lreg`,
                                       # vdsh-bake --light-region): dict rule ("grown" or
                                       # "box"), min, max (3 floats each, scene units)

Evaluation, vectorised over vertices and lights (vdsh.evaluate; float32,
the C library's numbers to the bit):

    L = [[0, 3, 0], [2, 1, -4]]        # light positions, L x 3
    d = vdsh.distances(f, s, L)        # V x L distances toward each light
    v = vdsh.shadows(f, s, L)          # V x L visibility in [0, 1] (smooth ramp;
                                       # compare_with="binary": 0 or 1)
    t = vdsh.distances_toward(f, s, dirs, vertices=[0, 5])   # toward directions
    y = vdsh.sh_eval(16, dirs)         # N x 256 basis, float32 as formats/vdsh_sh.c

    python -m vdsh info FILE [--json OUT]     # vdsh-info's main figures

Every reading rule of the spec is checked; numpy only.
"""
from __future__ import annotations

import os
import stat
import struct
import zlib
from typing import Any, Dict, List, NoReturn, Optional, Union

import numpy as np

from .evaluate import (compare, distances, distances_toward, sh_eval, shadows,  # noqa: F401
                       vertex_orders)

__all__ = ["VdshError", "VdshFile", "read", "parse", "coefficients", "sh_basis", "reconstruct",
           "sh_eval", "distances", "distances_toward", "shadows", "compare", "vertex_orders"]
__version__ = "0.1.0"

MAGIC = b"VDSH\r\n\x1a\n"
METHODS = ["paper", "full", "mirror", "lsq", "shadow", "decision"]
ENCODINGS = ["f32", "f16", "s8", "s8s6", "cpca"]
QUANTITIES = ["distance", "distance2", "log-distance"]
MAX_ORDER = 16
WINDOWS = ["none", "hann", "lanczos"]
KNOWN = {b"HEAD", b"SRCS", b"POSN", b"NORM", b"TRIS", b"COEF", b"stat", b"time", b"part", b"adpt",
         b"lpol", b"lreg"}
MAX_POOL_LIGHTS = 65536
LOG_SUM_MAX = 80.0


class VdshError(Exception):
    """A file that breaks a rule of formats/VDSH.md; the message names it."""


class VdshFile:
    """A .vdsh file as read: `header` (dict of HEAD's fields), `sources`
    (list of dicts name, size, sha256), `streams` (list of dicts, one per
    COEF chunk: order, encoding, method, method_id, quantity, window,
    window_param, method_param, scale, quantity_param, stored, coef_scales,
    levels, variable_order, orders), `positions`, `normals` (V x 3 float32),
    `triangles` (T x 3 uint32), and the ancillary `stats`, `timings`,
    `part`, `adaptive`, `light_pool` (dicts, or None when the chunk is
    absent)."""

    header: Dict[str, Any]
    sources: List[Dict[str, Any]]
    streams: List[Dict[str, Any]]
    stats: Optional[Dict[str, int]]
    timings: Optional[Dict[str, float]]
    part: Optional[Dict[str, Any]]
    adaptive: Optional[Dict[str, Any]]
    light_pool: Optional[Dict[str, Any]]
    light_region: Optional[Dict[str, Any]]
    positions: np.ndarray
    normals: np.ndarray
    triangles: np.ndarray

    def __init__(self) -> None:
        self.header, self.sources, self.streams = {}, [], []
        self.stats = self.timings = self.part = self.adaptive = self.light_pool = None
        self.light_region = None
        self._coef = []  # COEF payloads, read once every chunk is (a part's size them)
        self.positions = self.normals = self.triangles = None


def _s(n: int) -> str:
    """Plurals in messages: "%d byte%s" % (n, _s(n)) says "1 byte", "2 bytes"."""
    return "" if n == 1 else "s"


def _fail(path: str, msg: str) -> NoReturn:
    raise VdshError("%s: %s" % (path, msg))


def _finite(*v):
    return all(np.isfinite(x) for x in v)


def read(path: Union[str, "os.PathLike[str]"]) -> VdshFile:
    """Read and check a .vdsh file (every reading rule of formats/VDSH.md).

    Returns a VdshFile. Raises VdshError, whose message names the file and
    what is wrong, for a file that breaks a rule, and OSError when it
    cannot be opened."""
    # O_NONBLOCK: a FIFO opens without waiting for a writer, and is refused
    # below with anything else that is not a regular file (/dev/zero would
    # never end).
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0))
    with os.fdopen(fd, "rb") as fh:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            _fail(os.fspath(path), "not a regular file")
        data = fh.read()
    return parse(data, path)


# HEAD load_flags bits 1..3: the sources' up axis, turned into +y by the
# bake (vdsh-bake --up-axis; formats/vdsh.h, VDSH_LOAD_UP_MASK).
UP_AXES = ("y", "z", "-z", "x", "-x", "-y")

_BAKE_IT_FIRST = "; bake it first: vdsh-bake MODEL -o MODEL.vdsh"
_OTHER_FORMATS = (
    (b"VDSHSDF\0", "a VDSH distance volume (vdsh-bake --sdf; vdsh-view --sdf reads it)"),
    (b"glTF", "a binary glTF mesh (.glb, as vdsh-export writes)" + _BAKE_IT_FIRST),
    (b"\x76\x2f\x31\x01", "an OpenEXR image (the bake's basis cubemaps)"),
    (b"ply\n", "a PLY mesh" + _BAKE_IT_FIRST),
    (b"ply\r", "a PLY mesh" + _BAKE_IT_FIRST),
    (b"\x89PNG", "a PNG image"),
)
# The mesh formats vdsh-bake reads, by the name's extension (as vdsh-bake
# picks the reader) where the first bytes do not say.
_MESHES = {
    ".obj": "a Wavefront OBJ mesh" + _BAKE_IT_FIRST,
    ".ply": "a PLY mesh" + _BAKE_IT_FIRST,
    ".off": "an OFF mesh" + _BAKE_IT_FIRST,
    ".stl": "an STL mesh" + _BAKE_IT_FIRST,
    ".gltf": "a glTF mesh" + _BAKE_IT_FIRST,
    ".glb": "a binary glTF mesh (.glb, as vdsh-export writes)" + _BAKE_IT_FIRST,
}


def parse(data: bytes, path: str = "memory") -> VdshFile:
    """As `read`, from the file's bytes; `path` names it in messages."""
    n = len(data)
    if data[:8] != MAGIC[:n]:
        # Files the tools write beside a bake, and meshes, named for what
        # they are by the rule of formats/vdsh_read.c: the first bytes,
        # then (for a file that is not a damaged .vdsh) the mesh
        # extensions vdsh-bake reads (the distance volume's magic begins
        # with "VDSH").
        for magic, what in _OTHER_FORMATS:
            if data[:len(magic)] == magic:
                _fail(path, "not a .vdsh file: " + what)
        if n >= 8 and data[:4] == MAGIC[:4]:
            _fail(path, "not a .vdsh file: magic bytes 4..7 damaged (a text-mode "
                  "transfer changes CR, LF and ^Z)")
        what = _MESHES.get(os.path.splitext(os.fspath(path))[1].lower())
        if what:
            _fail(path, "not a .vdsh file: " + what)
        _fail(path, "not a .vdsh file (wrong magic)")
    if n < 32:  # a file cut short, as vdsh-info says it
        _fail(path, "truncated: %d byte%s, shorter than the 32-byte header" % (n, _s(n)))
    version, count, size, flags, crc = struct.unpack_from("<IIQII", data, 8)
    # The version before the header CRC, as formats/vdsh_read.c: a later
    # version may lay its header out otherwise, and "version N" is then
    # the useful message.
    crc_ok = zlib.crc32(data[:28]) == crc
    if version != 1:
        _fail(path, "format version %d, this reader reads version 1%s" % (
            version, "" if crc_ok else " (and the header CRC fails: the file may be damaged)"))
    if not crc_ok:
        _fail(path, "header CRC mismatch (stored 0x%08x, computed 0x%08x)" % (crc, zlib.crc32(data[:28])))
    if size > n:
        _fail(path, "truncated: %d byte%s, the header says %d" % (n, _s(n), size))
    if size != n:
        _fail(path, "file_size %d but the file has %d byte%s" % (size, n, _s(n)))
    if not 1 <= count <= 64 or flags != 0:
        _fail(path, "chunk_count %d or flags %d out of range" % (count, flags))
    f, off, seen = VdshFile(), 32, []
    for k in range(count):
        if off + 16 > n:
            _fail(path, "chunk %d header runs past the end" % k)
        cid, ccrc, csize = data[off:off + 4], *struct.unpack_from("<IQ", data, off + 4)
        pad = (-csize) % 16
        if csize > n - off - 16 or pad > n - off - 16 - csize:
            _fail(path, "chunk %d runs past the end" % k)
        body = data[off + 16:off + 16 + csize]
        padding = data[off + 16 + csize:off + 16 + csize + pad]
        c = zlib.crc32(data[off:off + 4])
        c = zlib.crc32(data[off + 8:off + 16], c)
        c = zlib.crc32(body + padding, c)
        if c != ccrc:
            _fail(path, "chunk %d %r: CRC mismatch" % (k, cid))
        if any(padding):
            _fail(path, "chunk %d: padding not zero" % k)
        if k == 0 and cid != b"HEAD":
            _fail(path, "HEAD is not the first chunk")
        if cid not in KNOWN:
            if 65 <= cid[0] <= 90:
                _fail(path, "unknown critical chunk %r" % cid)
        elif cid != b"COEF" and cid in seen:
            _fail(path, "a second %r chunk" % cid)
        seen.append(cid)
        if cid in KNOWN:
            _chunk(f, cid, body, path)
        off += 16 + csize + pad
    if off != n:
        _fail(path, "the last chunk ends at %d, file_size is %d" % (off, n))
    for req in (b"HEAD", b"SRCS", b"POSN", b"NORM", b"TRIS"):
        if req not in seen:
            _fail(path, "required chunk %r missing" % req)
    # a part's streams hold its range's rows, and `part` may follow them
    rows = f.part["range_end"] - f.part["range_begin"] if f.part else f.header["vertex_count"]
    for body in f._coef:
        _coef(f, body, rows, path)
    f._coef = []
    if not f.streams:
        _fail(path, "no COEF chunk")
    if f.stats and f.stats["rays_missed"] > f.stats["rays_traced"]:
        _fail(path, "stat: rays_missed > rays_traced")
    if f.light_pool is not None and (not f.part or f.part["encoding"] != "cpca"):
        _fail(path, "lpol: a light pool outside a cpca part")
    if f.light_pool is not None and (f.light_pool["margin"] or f.light_pool["starts"]) and (
            not f.part["cpca_clusters"] or f.part["cpca_bits"] & ~0x100):
        _fail(path, "lpol: a margin or starts with cpca settings other than K,alloc:BYTES")
    return f


def _chunk(f, cid, b, path):
    h = f.header
    if cid == b"HEAD":
        if len(b) != 128:
            _fail(path, "HEAD is %d byte%s, must be 128" % (len(b), _s(len(b))))
        (V, T, rays, sampling, seed, maxd, maxe, rule, lflags, cube, ov, ot, tflags) = \
            struct.unpack_from("<IIIIQffIIIIII", b, 0)
        bmin = struct.unpack_from("<3f", b, 56)
        bmax = struct.unpack_from("<3f", b, 68)
        if not 1 <= V <= 1 << 28 or T > 1 << 28 or rays < 1 or sampling > 1:
            _fail(path, "HEAD: a count or sampling out of range")
        if not (_finite(maxd) and maxd > 0 and _finite(maxe) and maxe >= 0):
            _fail(path, "HEAD: max_distance or max_edge out of range")
        # load_flags: bit 0 welded, bits 1..3 the up axis (UP_AXES), bits
        # 8..15 the crease angle (0 or 1..179)
        if (rule > 1 or lflags & ~0xff0f or (lflags >> 1) & 7 >= len(UP_AXES)
                or (lflags >> 8) & 0xff >= 180 or tflags & ~1):
            _fail(path, "HEAD: offset_rule or flags out of range")
        if not _finite(*bmin, *bmax) or any(a > c for a, c in zip(bmin, bmax)):
            _fail(path, "HEAD: bounds not finite or min > max")
        if any(b[80:128]):
            _fail(path, "HEAD: reserved bytes 80..127 not zero")
        h.update(vertex_count=V, triangle_count=T, rays=rays,
                 sampling=["sphere", "hemisphere"][sampling], seed=seed, max_distance=maxd,
                 max_edge=maxe, offset_rule=rule, load_flags=lflags, cube_size=cube,
                 occluder_vertex_count=ov, occluder_triangle_count=ot, trace_flags=tflags,
                 bounds_min=bmin, bounds_max=bmax)
        return
    V, T = h["vertex_count"], h["triangle_count"]
    if cid == b"SRCS":
        if len(b) < 4:
            _fail(path, "SRCS too short")
        (cnt,), o = struct.unpack_from("<I", b, 0), 4
        if cnt > 64:
            _fail(path, "SRCS: count %d > 64" % cnt)
        for _ in range(cnt):
            if o + 44 > len(b):
                _fail(path, "SRCS runs past its payload")
            sha, sz, ln = b[o:o + 32], *struct.unpack_from("<QI", b, o + 32)
            o += 44
            if not 1 <= ln <= 4096 or o + ln + (-ln) % 4 > len(b):
                _fail(path, "SRCS: name length %d" % ln)
            raw = b[o:o + ln]
            if 0 in raw or any(b[o + ln:o + ln + (-ln) % 4]):
                _fail(path, "SRCS: NUL in a name or padding not zero")
            try:
                name = raw.decode("utf-8")
            except UnicodeDecodeError:
                _fail(path, "SRCS: a name is not UTF-8")
            f.sources.append(dict(name=name, size=sz, sha256=sha.hex()))
            o += ln + (-ln) % 4
        if o != len(b):
            _fail(path, "SRCS: payload does not end after the last name")
    elif cid in (b"POSN", b"NORM"):
        if len(b) != 12 * V:
            _fail(path, "%s is %d byte%s, must be %d" % (cid.decode(), len(b), _s(len(b)), 12 * V))
        a = np.frombuffer(b, "<f4").reshape(V, 3)
        if not np.isfinite(a).all():
            _fail(path, "%s: a value is not finite" % cid.decode())
        if cid == b"NORM":
            ln = np.linalg.norm(a.astype(np.float64), axis=1)
            zero = (a == 0).all(axis=1)
            if ((np.abs(ln - 1) >= 1e-3) & ~zero).any():
                _fail(path, "NORM: a normal is neither unit nor zero")
            f.normals = a
        else:
            f.positions = a
    elif cid == b"TRIS":
        if len(b) != 12 * T:
            _fail(path, "TRIS is %d byte%s, must be %d" % (len(b), _s(len(b)), 12 * T))
        t = np.frombuffer(b, "<u4").reshape(T, 3)
        if T and t.max() >= V:
            _fail(path, "TRIS: an index is out of range")
        f.triangles = t
    elif cid == b"COEF":
        f._coef.append(b)
    elif cid == b"part":
        if len(b) != 32:
            _fail(path, "part is %d byte%s, must be 32" % (len(b), _s(len(b))))
        i, n, rb, re, enc, ck, cb, cbits = struct.unpack_from("<8I", b, 0)
        if not (n >= 1 and i < n and rb < re <= h["vertex_count"] and enc <= 4):
            _fail(path, "part: shard %d of %d, receivers %d..%d or encoding %d out of range"
                  % (i, n, rb, re, enc))
        if enc != 4 and (ck or cb or cbits):
            _fail(path, "part: cpca settings with encoding %s (must be 0)" % ENCODINGS[enc])
        if enc == 4 and (ck == 0 or cbits in (0, 0x100)):
            # auto: 0, budget, 0; alloc: K, budget, 0 or 0x100 (s8 bases)
            if not (ck <= 256 and 1 <= cb <= 4096 and (cbits == 0 or ck)):
                _fail(path, "part: cpca %s settings %d,%d,%d out of range"
                      % ("auto" if ck == 0 else "alloc", ck, cb, cbits))
        elif enc == 4 and not (1 <= ck <= 256 and 1 <= cb <= 256 and 2 <= cbits <= 8):
            _fail(path, "part: cpca settings %d,%d,%d out of range" % (ck, cb, cbits))
        f.part = dict(index=i, count=n, range_begin=rb, range_end=re, encoding=ENCODINGS[enc])
        if enc == 4:
            f.part.update(cpca_clusters=ck, cpca_basis=cb, cpca_bits=cbits)
    elif cid == b"lpol":  # a cpca part's light pool (VDSH.md "Parts")
        cnt = struct.unpack_from("<I", b, 0)[0] if len(b) >= 16 else 0
        if len(b) < 16 or len(b) != 16 + 12 * cnt:
            _fail(path, "lpol is %d byte%s, must be 16 + 12 x its %d light%s"
                  % (len(b), _s(len(b)), cnt, _s(cnt)))
        mix, margin, starts = struct.unpack_from("<ffI", b, 4)
        if not (0 < mix <= 1) or not 1 <= cnt <= MAX_POOL_LIGHTS:
            _fail(path, "lpol: light mix %g or %d light%s out of range" % (mix, cnt, _s(cnt)))
        if not (margin == 0 or 0 < margin <= 1e6) or starts > 16:
            _fail(path, "lpol: margin %g or %d starts out of range" % (margin, starts))
        lights = np.frombuffer(b, "<f4", 3 * cnt, 16).reshape(cnt, 3)
        if not np.isfinite(lights).all():
            _fail(path, "lpol: a light is not finite")
        f.light_pool = dict(mix=mix, lights=lights, margin=margin, starts=starts)
    elif cid == b"lreg":  # where the bake's lights went (VDSH.md `lreg`)
        if len(b) != 32:
            _fail(path, "lreg is %d byte%s, must be 32" % (len(b), _s(len(b))))
        rule = struct.unpack_from("<I", b, 0)[0]
        lo = struct.unpack_from("<3f", b, 4)
        hi = struct.unpack_from("<3f", b, 16)
        if any(b[28:32]):
            _fail(path, "lreg: reserved bytes 28..31 not zero")
        if rule not in (1, 2):
            _fail(path, "lreg: rule %d out of range (1 grown, 2 box)" % rule)
        if not all(np.isfinite(a) and np.isfinite(c) and a < c for a, c in zip(lo, hi)):
            _fail(path, "lreg: the box is not finite with min < max")
        f.light_region = dict(rule="grown" if rule == 1 else "box", min=list(lo), max=list(hi))
    elif cid == b"adpt":
        if len(b) != 32:
            _fail(path, "adpt is %d byte%s, must be 32" % (len(b), _s(len(b))))
        tol, me = struct.unpack_from("<2f", b, 0)
        mr, nl, mx, st, rd, cd = struct.unpack_from("<6I", b, 8)
        V = h["vertex_count"]
        if not (tol >= 0 and me > 0 and np.isfinite(me) and nl >= 1 and mx >= 1 and rd <= mx
                and 1 <= st <= V and (mr == 0 or V <= mr) and st + cd >= V):
            _fail(path, "adpt: a field is out of range")
        f.adaptive = dict(tolerance=tol, min_edge=me, max_receivers=mr, lights=nl, max_rounds=mx,
                          start_receivers=st, rounds=rd, candidates=cd)
    elif cid == b"stat":
        if len(b) != 32:
            _fail(path, "stat is %d byte%s, must be 32" % (len(b), _s(len(b))))
        v = struct.unpack("<QQIIII", b)
        f.stats = dict(zip(["rays_traced", "rays_missed", "degenerate_receivers",
                            "undefined_normals", "moved_origins", "flipped_normals"], v))
    elif cid == b"time":
        if len(b) != 64:
            _fail(path, "time is %d byte%s, must be 64" % (len(b), _s(len(b))))
        v = struct.unpack_from("<5d", b, 0)
        if not all(np.isfinite(x) and x >= 0 for x in v):
            _fail(path, "time: a value is not finite or negative")
        if any(b[44:64]):
            _fail(path, "time: reserved bytes 44..63 not zero")
        f.timings = dict(zip(["load", "refine", "build", "trace", "total"], v),
                         threads=struct.unpack_from("<I", b, 40)[0])


def _records(raw, nc, enc, levels, path):
    """R records of nc coefficients (R x bpv bytes) to their stored values
    (R x nc), with the encoding's rules: finite floats, s8 not -128, s8s6
    fields within +-31 and unused bits zero."""
    R = raw.shape[0]
    if enc == 3:
        words = (nc - 4 + 4) // 5 if nc > 4 else 0
        stored = np.empty((R, nc), np.int32)
        stored[:, :min(nc, 4)] = raw[:, :min(nc, 4)].view(np.int8)
        if words:
            w = raw[:, 4:4 + 4 * words].copy().view("<u4").reshape(R, words)
            for i in range(4, nc):
                fld = (w[:, (i - 4) // 5] >> np.uint32(6 * ((i - 4) % 5))) & np.uint32(63)
                stored[:, i] = fld.astype(np.int32) - 64 * (fld >= 32)
            used = np.array([(1 << (6 * min(5, nc - 4 - 5 * k))) - 1 for k in range(words)],
                            np.uint32)
            if (w & ~used).any():
                _fail(path, "COEF: unused bits of an s8s6 word not zero")
        if (stored < -levels[:nc].astype(np.int32)).any():
            _fail(path, "COEF: an s8s6 stored value is below its range")
    elif enc == 2:
        stored = raw[:, :nc].copy().view("i1")
        if (stored == -128).any():
            _fail(path, "COEF: an s8 stored value is -128 (range -127..127)")
    else:
        size = [4, 2][enc]
        stored = raw[:, :nc * size].copy().view(["<f4", "<f2"][enc]).astype(np.float32)
        if not np.isfinite(stored).all():
            _fail(path, "COEF: a stored value is not finite")
    return stored


def _bpv(enc, nc):
    """Bytes of one record of nc coefficients (VDSH.md, COEF)."""
    words = (nc - 4 + 4) // 5 if enc == 3 and nc > 4 else 0
    return [4 * nc, 2 * nc, nc, min(nc, 4) + 4 * words][enc]


def _coef(f, b, V, path):
    """One COEF stream of V rows (a part: its range's)."""
    if len(b) < 48:
        _fail(path, "COEF shorter than its header")
    order, enc, method, qty, win = struct.unpack_from("<5I", b, 0)
    wp, mp, scale, qp = struct.unpack_from("<4f", b, 20)
    flags = struct.unpack_from("<I", b, 36)[0]
    if not 1 <= order <= MAX_ORDER or enc > 4 or qty > 2 or win > 2:
        _fail(path, "COEF: order, encoding, quantity or window out of range")
    if not _finite(wp, mp) or (win == 0 and wp != 0) or (win != 0 and not wp > 0):
        _fail(path, "COEF: window_param or method_param out of range")
    if not (_finite(scale) and scale > 0):
        _fail(path, "COEF: scale must be finite and > 0")
    if (qty == 2 and not (_finite(qp) and qp > 0)) or (qty != 2 and qp != 0):
        _fail(path, "COEF: quantity_param out of range")
    if flags & ~1:
        _fail(path, "COEF: flags 0x%x: unknown bits" % flags)
    if any(b[40:48]):
        _fail(path, "COEF: reserved bytes 40..47 not zero")
    variable = bool(flags & 1)
    nc = order * order
    if enc == 4:
        if variable:
            _fail(path, "COEF: cpca streams cannot have variable order")
        if scale != 1:
            _fail(path, "COEF: scale must be 1 for cpca")
        stored, cpca = _cpca(b, order, V, path)
        _append(f, order, enc, method, qty, win, wp, mp, scale, qp, stored, None, None, False,
                None, path)
        f.streams[-1]["cpca"] = cpca
        return
    # s8, s8s6: order^2 f32 scales, zero-padded to 16 bytes, before the data
    table = (nc * 4 + 15) // 16 * 16 if enc >= 2 else 0
    scales = levels = None
    levels = np.array([31 if enc == 3 and i >= 4 else 127 for i in range(nc)], np.float32)
    if enc >= 2:
        if scale != 1:
            _fail(path, "COEF: scale must be 1 for %s" % ENCODINGS[enc])
        if len(b) < 48 + table:
            _fail(path, "COEF: shorter than its scale table")
        scales = np.frombuffer(b, "<f4", nc, 48)
        if not (np.isfinite(scales).all() and (scales >= 0).all()):
            _fail(path, "COEF: a scale of the table is not finite and >= 0")
        with np.errstate(over="ignore"):
            if not np.isfinite(levels * (scales / levels)).all():
                _fail(path, "COEF: a scale's steps overflow f32")
        if any(b[48 + nc * 4:48 + table]):
            _fail(path, "COEF: padding after the scale table not zero")
    data = 48 + table
    orders = None
    if variable:
        # VDSH.md "Variable-order streams": an order table (V bytes, padded
        # to 16), then each row's record of its own order, padded to 4 bytes
        otab = (V + 15) // 16 * 16
        if len(b) < data + otab:
            _fail(path, "COEF: shorter than its order table")
        orders = np.frombuffer(b, np.uint8, V, data).astype(np.int64)
        if any(b[data + V:data + otab]):
            _fail(path, "COEF: padding after the order table not zero")
        if ((orders < 1) | (orders > order)).any():
            _fail(path, "COEF: a vertex order outside 1..%d" % order)
        rec = np.array([(_bpv(enc, k * k) + 3) // 4 * 4 for k in range(order + 1)])
        start = data + otab + np.concatenate(([0], np.cumsum(rec[orders])))
        if len(b) != start[-1]:
            _fail(path, "COEF: payload is %d byte%s, must be %d" % (len(b), _s(len(b)), start[-1]))
        buf = np.frombuffer(b, np.uint8)
        stored = np.zeros((V, nc), np.float32 if enc < 2 else np.int32)
        for k in np.unique(orders):
            rows = np.nonzero(orders == k)[0]
            raw = buf[start[rows][:, None] + np.arange(rec[k])]
            used = _bpv(enc, k * k)
            if raw[:, used:].any():
                _fail(path, "COEF: padding after a record not zero")
            stored[rows, :k * k] = _records(raw, k * k, enc, levels, path)
    else:
        bpv = _bpv(enc, nc)
        if len(b) != data + V * bpv:
            _fail(path, "COEF: payload is %d byte%s, must be %d" % (len(b), _s(len(b)), data + V * bpv))
        raw = np.frombuffer(b, np.uint8, V * bpv, data).reshape(V, bpv)
        stored = _records(raw, nc, enc, levels, path)
    big = float(np.abs(stored.astype(np.float32)).max()) if stored.size else 0.0
    with np.errstate(over="ignore"):
        if not np.isfinite(np.float32(big) * np.float32(scale)):
            _fail(path, "COEF: a stored value times scale overflows f32")
    _append(f, order, enc, method, qty, win, wp, mp, scale, qp, stored, scales,
            levels if enc >= 2 else None, variable, orders, path)


def _cpca_fields(widths):
    """(word, shift) of each weight's field in a cpca record whose weight
    j is widths[j] bits wide (VDSH.md): from bit 8 of word 0 upward, a
    field that does not fit in what is left of a word starting the next."""
    out, word, shift = [], 0, 8
    for w in widths:
        if shift + w > 32:
            word, shift = word + 1, 0
        out.append((word, shift))
        shift += w
    return out


def _cpca(b, order, V, path):
    """A cpca stream's model and records (VDSH.md "cpca streams"), every
    rule checked; the decoded V x n^2 float32 coefficients, as vdsh.c: w_j
    = level x float32(scale / L), a = mean, then a = a + w_j x basis_j in
    float32, j in order."""
    nc = order * order
    if len(b) < 64:
        _fail(path, "COEF: shorter than its cpca header")
    K, B, bits, W = struct.unpack_from("<4I", b, 48)
    s8 = bool(bits & 0x100)  # VDSH_CPCA_BASES_S8: the bases s8, not f16
    bits &= ~0x100
    if not (1 <= K <= 256 and 1 <= B <= nc and (bits == 0 or 2 <= bits <= 8)):
        _fail(path, "COEF: cpca clusters %d, basis %d or bits %d out of range" % (K, B, bits))
    r16 = lambda n: (n + 15) // 16 * 16  # noqa: E731
    at = 64
    if bits:
        widths = np.full(B, bits, np.int64)
    else:  # a width per basis vector: u8[B], zero-padded to 16
        if len(b) < 64 + r16(B):
            _fail(path, "COEF: shorter than its cpca widths table")
        widths = np.frombuffer(b, np.uint8, B, 64).astype(np.int64)
        if ((widths < 2) | (widths > 8)).any():
            _fail(path, "COEF: a cpca width is out of 2..8")
        if any(b[64 + B:64 + r16(B)]):
            _fail(path, "COEF: padding after the cpca widths not zero")
        at += r16(B)
    fields = _cpca_fields(int(x) for x in widths)
    if W != (fields[-1][0] + 1):
        _fail(path, "COEF: cpca record_words %d, must be %d" % (W, fields[-1][0] + 1))
    sizes = [4 * K * B, 2 * K * nc, (1 if s8 else 2) * K * B * nc]
    model = at + sum(r16(x) for x in sizes)
    if len(b) != model + 4 * W * V:
        _fail(path, "COEF: payload is %d byte%s, must be %d" % (len(b), _s(len(b)), model + 4 * W * V))
    arrays = []
    for x, dt, shape in zip(sizes, ["<f4", "<f2", "i1" if s8 else "<f2"],
                            [(K, B), (K, nc), (K, B, nc)]):
        if any(b[at + x:at + r16(x)]):
            _fail(path, "COEF: padding after a cpca array not zero")
        arrays.append(np.frombuffer(b, dt, x // np.dtype(dt).itemsize, at).reshape(shape))
        at += r16(x)
    scales, means16, bases16 = arrays
    if not (np.isfinite(scales).all() and (scales >= 0).all()):
        _fail(path, "COEF: a cpca scale is not finite and >= 0")
    if not (np.isfinite(means16).all() and np.isfinite(bases16).all()):
        _fail(path, "COEF: a cpca mean or basis value is not finite")
    if s8 and (bases16 == -128).any():
        _fail(path, "COEF: a cpca s8 basis value is -128 (-127..127)")
    L = (1 << (widths - 1)) - 1  # per vector
    step = (scales.astype(np.float32) / L.astype(np.float32)).astype(np.float32)
    means = means16.astype(np.float32)
    bases = bases16.astype(np.float32)
    bound = (np.abs(means.astype(np.float64)) +
             np.einsum("kb,kbn->kn", L * step.astype(np.float64), np.abs(bases.astype(np.float64))))
    if not (bound <= 1e38).all():
        _fail(path, "COEF: a cpca cluster's coefficients can exceed 1e38")
    rec = np.frombuffer(b, "<u4", W * V, model).reshape(V, W)
    cluster = (rec[:, 0] & 0xff).astype(np.int64)
    if (cluster >= K).any():
        _fail(path, "COEF: a cpca cluster index is >= %d" % K)
    used = np.zeros(W, np.uint64)
    used[0] = 0xff
    levels = np.empty((V, B), np.int32)
    for j, (w, sh) in enumerate(fields):
        wd = int(widths[j])
        used[w] |= np.uint64(((1 << wd) - 1) << sh)
        u = ((rec[:, w] >> np.uint32(sh)) & np.uint32((1 << wd) - 1)).astype(np.int32)
        levels[:, j] = u - (u >> (wd - 1)) * (1 << wd)
    if (rec.astype(np.uint64) & ~used).any():
        _fail(path, "COEF: unused bits of a cpca record not zero")
    low = (levels < -L).any(axis=0)
    if low.any():
        j = int(np.argmax(low))
        _fail(path, "COEF: cpca weight %d is below -%d" % (j, L[j]))
    out = means[cluster]
    wts = levels.astype(np.float32) * step[cluster]
    for j in range(B):
        out = out + wts[:, j:j + 1] * bases[cluster, j]
    return out.astype(np.float32), dict(clusters=K, basis=B, bits=bits, bases_s8=s8,
                                        record_words=W,
                                        widths=widths.astype(np.int32),
                                        scales=scales.astype(np.float32), means=means,
                                        bases=bases, cluster=cluster, levels=levels)


def _append(f, order, enc, method, qty, win, wp, mp, scale, qp, stored, scales, levels, variable,
            orders, path):
    if any(s["quantity"] == QUANTITIES[qty] and s["variable_order"] == variable and
           (variable or s["order"] == order) for s in f.streams):
        _fail(path, "COEF: a second %s stream, %s" % (
            "variable-order" if variable else "order %d" % order, QUANTITIES[qty]))
    if len(f.streams) >= 15:
        _fail(path, "more than 15 COEF chunks")
    f.streams.append(dict(order=order, encoding=ENCODINGS[enc],
                          method=METHODS[method] if method < len(METHODS) else method,
                          method_id=method, quantity=QUANTITIES[qty], window=WINDOWS[win],
                          window_param=wp, method_param=mp, scale=scale, quantity_param=qp,
                          stored=stored, coef_scales=scales, levels=levels,
                          variable_order=variable, orders=orders, cpca=None))


def coefficients(stream: Dict[str, Any]) -> np.ndarray:
    """V x n^2 float32 (a part's: its range's rows): stored value x scale (the window is already applied);
    s8, s8s6: stored value x step_i, step_i = float32(scale_i / levels_i),
    levels 127 (31 for s8s6's coefficients 4..) (as vdsh.c)."""
    if stream["encoding"] in ("s8", "s8s6"):
        step = (stream["coef_scales"] / stream["levels"]).astype(np.float32)
        return stream["stored"].astype(np.float32) * step
    return stream["stored"].astype(np.float32) * np.float32(stream["scale"])


def sh_basis(order: int, dirs: Any) -> np.ndarray:
    """N x order^2 real SH (VDSH.md, Conventions) at unit directions (N x 3),
    in float64 (sh_eval: float32, as the C library computes them)."""
    d = np.asarray(dirs, np.float64).reshape(-1, 3)
    x, y, z = d[:, 0], d[:, 1], d[:, 2]
    out = np.zeros((len(d), order * order))
    fact = [1.0]
    for i in range(1, 2 * order + 2):
        fact.append(fact[-1] * i)
    xy = x + 1j * y
    for m in range(order):
        # P_m^m with the Condon-Shortley phase, times e^{i m phi} sin^m
        dfact = np.prod(np.arange(2 * m - 1, 0, -2)) if m else 1.0
        pmm = (-1) ** m * dfact * xy ** m
        p_prev, p = None, pmm
        for l in range(m, order):
            if l == m + 1:
                p_prev, p = p, z * (2 * m + 1) * pmm
            elif l > m + 1:
                p_prev, p = p, ((2 * l - 1) * z * p - (l + m - 1) * p_prev) / (l - m)
            k = np.sqrt((2 * l + 1) / (4 * np.pi) * fact[l - m] / fact[l + m])
            if m == 0:
                out[:, l * (l + 1)] = k * p.real
            else:
                out[:, l * (l + 1) + m] = np.sqrt(2) * k * p.real
                out[:, l * (l + 1) - m] = np.sqrt(2) * k * p.imag
    return out


def reconstruct(f: VdshFile, stream: Dict[str, Any], vertex: int, dirs: Any) -> np.ndarray:
    """Distances (float64, N) of one vertex toward unit directions (N x 3),
    VDSH.md's Reconstruction rules in float64. In a part, only its range's
    vertices have coefficients. For many vertices, and the C library's
    float32 numbers, use distances_toward (or distances, shadows)."""
    row = vertex - (f.part["range_begin"] if f.part else 0)
    if not 0 <= row < len(stream["stored"]):
        raise VdshError("vertex %d: not in the file's streams%s" % (
            vertex, " (a part: receivers %d..%d)" % (f.part["range_begin"], f.part["range_end"])
            if f.part else ""))
    c = coefficients(stream)[row].astype(np.float64)
    s = sh_basis(stream["order"], dirs) @ c
    dmax = f.header["max_distance"]
    q = stream["quantity"]
    if q == "distance":
        d = np.maximum(s, 0)
    elif q == "distance2":
        d = np.sqrt(np.maximum(s, 0))
    else:
        d = np.exp(np.minimum(s, LOG_SUM_MAX))
    return np.minimum(d, dmax)
