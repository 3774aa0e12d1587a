"""test_python_eval.py BAKE INFO REF SRC_DIR WORK - the Python evaluator
(python/vdsh/evaluate.py) against the C library, and `python -m vdsh info`
against vdsh-info.

Installs python/ as tests/test_python_reader.py does (pip, --no-index, into
WORK) and imports it from there. REF is test_python_eval_ref (the C
library's vdsh_sh_eval, vdsh_vertex_distance, vdsh_shadow,
vdsh_stream_distance on records). Checks:
- sh_eval at orders 1..16, 64 directions each (axes included), against
  vdsh_sh_eval: within 1e-6;
- on rooms baked here (every encoding; methods decision, shadow, lsq,
  paper; quantities log-distance and distance, and distance2 by rewriting
  an f32 file's stream headers; orders 1..5, 7, 12, 16; adaptive-order
  streams in s8s6 and f32) and the corpus's valid files: for every stream
  60 vertices x 50 lights (a light at a vertex, lights far outside the
  scene: the clamp) through distances() and shadows() as V x L arrays
  against C pair by pair: distances within 1e-6 relative, smooth shadows
  within 1e-6, binary shadows equal but where the distance is within 1e-6
  of the light's; log offsets (vdsh-eval --offsets) on some; directions
  per vertex through distances_toward against vdsh_stream_distance;
- a stream of an unknown method: distances read, shadows refused; a part:
  its range only, a vertex outside refused;
- `python -m vdsh info --json` against `vdsh-info --json`: every field it
  writes equal (floats to 1e-6 relative), exit status 1 naming a missing
  file, 2 for a usage error.
"""
import glob
import json
import os
import shutil
import struct
import subprocess
import sys
import zlib

import numpy as np

import testlib

bake, info, ref, src, work = sys.argv[1:6]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
fail = []
target = os.path.join(work, "site")
r = testlib.pip_install(os.path.join(src, "python"), target)
if r.returncode:
    sys.exit("FAIL: pip install ./python: %s" % r.stderr)
sys.path.insert(0, target)
import vdsh  # noqa: E402

assert vdsh.__file__.startswith(target), vdsh.__file__
REC = np.dtype([("id", "<u4"), ("v", "<f4", 3)])
rng = np.random.default_rng(7)


def run_ref(args, ids, vecs, width):
    rec = np.zeros(len(ids), REC)
    rec["id"], rec["v"] = ids, vecs
    fin, fout = os.path.join(work, "ref.in"), os.path.join(work, "ref.out")
    rec.tofile(fin)
    r = subprocess.run([ref] + args + [fin, fout], capture_output=True, text=True)
    if r.returncode:
        sys.exit("FAIL: %s: %s" % (" ".join(args), r.stderr))
    return np.fromfile(fout, "<f4").reshape(len(ids), width)


def units(n):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


# The SH basis, orders 1..16.
axes = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, 0, -1], [0.48, 0.6, 0.64]])
dirs = np.vstack([axes, units(58)]).astype(np.float32)
for k in range(1, 17):
    c = run_ref(["sh"], np.full(len(dirs), k), dirs, 256)[:, :k * k]
    p = vdsh.sh_eval(k, dirs)
    if p.shape != c.shape or not np.abs(p - c).max() <= 1e-6:
        fail.append("sh_eval order %d: max |diff| %g" % (k, np.abs(p - c).max()))
    if not np.allclose(p, vdsh.sh_basis(k, dirs), atol=1e-5):
        fail.append("sh_eval order %d differs from sh_basis (float64)" % k)

counts = dict(pairs=0, streams=0, identical=0)


def check_stream(path, f, si, offset):
    """60 vertices x 50 lights, and 60 vertices x 8 directions, of stream si."""
    s = f.streams[si]
    V = f.header["vertex_count"]
    lo, hi = np.array(f.header["bounds_min"]), np.array(f.header["bounds_max"])
    vs = rng.choice(V, 60, replace=V < 60)
    vs[1] = vs[0]  # a vertex twice
    span = np.maximum(hi - lo, 1e-3)
    L = rng.uniform(lo - 0.05 * span, hi + 0.05 * span, size=(50, 3))
    L[0] = f.positions[vs[0]]                               # a light at a vertex
    L[1] = lo - 40 * span                                   # far away: the clamp
    L[2] = f.positions[vs[5]] + 1e-3 * f.normals[vs[5]]     # just above a vertex
    d = vdsh.distances(f, s, L, vertices=vs, offset=offset)
    sm = vdsh.shadows(f, s, L, vertices=vs, offset=offset)
    bi = vdsh.shadows(f, s, L, vertices=vs, compare_with="binary", offset=offset)
    if not (d.shape == sm.shape == bi.shape == (60, 50)):
        fail.append("%s stream %d: shapes %s %s %s" % (path, si, d.shape, sm.shape, bi.shape))
        return
    c = run_ref(["lights", path, str(si), repr(offset)], np.repeat(vs, 50),
                np.tile(L.astype(np.float32), (60, 1)), 3).reshape(60, 50, 3)
    name = "%s stream %d (order %d%s, %s, %s, %s, offset %g)" % (
        os.path.basename(path), si, s["order"], " variable" if s["variable_order"] else "",
        s["encoding"], s["method"], s["quantity"], offset)
    cd = c[..., 0]
    dd = np.abs(d - cd) / np.maximum(1.0, np.abs(cd))
    if not dd.max() <= 1e-6:
        fail.append("%s: distances differ by %g (relative)" % (name, dd.max()))
    if not np.abs(sm - c[..., 1]).max() <= 1e-6:
        fail.append("%s: smooth shadows differ by %g" % (name, np.abs(sm - c[..., 1]).max()))
    # binary: equal, but where the decision is a tie within the tolerance
    dl = np.linalg.norm(L.astype(np.float32)[None] - f.positions[vs][:, None], axis=2)
    tie = np.abs(cd - dl) <= 1e-6 * np.maximum(1.0, dl)
    if ((bi != c[..., 2]) & ~tie).any():
        fail.append("%s: %d binary shadows differ" % (name, ((bi != c[..., 2]) & ~tie).sum()))
    at = vs == vs[0]
    if not (sm[at, 0] == 1).all() or not (bi[at, 0] == 1).all() or not (d[at, 0] == 0).all():
        fail.append("%s: a light at the vertex is not visible at distance 0" % name)
    if not (d <= np.float32(f.header["max_distance"])).all() or not (d >= 0).all():
        fail.append("%s: a distance outside [0, max_distance]" % name)
    # Directions, one set per vertex.
    D = units(60 * 8).reshape(60, 8, 3).astype(np.float32)
    t = vdsh.distances_toward(f, s, D, vertices=vs, offset=offset)
    ct = run_ref(["dirs", path, str(si), repr(offset)], np.repeat(vs, 8),
                 D.reshape(-1, 3), 1).reshape(60, 8)
    if not (np.abs(t - ct) / np.maximum(1.0, np.abs(ct))).max() <= 1e-6:
        fail.append("%s: distances_toward differ" % name)
    counts["pairs"] += d.size + t.size
    counts["streams"] += 1
    counts["identical"] += int((d == cd).sum() + (t == ct).sum())


def distance2_copy(path, out):
    """The file with every stream's quantity rewritten to distance2 (the
    bake writes none; its header field and chunk CRC rewritten)."""
    b = bytearray(open(path, "rb").read())
    off = 32
    while off < len(b):
        cid, size = bytes(b[off:off + 4]), struct.unpack_from("<Q", b, off + 8)[0]
        pad = (-size) % 16
        if cid == b"COEF":
            struct.pack_into("<I", b, off + 16 + 12, 1)
            crc = zlib.crc32(b[off + 16:off + 16 + size + pad],
                             zlib.crc32(b[off + 8:off + 16], zlib.crc32(b[off:off + 4])))
            struct.pack_into("<I", b, off + 4, crc)
        off += 16 + size + pad
    open(out, "wb").write(b)


bakes = (("default", [], (0.0, 0.4)),
         ("shadow-f16", ["--method", "shadow", "--encoding", "f16", "--orders", "1,4"], (0.0,)),
         ("lsq-s8", ["--method", "lsq", "--quantity", "distance", "--encoding", "s8"], (0.0, -0.3)),
         ("paper-f32", ["--method", "paper", "--encoding", "f32", "--orders", "2,5"], (0.0, 0.2)),
         ("high-f16", ["--orders", "7,12,16", "--encoding", "f16"], (0.0,)),
         ("adaptive-order", ["--adaptive-order", "0.02", "--max-order", "9", "--orders", "3"],
          (0.0, 0.3)),
         ("adaptive-order-f32", ["--adaptive-order", "0.02", "--encoding", "f32"], (0.0,)))
files = []
for name, args, offsets in bakes:
    out = os.path.join(work, name + ".vdsh")
    e = testlib.bake_room(bake, out, "2", "128", args)
    if e is not None:
        fail.append("bake %s: %s" % (name, e))
        continue
    files.append((out, offsets))
if os.path.exists(os.path.join(work, "paper-f32.vdsh")):
    out = os.path.join(work, "distance2.vdsh")
    distance2_copy(os.path.join(work, "paper-f32.vdsh"), out)
    files.append((out, (0.0, 0.25)))
for path in sorted(glob.glob(os.path.join(src, "tests", "corpus", "vdsh", "*.vdsh"))):
    try:
        if not vdsh.read(path).part:
            files.append((path, (0.0,)))
    except vdsh.VdshError:
        pass
kinds = set()
for path, offsets in files:
    f = vdsh.read(path)
    for si, s in enumerate(f.streams):
        kinds.add((s["encoding"], s["quantity"], s["method"], s["variable_order"]))
        for off in offsets:
            check_stream(path, f, si, off)
for want in [("encoding", e) for e in ("f32", "f16", "s8", "s8s6")] + \
        [("quantity", q) for q in ("distance", "distance2", "log-distance")]:
    if not any(want[1] in k for k in kinds):
        fail.append("no stream of %s %s was checked" % want)

# An unknown method: distances, no shadows. A part: its range only.
f = vdsh.read(files[0][0])
s = dict(f.streams[0], method_id=9, method=9)
vdsh.distances(f, s, [[0, 1, 0]])
try:
    vdsh.shadows(f, s, [[0, 1, 0]])
    fail.append("shadows of an unknown method accepted")
except vdsh.VdshError:
    pass
part = os.path.join(work, "part.vdsh")
r = subprocess.run([bake, "builtin:room", "--max-edge", "2", "--rays", "64", "-q", "--cube-size",
                    "0", "--shard", "1/3", "-o", part], capture_output=True, text=True)
if r.returncode:
    fail.append("bake part: %s" % r.stderr.strip())
else:
    p = vdsh.read(part)
    b, e = p.part["range_begin"], p.part["range_end"]
    if vdsh.shadows(p, p.streams[0], [[0, 1, 0]]).shape != (e - b, 1):
        fail.append("part: shadows of every vertex is not its range's")
    try:
        vdsh.distances(p, p.streams[0], [[0, 1, 0]], vertices=[e])
        fail.append("part: a vertex outside its range accepted")
    except vdsh.VdshError:
        pass

# python -m vdsh info against vdsh-info.
env = dict(os.environ, PYTHONPATH=target)


def same(a, b, where):
    if isinstance(a, dict):
        for k, v in a.items():
            if not isinstance(b, dict) or k not in b:
                fail.append("info %s.%s: not in vdsh-info's JSON" % (where, k))
            else:
                same(v, b[k], where + "." + k)
    elif isinstance(a, list):
        if not isinstance(b, list) or len(a) != len(b):
            fail.append("info %s: %r, vdsh-info %r" % (where, a, b))
        else:
            for i, (x, y) in enumerate(zip(a, b)):
                same(x, y, "%s[%d]" % (where, i))
    elif isinstance(a, float) or isinstance(b, float):
        if not (isinstance(b, (int, float)) and abs(a - b) <= 1e-6 * max(1.0, abs(a), abs(b))):
            fail.append("info %s: %r, vdsh-info %r" % (where, a, b))
    elif a != b:
        fail.append("info %s: %r, vdsh-info %r" % (where, a, b))


cpca = os.path.join(work, "cpca.vdsh")
r = subprocess.run([bake, "builtin:room", "--max-edge", "2", "--rays", "64", "-q", "--cube-size",
                    "0", "--orders", "7", "--encoding", "cpca", "--cpca", "3,9,4", "-o", cpca],
                   capture_output=True, text=True)
if r.returncode:
    fail.append("bake cpca: %s" % r.stderr.strip())
# A width per basis vector (cpca bits 0): its "widths" in "cpca".
cpca_w = os.path.join(work, "cpca-widths.vdsh")
r = subprocess.run([bake, "builtin:room", "--max-edge", "2", "--rays", "64", "-q", "--cube-size",
                    "0", "--orders", "7", "--encoding", "cpca", "--cpca", "2,alloc:24", "-o",
                    cpca_w], capture_output=True, text=True)
if r.returncode:
    fail.append("bake cpca widths: %s" % r.stderr.strip())
checked = [p for p, _ in files[:3]] + [os.path.join(work, "adaptive-order.vdsh"), part, cpca,
                                       cpca_w]
for path in checked:
    if not os.path.exists(path):
        continue
    py = subprocess.run([sys.executable, "-m", "vdsh", "info", "--json", "-", path],
                        capture_output=True, text=True, env=env)
    c = subprocess.run([info, "--json", "-", path], capture_output=True, text=True)
    if py.returncode or c.returncode:
        fail.append("info %s: exit %d, vdsh-info %d" % (path, py.returncode, c.returncode))
        continue
    same(json.loads(py.stdout), json.loads(c.stdout), os.path.basename(path))
    # A cpca stream's model, as vdsh-info writes it (it was left out).
    for i, st in enumerate(json.loads(py.stdout)["streams"]):
        if st["encoding"] == "cpca" and "cpca" not in st:
            fail.append("info %s: stream %d (cpca) has no \"cpca\" object" % (path, i))
    t = subprocess.run([sys.executable, "-m", "vdsh", "info", path], capture_output=True,
                       text=True, env=env)
    if t.returncode or "%d vertices" % vdsh.read(path).header["vertex_count"] not in t.stdout:
        fail.append("info %s (text): %s" % (path, t.stdout + t.stderr))
missing = os.path.join(work, "missing.vdsh")
r = subprocess.run([sys.executable, "-m", "vdsh", "info", missing], capture_output=True,
                   text=True, env=env)
if r.returncode != 1 or missing not in r.stderr:
    fail.append("info of a missing file: exit %d, %r" % (r.returncode, r.stderr))
r = subprocess.run([sys.executable, "-m", "vdsh", "info", "--bogus", missing],
                   capture_output=True, text=True, env=env)
if r.returncode != 2 or "--help" not in r.stderr:
    fail.append("info --bogus: exit %d, %r" % (r.returncode, r.stderr))
# --json over an input (or a hard link to it) is refused, the input kept
if checked and os.path.exists(checked[0]):
    src = checked[0]
    link = os.path.join(work, "info-link.vdsh")
    if os.path.lexists(link):
        os.unlink(link)
    os.link(src, link)
    before = open(src, "rb").read()
    for target in (src, link):
        r = subprocess.run([sys.executable, "-m", "vdsh", "info", "--json", target, src],
                           capture_output=True, text=True, env=env)
        if r.returncode != 1 or "same file" not in r.stderr or open(src, "rb").read() != before:
            fail.append("info --json over its input: exit %d, %r, the input %s" % (
                r.returncode, r.stderr, "kept" if open(src, "rb").read() == before else "CHANGED"))
            open(src, "wb").write(before)
    os.unlink(link)
    r = subprocess.run([sys.executable, "-m", "vdsh", "info", "--json", work, src],
                       capture_output=True, text=True, env=env)
    if r.returncode != 1 or "is a directory" not in r.stderr:
        fail.append("info --json FOLDER: exit %d, %r" % (r.returncode, r.stderr))
r = subprocess.run([sys.executable, "-m", "vdsh", "--help"], capture_output=True, text=True,
                   env=env)
if r.returncode or not r.stdout.startswith("usage: "):
    fail.append("--help: exit %d, %r" % (r.returncode, r.stdout))

for m in fail:
    print("FAIL:", m)
print("python evaluator: %d streams, %d vertex-light and vertex-direction values against C, "
      "%d equal to the bit; sh_eval orders 1-16; %s"
      % (counts["streams"], counts["pairs"], counts["identical"],
         "agrees" if not fail else "DISAGREES"))
sys.exit(1 if fail else 0)
