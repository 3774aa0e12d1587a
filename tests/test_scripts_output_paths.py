#!/usr/bin/python3
"""A measuring script's --json or --plot in a folder that does not exist
is a usage error (exit 2) naming the option, before anything runs
(scripts/frames and order_curve ran every bake and render, then died with
a FileNotFoundError traceback, the results lost). The programs are a
stand-in vdsh-bake that records being run.

Usage: test_scripts_output_paths.py SCRIPTS_DIR
"""
import os
import subprocess
import sys
import tempfile

import testlib

scripts = sys.argv[1]
fails = []
check = testlib.checker(fails)

CASES = [("frames", ["--scenes", "room", "--json", "nodir/x.json"], "--json"),
         ("order_curve", ["--scenes", "val-room-1", "--json", "nodir/x.json"], "--json"),
         ("order_curve", ["--scenes", "val-room-1", "--plot", "nodir/x.png"], "--plot")]

for name, args, opt in CASES:
    with tempfile.TemporaryDirectory() as work:
        build = os.path.join(work, "build")
        os.makedirs(os.path.join(build, "bake"))
        stub = os.path.join(build, "bake", "vdsh-bake")
        with open(stub, "w") as f:
            f.write("#!/bin/sh\ntouch '%s/ran'\nexit 1\n" % work)
        os.chmod(stub, 0o755)
        r = subprocess.run([os.path.join(scripts, name), "--build", build, *args], cwd=work,
                           capture_output=True, text=True, timeout=60)
        check(r.returncode == 2 and opt in r.stderr and "nodir" in r.stderr and
              "Traceback" not in r.stderr and not os.path.exists(os.path.join(work, "ran")),
              "%s %s: exit %d, ran: %s, %r" % (name, " ".join(args), r.returncode,
                                              os.path.exists(os.path.join(work, "ran")),
                                              r.stderr[-300:]))
sys.exit(1 if fails else 0)
