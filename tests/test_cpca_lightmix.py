#!/usr/bin/python3
"""The cpca encoder's light-density study hook (formats/vdsh_cpca.c,
VDSH_CPCA_LIGHTMIX; docs/ACCURACY.md, "A light-density metric"): off by
default; on with a = 0 it writes today's bytes; with a = 1 another fit,
still a valid file that decodes near the f32 bake; an unusable setting
(positions of the wrong length, a outside 0..1) is an error naming the
variables, the bake exits non-zero and writes no file.

Usage: test_cpca_lightmix.py VDSH_BAKE LIGHT_POOL_TOOL SOURCE_DIR WORK_DIR
"""
import os
import subprocess
import sys

import numpy as np

bake, pool_tool, src, work = sys.argv[1:5]
sys.path.insert(0, os.path.join(src, "python"))
import vdsh  # noqa: E402

os.makedirs(work, exist_ok=True)
TINY = ["builtin:room", "--max-edge", "1.0", "--rays", "64", "--cube-size", "0", "-q",
        "--orders", "7"]
CPCA = ["--encoding", "cpca", "--cpca", "4,alloc:40"]
HOOK = ("VDSH_CPCA_LIGHTMIX", "VDSH_CPCA_LIGHTS", "VDSH_CPCA_POSITIONS")
fail = []


def run_bake(out, extra, env=None):
    e = {k: v for k, v in os.environ.items() if k not in HOOK}
    e.update(env or {})
    return subprocess.run([bake] + TINY + extra + ["-o", out], env=e, capture_output=True,
                          text=True)


def path(name):
    return os.path.join(work, name)


r = run_bake(path("f32.vdsh"), ["--encoding", "f32"])
r2 = run_bake(path("plain.vdsh"), CPCA)
if r.returncode or r2.returncode:
    sys.exit("bake failed: %s %s" % (r.stderr, r2.stderr))
ref = vdsh.read(path("f32.vdsh"))
np.asarray(ref.positions, "<f4").tofile(path("pos.f32"))
subprocess.run([pool_tool, "builtin:room", "256", "7", path("pool.f32")], check=True,
               stdout=subprocess.DEVNULL)
lights = np.fromfile(path("pool.f32"), "<f4").reshape(-1, 3)
if len(lights) != 256 or not np.isfinite(lights).all():
    fail.append("light_pool_tool: %d lights" % len(lights))
hook = dict(VDSH_CPCA_LIGHTS=path("pool.f32"), VDSH_CPCA_POSITIONS=path("pos.f32"))


def blob(name):
    with open(path(name), "rb") as f:
        return f.read()


x = vdsh.coefficients(ref.streams[0]).astype(np.float64)
spread = np.sqrt(((x - x.mean(0)) ** 2).sum(1).mean())
for a in ("0", "1"):
    name = "mix%s.vdsh" % a
    r = run_bake(path(name), CPCA, dict(hook, VDSH_CPCA_LIGHTMIX=a))
    if r.returncode:
        fail.append("a = %s: bake failed: %s" % (a, r.stderr))
        continue
    same = blob(name) == blob("plain.vdsh")
    if same != (a == "0"):
        fail.append("a = %s: bytes %s today's" % (a, "equal" if same else "differ from"))
    got = vdsh.coefficients(vdsh.read(path(name)).streams[0]).astype(np.float64)
    err = np.sqrt(((got - x) ** 2).sum(1).mean()) / spread
    if not err < 0.5:
        fail.append("a = %s: decoded error %.3f of the spread" % (a, err))
    print("a = %s: %s today's bytes, decoded error %.4f of the spread" % (
        a, "same as" if same else "not", err))

np.asarray(ref.positions, "<f4")[:-1].tofile(path("short.f32"))
for what, env in (("short positions", dict(hook, VDSH_CPCA_LIGHTMIX="0.5",
                                           VDSH_CPCA_POSITIONS=path("short.f32"))),
                  ("a = 2", dict(hook, VDSH_CPCA_LIGHTMIX="2")),
                  ("no pool", dict(VDSH_CPCA_LIGHTMIX="0.5",
                                   VDSH_CPCA_POSITIONS=path("pos.f32")))):
    out = path("bad.vdsh")
    r = run_bake(out, CPCA, env)
    if r.returncode == 0 or "VDSH_CPCA_POSITIONS" not in r.stderr or os.path.exists(out):
        fail.append("%s: exit %d, file %s, stderr %r" % (what, r.returncode,
                                                         os.path.exists(out), r.stderr))
if fail:
    sys.exit("FAIL:\n  " + "\n  ".join(fail))
print("ok")
