#!/usr/bin/python3
"""The cpca encoder's light-density metric (vdsh-bake --cpca ...,light:A;
formats/vdsh_cpca.h; docs/ACCURACY.md, "A light-density metric"):

- light:0 is the uniform metric: the same bytes whether or not a pool
  exists (the default K, B, bits with `light:0` alone, and a part merged);
- light:1 and light:0.5 are other fits, valid files that decode near the
  f32 bake; the default (no light:) is VDSH_CPCA_DEFAULT_LIGHT_MIX's for
  alloc, light:0's for fixed widths (8,54,4); the plain --encoding cpca is
  --help's default settings (16,alloc:32,margin:0.25,starts:3,bases:8) with
  light:1, not 16,alloc:32 said alone (one start, no margin); starts:1
  alone is the default base with its margin;
- bad values are refused with a message naming light:A, exit 2, no file;
- a part carries the pool (`lpol`), vdsh-info shows the mix; vdsh-merge
  refuses parts whose pools differ, naming the part, and a part whose
  lpol is damaged (CRC, a mix out of range) or an lpol in a whole file is
  refused by the C and Python readers;
- a whole bake's --report says the mix and pool it fitted with (the
  file does not record them), vdsh-info says so;
- tests/light_pool_tool's seed bake:1 is the pool a bake of seed 1 places
  (bake.h VB_POOL_SEED, one definition: scripts/cpca_study draws with it);
- a one-shard part's merge equals the whole bake at light:1 (bake_cpca
  checks 2 shards and threads with the default);
- the margin and the starts (--cpca ...,margin:S,starts:N; docs/
  ACCURACY.md "Weighting the light metric by the decision margin",
  "Keeping the best of several k-means starts"): margin:1e6 (every light's
  weight rounds to 1) and starts:1 give light:1's bytes; margin:0.25 is
  another fit, valid, within the bytes per vertex budget; starts:2 keeps
  whichever of the default's and VDSH_CPCA_KMEANS_SEED=1's bytes has the
  fewer pool decisions differing (tests/cpca_kchoice_tool --score, the
  pool the bake fitted with), starts:3 with KMEANS_SEED=1 the fewest of
  seeds 1, 2, 3; margin:0.25,starts:2 in any order is one setting; a part
  records them (lpol, vdsh-info, the Python reader), two shards merge to
  the whole bake's bytes, parts whose margin or starts differ are refused,
  naming the part, and an lpol whose margin is out of range, or set with
  fixed widths, is refused by the C and Python readers; bad values (a
  margin of 0, starts 1.5 or 17, either with K,B,BITS or light:0, an
  option twice) are refused, exit 2, no file;
- the study knobs (formats/vdsh_cpca_study.h): VDSH_CPCA_REFIT_ROUNDS=2
  (the default's rounds) gives light:1's bytes, a value out of range is
  ignored with a message naming the variable; VDSH_CPCA_KMEANS_SEED=1 is
  another fit.

Usage: test_cpca_lightmix.py VDSH_BAKE VDSH_MERGE VDSH_INFO SOURCE_DIR WORK_DIR LIGHT_POOL_TOOL
                             KCHOICE_TOOL
"""
import json
import os
import re
import struct
import subprocess
import sys

import numpy as np

bake, merge, info, src, work, pool_tool, kchoice = sys.argv[1:8]
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402
from testlib import chunks, fix_crc  # noqa: E402

os.makedirs(work, exist_ok=True)
TINY = ["builtin:room", "--max-edge", "1.0", "--rays", "64", "--cube-size", "0", "-q",
        "--orders", "7"]
fail = []


def path(name):
    return os.path.join(work, name)


def run_bake(out, extra):
    return subprocess.run([bake] + TINY + extra + ["-o", path(out)], capture_output=True,
                          text=True)


def blob(name):
    with open(path(name), "rb") as f:
        return f.read()


def must(r, what):
    if r.returncode:
        sys.exit("%s failed: %s" % (what, r.stderr))


must(run_bake("f32.vdsh", ["--encoding", "f32"]), "f32 bake")
ref = vdsh.read(path("f32.vdsh"))
x = vdsh.coefficients(ref.streams[0]).astype(np.float64)
spread = np.sqrt(((x - x.mean(0)) ** 2).sum(1).mean())

CPCA = ["--encoding", "cpca", "--cpca"]
# the default settings, as vdsh-bake --help says them
# (16,alloc:32,margin:0.25,starts:3,bases:8), and their base (16,alloc:32)
helptext = subprocess.run([bake, "--help"], capture_output=True, text=True).stdout
DEFAULT = helptext.split("Default ")[1].split()[0]
BASE = ",".join(DEFAULT.split(",")[:2])
S8 = ",bases:8" if DEFAULT.endswith(",bases:8") else ""  # the default's bases, not the base's
if ",alloc:" not in BASE or ",margin:" not in DEFAULT or ",starts:" not in DEFAULT:
    fail.append("--help's default settings %r are not K,alloc:BYTES,margin:S,starts:N" % DEFAULT)
for name, setting in (("l0", "4,alloc:40,light:0"), ("l05", "4,alloc:40,light:0.5"),
                      ("l1", "4,alloc:40,light:1"), ("def", "4,alloc:40"),
                      ("l0alone", "light:0"), ("l0full", BASE + ",light:0" + S8),
                      ("l1full", DEFAULT + ",light:1"), ("plain", None),
                      ("base", BASE), ("st1alone", "starts:1"),
                      ("st1full", BASE + ",margin:" + DEFAULT.split("margin:")[1].split(",")[0] + S8),
                      ("fixed", "8,54,4"), ("fixed0", "8,54,4,light:0")):
    must(run_bake(name + ".vdsh", CPCA + [setting] if setting else CPCA[:2]), str(setting))
    got = vdsh.coefficients(vdsh.read(path(name + ".vdsh")).streams[0]).astype(np.float64)
    err = np.sqrt(((got - x) ** 2).sum(1).mean()) / spread
    print("%s: decoded error %.4f of the spread" % (setting, err))
    if not err < 0.5:
        fail.append("%s: decoded error %.3f of the spread" % (setting, err))

if blob("l0.vdsh") in (blob("l1.vdsh"), blob("l05.vdsh")) or blob("l1.vdsh") == blob("l05.vdsh"):
    fail.append("light:0, 0.5 and 1 are not three fits")
if blob("l0alone.vdsh") != blob("l0full.vdsh"):
    fail.append("light:0 alone is not the default K and budget with light:0")
# the plain --encoding cpca is the default settings with their (alloc) mix;
# the base said alone is one start without the margin, another fit; an
# option alone keeps the default's others
if blob("plain.vdsh") != blob("l1full.vdsh"):
    fail.append("--encoding cpca without --cpca is not --cpca %s,light:1" % DEFAULT)
if blob("base.vdsh") == blob("plain.vdsh"):
    fail.append("--cpca %s said alone gives the default's bytes (%s)" % (BASE, DEFAULT))
if blob("st1alone.vdsh") != blob("st1full.vdsh") or blob("st1alone.vdsh") == blob("base.vdsh"):
    fail.append("starts:1 alone is not the default base with its margin")
# the default mix, as vdsh-bake --help says it
default = helptext.split("A in 0..1, default ")[1].split()[0]
want = {"0": "l0", "1": "l1"}.get(default)
if want is None or blob("def.vdsh") != blob(want + ".vdsh"):
    fail.append("the default light mix (--help: %r) does not give its bytes" % default)
# fixed widths keep the uniform metric unless told (it lost there)
if blob("fixed.vdsh") != blob("fixed0.vdsh"):
    fail.append("8,54,4 without light: is not the uniform metric")

for bad in ("4,alloc:40,light:2", "4,alloc:40,light:-1", "4,alloc:40,light:", "light:abc",
            "4,alloc:40,light:1,2", "light:0.5x", "4,alloc:40,light:nan", "4,alloc:40,light:1e0"):
    r = run_bake("bad.vdsh", CPCA + [bad])
    if r.returncode != 2 or "light:A" not in r.stderr or os.path.exists(path("bad.vdsh")):
        fail.append("--cpca %s: exit %d, file %s, stderr %r" % (
            bad, r.returncode, os.path.exists(path("bad.vdsh")), r.stderr))

# Parts: the pool in `lpol`, shown by vdsh-info; one shard merged is the
# whole bake.
for name, setting in (("p1", "4,alloc:40,light:1"), ("p05", "4,alloc:40,light:0.5"),
                      ("p0", "4,alloc:40,light:0")):
    must(run_bake(name + ".vdsh", CPCA + [setting, "--shard", "0/1"]), setting + " part")
p1 = vdsh.read(path("p1.vdsh"))
if p1.light_pool is None or len(p1.light_pool["lights"]) != 2048 or p1.light_pool["mix"] != 1:
    fail.append("the light:1 part's lpol: %r" % (p1.light_pool and {
        k: (len(v) if k == "lights" else v) for k, v in p1.light_pool.items()}))
r = subprocess.run([pool_tool, "builtin:room", "2048", "bake:1", path("pool.f32")],
                   capture_output=True, text=True)
if r.returncode or np.asarray(p1.light_pool["lights"], dtype="<f4").tobytes() != blob("pool.f32"):
    fail.append("light_pool_tool bake:1 is not the part's pool: %s" % r.stderr)
if vdsh.read(path("p0.vdsh")).light_pool is not None:
    fail.append("a light:0 part carries a pool")
for whole in ("l1.vdsh", "def.vdsh"):
    if vdsh.read(path(whole)).light_pool is not None or b"lpol" in blob(whole):
        fail.append("%s (a whole file) carries lpol" % whole)
txt = subprocess.run([info, path("p1.vdsh")], capture_output=True, text=True).stdout
if "cpca 4,alloc:40,light:1 (fitted at the merge; light pool of 2048 lights)" not in txt:
    fail.append("vdsh-info does not show the part's light mix: %r" % txt)
for name, want in (("p1", "l1"), ("p0", "l0")):
    r = subprocess.run([merge, "-q", path(name + ".vdsh"), "-o", path(name + "-m.vdsh")],
                       capture_output=True, text=True)
    if r.returncode or blob(name + "-m.vdsh") != blob(want + ".vdsh"):
        fail.append("%s merged is not the whole %s bake: %s" % (name, want, r.stderr))

# The study knobs, in the environment of the bake (its encoder), and the
# margin and starts settings.
def knob_bake(name, env, setting="4,alloc:40,light:1"):
    r = subprocess.run([bake] + TINY + CPCA + [setting, "-o", path(name)],
                       capture_output=True, text=True, env=dict(os.environ, **env))
    must(r, "%s %s bake" % (env, setting))
    return r.stderr


for name, env, setting in (("k-wide.vdsh", {}, "4,alloc:40,margin:1000000,light:1"),
                           ("k-r2.vdsh", {"VDSH_CPCA_REFIT_ROUNDS": "2"}, "4,alloc:40,light:1"),
                           ("k-st1.vdsh", {}, "4,alloc:40,starts:1")):
    knob_bake(name, env, setting)
    if blob(name) != blob("l1.vdsh"):
        fail.append("%s %s does not give light:1's bytes" % (env, setting))
for var, val in (("VDSH_CPCA_KMEANS_SEED", "70000"), ("VDSH_CPCA_REFIT_ROUNDS", "-1")):
    err = knob_bake("k-bad.vdsh", {var: val})
    if blob("k-bad.vdsh") != blob("l1.vdsh") or var not in err or "ignored" not in err:
        fail.append("%s=%s: not ignored with a message (stderr %r)" % (var, val, err))
for name, env, setting in (("k-m.vdsh", {}, "4,alloc:40,light:1,margin:0.25"),
                           ("k-seed.vdsh", {"VDSH_CPCA_KMEANS_SEED": "1"}, "4,alloc:40,light:1")):
    knob_bake(name, env, setting)
    st = vdsh.read(path(name)).streams[0]
    got = vdsh.coefficients(st).astype(np.float64)
    err = np.sqrt(((got - x) ** 2).sum(1).mean()) / spread
    print("%s %s: decoded error %.4f of the spread" % (env, setting, err))
    if blob(name) == blob("l1.vdsh") or not err < 0.5:
        fail.append("%s %s: not another valid fit (decoded error %.3f)" % (env, setting, err))
    txt = subprocess.run([info, path(name)], capture_output=True, text=True).stdout
    per = re.search(r"([0-9.]+) with the model", txt)
    if not per or not float(per.group(1)) <= 40.0:
        fail.append("%s %s: not within the 40-byte budget: %r" % (env, setting, txt))
for bad in ("4,alloc:40,margin:0", "4,alloc:40,margin:-1", "4,alloc:40,margin:1e6",
            "4,alloc:40,margin:2000000", "4,alloc:40,starts:0", "4,alloc:40,starts:1.5",
            "4,alloc:40,starts:17", "8,54,4,margin:0.25", "auto,starts:2",
            "4,alloc:40,light:0,starts:2", "4,alloc:40,starts:2,starts:2",
            "4,alloc:40,margin:0.25,foo:1"):
    r = run_bake("bad.vdsh", CPCA + [bad])
    # the usage message names --help's default (both from the macros)
    if r.returncode != 2 or "margin:S" not in r.stderr or os.path.exists(path("bad.vdsh")) \
            or "(default %s)" % DEFAULT not in r.stderr:
        fail.append("--cpca %s: exit %d, file %s, stderr %r" % (
            bad, r.returncode, os.path.exists(path("bad.vdsh")), r.stderr))


# starts:N: the start whose decisions over the bake's pool (pool.f32,
# bake:1) differ from the f32 stream's at the fewest pairs.
def disagree(names):
    r = subprocess.run([kchoice, "--score", path("f32.vdsh"), path("pool.f32")] +
                       [path(n) for n in names], capture_output=True, text=True)
    must(r, "cpca_kchoice_tool --score")
    return [json.loads(line)["disagree"] for line in r.stdout.splitlines()]


for seed in ("2", "3"):
    knob_bake("k-seed%s.vdsh" % seed, {"VDSH_CPCA_KMEANS_SEED": seed})
for name, env, setting, cands in (
        ("k-st2.vdsh", {}, "4,alloc:40,starts:2", ["l1.vdsh", "k-seed.vdsh"]),
        ("k-st3.vdsh", {"VDSH_CPCA_KMEANS_SEED": "1"}, "4,alloc:40,starts:3",
         ["k-seed.vdsh", "k-seed2.vdsh", "k-seed3.vdsh"])):
    knob_bake(name, env, setting)
    d = disagree(cands)
    keep = cands[d.index(min(d))]
    print("%s %s: decisions differing %s, keeps %s" % (env, setting, d, keep))
    if len(set(blob(c) for c in cands)) != len(cands) or blob(name) != blob(keep):
        fail.append("%s %s: not the bytes of %s (fewest decisions differing of %s: %s)" % (
            env, setting, keep, cands, d))

# margin and starts together (each start with the margin), in either
# order, and through two shards
MS = "4,alloc:40,margin:0.25,starts:2"
knob_bake("k-ms.vdsh", {}, MS)
knob_bake("k-sm.vdsh", {}, "4,alloc:40,starts:2,light:1,margin:0.25")
knob_bake("k-mseed.vdsh", {"VDSH_CPCA_KMEANS_SEED": "1"}, "4,alloc:40,light:1,margin:0.25")
cands = ["k-m.vdsh", "k-mseed.vdsh"]
d = disagree(cands)
keep = cands[d.index(min(d))]
print("%s: decisions differing %s, keeps %s" % (MS, d, keep))
if blob("k-ms.vdsh") != blob("k-sm.vdsh") or blob("k-ms.vdsh") != blob(keep) or \
        blob("k-m.vdsh") == blob("k-mseed.vdsh"):
    fail.append("%s: not one setting in either order, or not the bytes of %s (of %s: %s)" % (
        MS, keep, cands, d))
for i in (0, 1):
    must(run_bake("ms%d.vdsh" % i, CPCA + [MS, "--shard", "%d/2" % i]), "%s shard %d" % (MS, i))
r = subprocess.run([merge, "-q", path("ms0.vdsh"), path("ms1.vdsh"), "-o", path("ms-m.vdsh")],
                   capture_output=True, text=True)
if r.returncode or blob("ms-m.vdsh") != blob("k-ms.vdsh"):
    fail.append("%s: two shards merged are not the whole bake: %s" % (MS, r.stderr))
lp = vdsh.read(path("ms0.vdsh")).light_pool
if not lp or lp["margin"] != 0.25 or lp["starts"] != 2 or lp["mix"] != 1:
    fail.append("%s part's lpol in the Python reader: %r" % (MS, lp and {
        k: v for k, v in lp.items() if k != "lights"}))
txt = subprocess.run([info, path("ms0.vdsh")], capture_output=True, text=True).stdout
if "cpca 4,alloc:40,light:1,margin:0.25,starts:2 (fitted at the merge" not in txt:
    fail.append("vdsh-info does not show the part's margin and starts: %r" % txt)
must(run_bake("ms1b.vdsh", CPCA + ["4,alloc:40,margin:0.25,starts:3", "--shard", "1/2"]),
     "starts:3 shard")
r = subprocess.run([merge, "-q", path("ms0.vdsh"), path("ms1b.vdsh"), "-o", path("ms-x.vdsh")],
                   capture_output=True, text=True)
if r.returncode == 0 or "ms1b.vdsh" not in r.stderr or "starts" not in r.stderr or \
        os.path.exists(path("ms-x.vdsh")):
    fail.append("parts with other starts: exit %d, stderr %r" % (r.returncode, r.stderr))

# A whole file does not record the mix or the pool (VDSH.md "cpca
# streams"): the bake's --report says them, vdsh-info says where to look.
for name, setting, mix, pool in (("r05", "4,alloc:40,light:0.5", 0.5, 2048),
                                 ("r0", "4,alloc:40,light:0", 0.0, 0),
                                 ("rfix", "8,54,4", 0.0, 0)):
    must(run_bake(name + ".vdsh", CPCA + [setting, "--report", path(name + ".json")]), setting)
    with open(path(name + ".json")) as f:
        cp = json.load(f).get("cpca")
    k = int(setting.split(",")[0])
    if not cp or cp.get("light_mix") != mix or cp.get("light_pool") != pool or \
            cp.get("clusters") != k:
        fail.append("--cpca %s: the report's cpca %r (want light_mix %g, light_pool %d)" % (
            setting, cp, mix, pool))
    txt = subprocess.run([info, path(name + ".vdsh")], capture_output=True, text=True).stdout
    if "light mix and pool not recorded in a whole file (vdsh-bake --report" not in txt:
        fail.append("vdsh-info of a whole cpca file does not say where the mix is: %r" % txt)
must(run_bake("rs8.vdsh", ["--report", path("rs8.json")]), "s8s6 bake")
with open(path("rs8.json")) as f:
    if json.load(f).get("cpca", 0) is not None:
        fail.append("an s8s6 bake's report has a cpca object")

# Two shards whose pools differ: refused, naming the part.
for i, setting in ((0, "4,alloc:40,light:1"), (1, "4,alloc:40,light:0.5")):
    must(run_bake("s%d.vdsh" % i, CPCA + [setting, "--shard", "%d/2" % i]), "shard %d" % i)
r = subprocess.run([merge, "-q", path("s0.vdsh"), path("s1.vdsh"), "-o", path("mix.vdsh")],
                   capture_output=True, text=True)
if r.returncode == 0 or "s1.vdsh" not in r.stderr or "light pool" not in r.stderr or \
        os.path.exists(path("mix.vdsh")):
    fail.append("parts with other pools: exit %d, stderr %r" % (r.returncode, r.stderr))


def refused(name, data, words):
    """The C reader (via vdsh-info and vdsh-merge) and the Python reader
    refuse data, saying each of words."""
    with open(path(name), "wb") as f:
        f.write(data)
    for cmd in ([info, path(name)], [merge, "-q", path(name), "-o", path(name + "-m")]):
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode == 0 or name not in r.stderr or not all(w in r.stderr for w in words) or \
                os.path.exists(path(name + "-m")):
            fail.append("%s: %s: exit %d, stderr %r" % (name, os.path.basename(cmd[0]),
                                                        r.returncode, r.stderr))
    try:
        vdsh.read(path(name))
        fail.append("%s: the Python reader accepts it" % name)
    except vdsh.VdshError as e:
        if not all(w in str(e) for w in words if w != "CRC"):
            fail.append("%s: the Python reader says %r" % (name, str(e)))


d = bytearray(blob("p1.vdsh"))
off, _, size = next(c for c in chunks(d) if c[1] == b"lpol")
bad = bytearray(d)
bad[off + 16 + 16 + 5] ^= 0x40  # a light's byte, the CRC left
refused("lpol-crc.vdsh", bad, ["CRC"])
bad = bytearray(d)
struct.pack_into("<f", bad, off + 16 + 4, 0.0)  # mix 0, the CRC fixed
fix_crc(bad, off, size)
refused("lpol-mix0.vdsh", bad, ["lpol", "light mix"])
bad = bytearray(d)
struct.pack_into("<I", bad, off + 16, 2047)  # a count the size does not hold
fix_crc(bad, off, size)
refused("lpol-count.vdsh", bad, ["lpol"])
# an lpol in a whole file: the part chunk removed (its id turned into an
# unknown ancillary one is still skipped, so lpol is then outside a part)
bad = bytearray(d)
poff, _, psize = next(c for c in chunks(d) if c[1] == b"part")
bad[poff:poff + 4] = b"xprt"
fix_crc(bad, poff, psize)
refused("lpol-whole.vdsh", bad, ["lpol", "outside a cpca part"])
d = bytearray(blob("ms0.vdsh"))
off, _, size = next(c for c in chunks(d) if c[1] == b"lpol")
bad = bytearray(d)
struct.pack_into("<f", bad, off + 16 + 8, -0.25)  # a negative margin, the CRC fixed
fix_crc(bad, off, size)
refused("lpol-margin.vdsh", bad, ["lpol", "margin"])
bad = bytearray(d)
struct.pack_into("<I", bad, off + 16 + 12, 17)  # 17 starts
fix_crc(bad, off, size)
refused("lpol-starts.vdsh", bad, ["lpol", "starts"])
# a margin with fixed widths: the part chunk's bits set (K,B,BITS 4,40,4)
bad = bytearray(d)
poff, _, psize = next(c for c in chunks(d) if c[1] == b"part")
struct.pack_into("<I", bad, poff + 16 + 28, 4)
fix_crc(bad, poff, psize)
refused("lpol-fixed.vdsh", bad, ["lpol", "K,alloc:BYTES"])

if fail:
    sys.exit("FAIL:\n  " + "\n  ".join(fail))
print("ok")
