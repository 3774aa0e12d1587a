#!/usr/bin/python3
"""SIGTERM to a measuring script (scripts/frames, order_curve, sdf_frames,
bench_bake) while it runs a program: the program is killed and the
script's temporary folder removed (by default Python died at once, leaving
the child running and the folder, gigabytes of frames, in /tmp). The
programs are a stand-in vdsh-bake that says it started and sleeps, so the
signal lands while the script waits on it; TMPDIR is a folder of the test's.

Usage: test_scripts_sigterm.py SCRIPTS_DIR
"""
import os
import signal
import subprocess
import sys
import tempfile
import time

import testlib

scripts = sys.argv[1]
fails = []
check = testlib.checker(fails)

STUB = """#!/bin/sh
[ "$1" = --version ] && { echo stand-in; exit 0; }
echo $$ > "%s/started"
exec sleep 60
"""

CASES = [("frames", ["--scenes", "room"]),
         ("order_curve", ["--scenes", "val-room-1"]),
         ("sdf_frames", ["--scenes", "room"]),
         ("bench_bake", ["--quick", "--repeat", "1", "--out", "bench.md"])]

for name, args in CASES:
    with tempfile.TemporaryDirectory() as work:
        build = os.path.join(work, "build")
        os.makedirs(os.path.join(build, "bake"))
        stub = os.path.join(build, "bake", "vdsh-bake")
        with open(stub, "w") as f:
            f.write(STUB % work)
        os.chmod(stub, 0o755)
        tmpdir = os.path.join(work, "tmp")
        os.makedirs(tmpdir)
        env = dict(os.environ, TMPDIR=tmpdir)
        p = subprocess.Popen([os.path.join(scripts, name), "--build", build, *args], cwd=work,
                             env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        started = os.path.join(work, "started")
        for _ in range(300):
            if os.path.exists(started) or p.poll() is not None:
                break
            time.sleep(0.05)
        if not os.path.exists(started):
            p.kill()
            check(False, "%s: the stand-in vdsh-bake never started: %s" % (name, p.communicate()[1]))
            continue
        time.sleep(0.2)
        child = int(open(started).read())
        p.send_signal(signal.SIGTERM)
        try:
            _, err = p.communicate(timeout=20)
        except subprocess.TimeoutExpired:
            p.kill()
            err = ""
        check(p.returncode not in (0, None), "%s: exit %s after SIGTERM" % (name, p.returncode))
        left = os.listdir(tmpdir)
        check(not left, "%s: left in TMPDIR after SIGTERM: %s" % (name, left))
        try:
            os.kill(child, 0)
            alive = open("/proc/%d/stat" % child).read().split()[2] != "Z"
        except OSError:
            alive = False
        check(not alive, "%s: its vdsh-bake (pid %d) still runs after SIGTERM" % (name, child))
        if alive:
            os.kill(child, signal.SIGKILL)
sys.exit(1 if fails else 0)
