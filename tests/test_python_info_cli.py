"""test_python_info_cli.py SRC_DIR WORK - `python -m vdsh info` (python/,
imported from the checkout) on what a user may hand it, as the C programs
take it (README "Bad input and hard cases", formats/vdsh_output.h):
- `--json OUT` naming the input itself: refused (exit 1, naming it) before
  anything is written; the input unchanged;
- `--json` into a missing folder or onto a directory: refused (exit 1,
  naming the path), nothing written;
- `--json /dev/stdout` with stdout redirected to a file (a link to
  /proc/self/fd/1 in WORK stands for /dev/stdout): the JSON in the file, the
  link left a link (a rename over it used to replace /dev/stdout itself);
- a new JSON file has mode 0666 less the umask, no temporary left beside it;
- inputs that are not regular files (/dev/zero, a FIFO with no writer):
  exit 1 naming the file, at once (they used to exhaust memory and hang);
- the library's shadows() with lights that are not L x 3 positions: a
  ValueError saying so.
"""
import glob
import json
import os
import shutil
import stat
import subprocess
import sys

src, work = sys.argv[1:3]
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
env = dict(os.environ, PYTHONPATH=os.path.join(src, "python"), PYTHONDONTWRITEBYTECODE="1")
fail = []


def info(*args, **kw):
    return subprocess.run([sys.executable, "-m", "vdsh", "info"] + list(args), env=env,
                          capture_output=True, text=True, timeout=60, **kw)


good = os.path.join(work, "cube.vdsh")
shutil.copy(os.path.join(src, "tests", "corpus", "vdsh", "cube-s8-orders1235.vdsh"), good)
before = open(good, "rb").read()

# the listing's plurals, as vdsh-info's: order 1 has "1 coefficient"
r = info(good)
if r.returncode or "order 1 (1 coefficient)," not in r.stdout or "(1 coefficients)" in r.stdout:
    fail.append("info cube.vdsh: order 1's count not in the singular: %r" % r.stdout[:600])

r = info("--json", good, good)
if r.returncode != 1 or good not in r.stderr or open(good, "rb").read() != before:
    fail.append("--json onto its input: exit %d, %r, input %s" % (
        r.returncode, r.stderr, "unchanged" if open(good, "rb").read() == before else "CHANGED"))

for out in (os.path.join(work, "no-such-folder", "x.json"), work):
    r = info("--json", out, good)
    if r.returncode != 1 or out not in r.stderr or r.stdout:
        fail.append("--json %s: exit %d, %r" % (out, r.returncode, r.stderr))
if os.path.exists(os.path.join(work, "no-such-folder")):
    fail.append("a missing folder was created")

r = info("--json=", good)
if r.returncode != 2 or "--json" not in r.stderr:
    fail.append("--json= (no name): exit %d, %r" % (r.returncode, r.stderr))

link, redirected = os.path.join(work, "stdout-link"), os.path.join(work, "redirected.json")
os.symlink("/proc/self/fd/1", link)
with open(redirected, "w") as fh:
    r = subprocess.run([sys.executable, "-m", "vdsh", "info", "--json", link, good], env=env,
                       stdout=fh, stderr=subprocess.PIPE, text=True, timeout=60)
if r.returncode or not os.path.islink(link):
    fail.append("--json through /proc/self/fd/1: exit %d, %r, the link %s" % (
        r.returncode, r.stderr, "kept" if os.path.islink(link) else "REPLACED"))
else:
    try:
        if json.load(open(redirected))["vertex_count"] <= 0:
            fail.append("--json through /proc/self/fd/1: no vertices")
    except (ValueError, KeyError) as e:
        fail.append("--json through /proc/self/fd/1: the file holds no JSON (%s)" % e)

out = os.path.join(work, "new.json")
mask = os.umask(0o022)
os.umask(mask)
r = info("--json", out, good)
mode = stat.S_IMODE(os.stat(out).st_mode) if os.path.exists(out) else None
if r.returncode or mode != 0o666 & ~mask:
    fail.append("--json new file: exit %d, mode %s (want %o)" % (
        r.returncode, None if mode is None else "%o" % mode, 0o666 & ~mask))
if glob.glob(os.path.join(work, "*.tmp.*")):
    fail.append("temporaries left: %s" % glob.glob(os.path.join(work, "*.tmp.*")))

fifo = os.path.join(work, "fifo")
os.mkfifo(fifo)
for path in ("/dev/zero", fifo):
    try:
        r = info(path)
        if r.returncode != 1 or path not in r.stderr or "Traceback" in r.stderr:
            fail.append("info %s: exit %d, %r" % (path, r.returncode, r.stderr[-300:]))
    except subprocess.TimeoutExpired:
        fail.append("info %s: still running after 60 s" % path)

# A file cut short (a download stopped) is "truncated" with its size, as
# vdsh-info says, also within the 32-byte header (was "not a .vdsh file
# (magic)"); a damaged magic is not called truncated.
for cut in (0, 5, 8, 20, 31, 32, 100, len(before) - 1):
    path = os.path.join(work, "cut-%d.vdsh" % cut)
    open(path, "wb").write(before[:cut])
    r = info(path)
    if r.returncode != 1 or "truncated: %d bytes" % cut not in r.stderr or path not in r.stderr:
        fail.append("info %s (%d bytes): exit %d, %r" % (path, cut, r.returncode, r.stderr[-300:]))
path = os.path.join(work, "not-vdsh.vdsh")
open(path, "wb").write(b"VDSX" + before[4:20])
r = info(path)
if r.returncode != 1 or "truncated" in r.stderr or "not a .vdsh file" not in r.stderr:
    fail.append("info %s: exit %d, %r" % (path, r.returncode, r.stderr[-300:]))

# A distance volume (its magic begins "VDSH") and a glb are named for what
# they are, as vdsh-info names them.
for name, head, what in (("volume.sdf", b"VDSHSDF\0", "a VDSH distance volume"),
                         ("scene.glb", b"glTF\2\0\0\0", "a binary glTF")):
    path = os.path.join(work, name)
    open(path, "wb").write(head + bytes(64))
    r = info(path)
    if r.returncode != 1 or "not a .vdsh file: " + what not in r.stderr or path not in r.stderr:
        fail.append("info %s: exit %d, %r" % (path, r.returncode, r.stderr[-300:]))

# The library: lights that are not positions are named as such (was
# numpy's "cannot reshape array of size 4 into shape (3)").
sys.path.insert(0, os.path.join(src, "python"))
sys.dont_write_bytecode = True
import vdsh  # noqa: E402
f = vdsh.read(os.path.join(src, "tests", "corpus", "vdsh", "cube-s8-orders1235.vdsh"))
for bad in ([[0, 3, 0, 1]], [1, 2], [[[0, 1, 2]]]):
    try:
        vdsh.shadows(f, f.streams[0], bad)
        fail.append("shadows(lights=%r): accepted" % (bad,))
    except ValueError as e:
        if "lights: positions" not in str(e):
            fail.append("shadows(lights=%r): %s" % (bad, e))
if vdsh.shadows(f, f.streams[0], [0, 1, 2]).shape[1] != 1:
    fail.append("shadows(lights=[x, y, z]): not one light")

for m in fail:
    print("FAIL:", m)
print("python -m vdsh info: outputs and inputs %s" % ("as the C programs" if not fail else "WRONG"))
sys.exit(1 if fail else 0)
