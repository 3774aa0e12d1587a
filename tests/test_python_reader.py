"""test_python_reader.py BAKE INFO SRC_DIR WORK - the Python reader (python/)
against the C reader (tools/vdsh-info, formats/vdsh.c).

Installs python/ with pip (--no-build-isolation --no-index, into WORK: no
network, Debian's pip and setuptools) straight from the checkout, as the
README says, and checks that the install leaves the checkout as it was (no
python/build/, python/vdsh.egg-info/: issue 26; what it left is reported,
then removed); imports it from WORK, and checks:
- the SH basis against formats/VDSH.md's table of values;
- on files baked here (default (s8s6), f16, s8, paper f32, lsq with the
  quantity chosen per order, a Hann window, with --record-timings) and on every file of
  tests/corpus/vdsh: both readers accept or both refuse; where both accept,
  the fields vdsh-info --json prints agree (counts, bake parameters,
  streams, coefficient 0's min/max/mean, statistics);
- a file of format version 2 (CRC recomputed, and stale): both readers
  say "format version 2" (the version checked before the header CRC);
- corruption sweeps: a small good file (f16, s8, s8s6) with one byte changed
  (xor 0x55) at 400 evenly spread offsets: both readers accept and refuse
  the same files (a changed byte anywhere must be refused: CRCs);
- the s8 and s8s6 bakes against the f16 one: every coefficient within
  half its index's step (plus f16 rounding), scales the largest |c| per
  index;
- parts (vdsh-bake --shard I/3, f32): read as parts by both readers, each
  stream the whole f32 bake's rows of its range, reconstruct refusing a
  vertex outside it;
- an adaptive bake (vdsh-bake --adaptive): its `adpt` chunk read alike;
- orders 7 and 12, and adaptive-order bakes (variable-order streams) in
  s8s6, f16 and f32: their per-order vertex counts read alike;
- reconstruction: for the default bake's order-5 log stream, distances
  toward 64 directions at 50 vertices equal exp of the SH sum clamped to
  max_distance, and lie in (0, max_distance].
"""
import glob
import json
import os
import shutil
import subprocess
import sys
import zlib

import numpy as np

import testlib

bake, info, src, work = sys.argv[1:5]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
fail = []

# Install the package as a user would, from the checkout itself; the
# checkout must stay as it was (every file, ignored ones too; and git's
# view of it where it is a git checkout).
pkg = os.path.join(src, "python")


def tree(top):
    return {os.path.relpath(os.path.join(d, n), top)
            for d, dirs, files in os.walk(top) for n in dirs + files}


def git_status():
    try:
        r = subprocess.run(["git", "-C", src, "status", "--porcelain", "--ignored", "--",
                            "python"], capture_output=True, text=True)
    except OSError:
        return None
    return r.stdout if r.returncode == 0 else None


before, git_before = tree(pkg), git_status()
target = os.path.join(work, "site")
r = testlib.pip_install(pkg, target)
left = sorted(tree(pkg) - before)
git_after = git_status()
for rel in left:  # report, then leave the checkout clean
    path = os.path.join(pkg, rel)
    if os.path.isdir(path) and not os.path.islink(path):
        shutil.rmtree(path, ignore_errors=True)
    elif os.path.lexists(path):
        os.remove(path)
if left:
    fail.append("pip install ./python left in the checkout: %s"
                % ", ".join(x for x in left if os.sep not in x))
if git_before is not None and git_after != git_before:
    fail.append("git status of python/ changed by pip install: %r -> %r" % (git_before, git_after))
if r.returncode:
    sys.exit("FAIL: pip install ./python: %s" % r.stderr)
sys.path.insert(0, target)
import vdsh  # noqa: E402

assert vdsh.__file__.startswith(target), vdsh.__file__

# The spec's table of values (VDSH.md, Conventions).
table = {(0.48, 0.6, 0.64): [0.282095, -0.293162, 0.312706, -0.234529, 0.314654, -0.419539,
                             0.072162, -0.335631, -0.070797, -0.117253, 0.532798, -0.287390,
                             -0.227369, -0.229912, -0.119879, 0.240625, -0.093437, -0.225127,
                             0.508809, 0.034118, -0.361361, 0.027295, -0.114482, 0.461999,
                             -0.197126],
         (1, 0, 0): [0.282095, 0, 0, -0.488603, 0, 0, -0.315392, 0, 0.546274, 0, 0, 0, 0,
                     0.457046, 0, -0.590044, 0, 0, 0, 0, 0.317357, 0, -0.473087, 0, 0.625836]}
for d, want in table.items():
    got = vdsh.sh_basis(5, [d])[0]
    if np.abs(got - want).max() > 2e-6:
        fail.append("sh_basis%s: %s" % (d, np.round(got, 6)))


def c_reader(path):
    r = subprocess.run([info, "--json", "-", path], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    d = json.loads(r.stdout)
    return d if d.get("valid") else None


def py_reader(path):
    try:
        return vdsh.read(path)
    except vdsh.VdshError as e:
        return str(e)


def close(a, b, rel=1e-5):
    return abs(a - b) <= rel * max(1.0, abs(a), abs(b))


def compare(path):
    c, p = c_reader(path), py_reader(path)
    if (c is None) != isinstance(p, str):
        fail.append("%s: C %s, Python %s" % (path, "refuses" if c is None else "accepts",
                                             p if isinstance(p, str) else "accepts"))
        return None
    if c is None:
        return None
    h, b = p.header, c["bake"]
    pairs = [("vertex_count", c["vertex_count"], h["vertex_count"]),
             ("triangle_count", c["triangle_count"], h["triangle_count"]),
             ("rays", b["rays"], h["rays"]), ("sampling", b["sampling"], h["sampling"]),
             ("seed", b["seed"], h["seed"]), ("cube_size", b["cube_size"], h["cube_size"]),
             ("streams", len(c["streams"]), len(p.streams)),
             ("sources", len(c["sources"]), len(p.sources))]
    for k, a, v in pairs:
        if a != v:
            fail.append("%s: %s: C %s, Python %s" % (path, k, a, v))
    if not close(b["max_distance"], h["max_distance"]):
        fail.append("%s: max_distance" % path)
    for cs, ps in zip(c["streams"], p.streams):
        for k in ("order", "encoding", "quantity", "window", "method_id"):
            if cs[k] != ps[k]:
                fail.append("%s: stream %s: C %s, Python %s" % (path, k, cs[k], ps[k]))
        if not close(cs["scale"], ps["scale"]):
            fail.append("%s: stream scale" % path)
        if cs.get("variable_order", False) != ps["variable_order"] or (
                ps["variable_order"] and list(np.bincount(ps["orders"], minlength=ps["order"] + 1)[1:])
                != cs["vertices_per_order"]):
            fail.append("%s: variable order: C %s, Python %s" % (
                path, cs.get("vertices_per_order"), ps["orders"]))
        c0 = vdsh.coefficients(ps)[:, 0]
        for k, v in (("min", c0.min()), ("max", c0.max()), ("mean", c0.astype(np.float64).mean())):
            if not close(cs["coefficient0"][k], float(v), 1e-5):
                fail.append("%s: order %d coefficient0 %s: C %s, Python %s"
                            % (path, ps["order"], k, cs["coefficient0"][k], v))
    if c.get("stats") and p.stats and c["stats"] != {k: p.stats[k] for k in c["stats"]}:
        fail.append("%s: stats differ" % path)
    # vdsh-info's part carries a cpca part's light pool (lpol) as four keys;
    # the Python reader keeps the pool apart, as f.light_pool.
    pp = dict(p.part) if p.part else p.part
    if pp and pp["encoding"] == "cpca":
        lp = p.light_pool
        pp.update(cpca_light_mix=float(lp["mix"]) if lp else 0.0,
                  cpca_light_pool=len(lp["lights"]) if lp else 0,
                  cpca_margin=float(lp["margin"]) if lp else 0.0,
                  cpca_starts=lp["starts"] if lp else 0)
    if c.get("part") != pp:
        fail.append("%s: part: C %s, Python %s" % (path, c.get("part"), pp))
    ca, pa = c.get("adaptive"), p.adaptive
    if (ca is None) != (pa is None) or (ca and any(
            not close(ca[k], pa[k]) for k in ("tolerance", "min_edge")) or ca and any(
            ca[k] != pa[k] for k in ("max_receivers", "lights", "max_rounds", "start_receivers",
                                     "rounds", "candidates"))):
        fail.append("%s: adaptive: C %s, Python %s" % (path, ca, pa))
    # the light region (lreg, vdsh-bake --light-region): rule and box
    cl, pl = c.get("light_region"), p.light_region
    if (cl is None) != (pl is None) or (cl and (cl["rule"] != pl["rule"] or any(
            not close(a, b) for k in ("min", "max") for a, b in zip(cl[k], pl[k])))):
        fail.append("%s: light region: C %s, Python %s" % (path, cl, pl))
    return p


baked = {}
for name, args in (("default", []), ("paper-f32", ["--method", "paper", "--encoding", "f32"]),
                   ("lsq-auto", ["--method", "lsq", "--quantity", "auto"]),
                   ("hann", ["--method", "lsq", "--window", "hann"]),
                   ("timings", ["--record-timings", "--orders", "3", "--encoding", "f16"]),
                   ("f16", ["--encoding", "f16"]),
                   ("f32", ["--encoding", "f32"]),
                   ("s8", ["--encoding", "s8"]),
                   ("s8-small", ["--encoding", "s8", "--orders", "3"]),
                   ("s8s6", ["--encoding", "s8s6"]),
                   ("s8s6-small", ["--encoding", "s8s6", "--orders", "3,5"]),
                   ("adaptive", ["--adaptive", "0.05"]),
                   ("light-region", ["--light-region", "-1,0.5,-2,9,2.5,7"]),
                   ("order12", ["--orders", "7,12", "--encoding", "f16"]),
                   ("cpca-small", ["--orders", "7", "--encoding", "cpca", "--cpca", "3,9,4"]),
                   ("adaptive-order", ["--adaptive-order", "0.02", "--max-order", "9",
                                       "--orders", "3"]),
                   ("adaptive-order-f16", ["--adaptive-order", "0.02", "--encoding", "f16"]),
                   ("adaptive-order-f32", ["--adaptive-order", "0.02", "--encoding", "f32"])):
    out = os.path.join(work, name + ".vdsh")
    e = testlib.bake_room(bake, out, "1.5", "256", args)
    if e is not None:
        fail.append("bake %s: %s" % (name, e))
        continue
    baked[name] = compare(out)

# Parts (vdsh-bake --shard I/N): streams of the range's rows only, equal to
# those rows of the whole bake's f32 streams.
whole = baked.get("f32")
for i in range(3):
    out = os.path.join(work, "part-%d.vdsh" % i)
    r = subprocess.run([bake, "builtin:room", "--max-edge", "1.5", "--rays", "256", "-q",
                        "--cube-size", "0", "--encoding", "f32", "--shard", "%d/3" % i,
                        "-o", out], capture_output=True, text=True)
    if r.returncode:
        fail.append("bake part %d: %s" % (i, r.stderr.strip()))
        continue
    part = baked["part-%d" % i] = compare(out)
    if not (part and whole and part.part):
        fail.append("part %d: not read as a part" % i)
        continue
    b, e = part.part["range_begin"], part.part["range_end"]
    if part.part["index"] != i or part.part["count"] != 3 or not 0 <= b < e:
        fail.append("part %d: %s" % (i, part.part))
    for ps, ws in zip(part.streams, whole.streams):
        if vdsh.coefficients(ps).shape[0] != e - b or \
                not np.array_equal(vdsh.coefficients(ps), vdsh.coefficients(ws)[b:e]):
            fail.append("part %d order %d: not the whole bake's rows %d..%d"
                        % (i, ps["order"], b, e))
    ps = part.streams[-1]
    try:
        vdsh.reconstruct(part, ps, e, np.array([[0.0, 0.0, 1.0]]))
        fail.append("part %d: reconstruct outside its range accepted" % i)
    except vdsh.VdshError:
        pass
    if not np.allclose(vdsh.reconstruct(part, ps, b, np.array([[0.0, 0.0, 1.0]])),
                       vdsh.reconstruct(whole, whole.streams[-1], b, np.array([[0.0, 0.0, 1.0]]))):
        fail.append("part %d: reconstruct at vertex %d" % (i, b))

corpus = sorted(glob.glob(os.path.join(src, "tests", "corpus", "vdsh", "*")))
accepted = sum(compare(f) is not None for f in corpus)
print("corpus: %d files, %d accepted by both" % (len(corpus), accepted))

# Corruption sweeps on the smallest baked files (f16, and s8 with its
# scale table).
for small in ("timings", "s8-small", "s8s6-small", "cpca-small"):
    good = os.path.join(work, small + ".vdsh")
    data = open(good, "rb").read()
    bad = os.path.join(work, "bad.vdsh")
    refused = 0
    for off in np.linspace(0, len(data) - 1, 400).astype(int):
        d = bytearray(data)
        d[off] ^= 0x55
        open(bad, "wb").write(d)
        c_ok = c_reader(bad) is not None
        p_ok = not isinstance(py_reader(bad), str)
        if c_ok != p_ok:
            fail.append("%s: corrupt byte %d: C %s, Python %s" % (small, off, c_ok, p_ok))
        refused += not p_ok
    print("corruption sweep (%s): 400 files, %d refused by both" % (small, refused))
    if refused != 400:
        fail.append("%s: a changed byte was accepted (%d of 400 refused)" % (small, refused))

# A file of a later format version (the header's version word 2): the
# version is checked before the header CRC, as formats/vdsh_read.c does
# (a later version may lay its header out otherwise), so both readers say
# "format version 2", with the CRC recomputed and with it left stale (then
# adding that the CRC fails too); before, Python said "header CRC
# mismatch" for the stale one.
good = open(os.path.join(work, "timings.vdsh"), "rb").read()
for fix_crc in (True, False):
    d = bytearray(good)
    d[8:12] = (2).to_bytes(4, "little")
    if fix_crc:
        d[28:32] = zlib.crc32(bytes(d[:28])).to_bytes(4, "little")
    future = os.path.join(work, "future-%s.vdsh" % ("crc" if fix_crc else "stale"))
    open(future, "wb").write(d)
    want = "format version 2, this reader reads version 1"
    also = "" if fix_crc else " (and the header CRC fails"
    pm = py_reader(future)
    cm = subprocess.run([info, future], capture_output=True, text=True).stderr
    for who, m in (("Python", pm), ("C", cm)):
        if not isinstance(m, str) or want + also not in m:
            fail.append("%s: %s reader says %r, want '%s%s'" % (future, who, m, want, also))

# s8 and s8s6 against f16 of the same bake: each coefficient within half
# its step (scale_i / (2 levels_i)) plus f16's own rounding (relative 2^-11
# of its scale).
f16 = baked.get("f16")
for enc in ("s8", "s8s6"):
    q = baked.get(enc)
    if not (f16 and q):
        continue
    for a, b in zip(f16.streams, q.streams):
        ca, cb = vdsh.coefficients(a).astype(np.float64), vdsh.coefficients(b).astype(np.float64)
        tol = b["coef_scales"] / (2.0 * b["levels"]) * (1 + 1e-5) + a["scale"] * 2.0 ** -11
        if b["encoding"] != enc or not (np.abs(ca - cb) <= tol).all():
            fail.append("%s order %d: not within half a step of f16" % (enc, b["order"]))
        if not np.allclose(b["coef_scales"], np.abs(ca).max(axis=0), rtol=1e-3,
                           atol=a["scale"] * 2.0 ** -11):
            fail.append("%s order %d: scales are not the largest |c| per index" % (enc, b["order"]))

f = baked.get("default")
if f:
    s = next(s for s in f.streams if s["order"] == 5)
    rng = np.random.default_rng(1)
    dirs = rng.normal(size=(64, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    for v in rng.choice(f.header["vertex_count"], 50, replace=False):
        d = vdsh.reconstruct(f, s, v, dirs)
        want = np.minimum(np.exp(np.minimum(vdsh.sh_basis(5, dirs) @ vdsh.coefficients(s)[v], 80)),
                          f.header["max_distance"])
        if not (np.allclose(d, want) and (d > 0).all() and (d <= f.header["max_distance"]).all()):
            fail.append("reconstruct at vertex %d" % v)

for m in fail:
    print("FAIL:", m)
print("python reader: %d files compared, %s" % (len(baked) + len(corpus) + 1200,
                                                  "agrees with the C reader" if not fail else "DISAGREES"))
sys.exit(1 if fail else 0)
