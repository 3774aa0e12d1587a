"""scripts/sdf_frames' own steps, without GL: the volume's dimensions, bake
seconds and bytes come from vdsh-bake's --report ("sdf"), not a regex on
its log; a scoring step where no pixel counts is a clear message naming
the mode, not a ZeroDivisionError; small volumes print in kB (a 16^3
volume was "0.01 MB").

Usage: test_sdf_frames_script.py SCRIPTS_DIR VDSH_BAKE WORK_DIR
"""
import json
import os
import shutil
import sys

from testlib import load_script

scripts, bake, work = sys.argv[1:4]
sys.path.insert(0, scripts)
sf = load_script(os.path.join(scripts, "sdf_frames"))
fail = 0


def check(ok, what):
    global fail
    if not ok:
        print("FAIL:", what, file=sys.stderr)
        fail = 1


# No pixel counts: a message naming what was scored, exit (not a traceback).
sets = [dict(set=0, counted=0, shadowed=0, lit=0, rmse_ideal=0, rmse_hard=0, recall=0,
             false_area=0)]
for args in ((sets, 0), (sets, 0, "mode sdf of F")):
    try:
        sf.pool(*args)
        check(False, "no pixel counted: no error")
    except SystemExit as e:
        check("no pixel counts" in str(e.code) and (len(args) == 2 or "mode sdf of F" in
                                                    str(e.code)),
              "no pixel counted: message %r" % (e.code,))
    except Exception as e:  # it was a ZeroDivisionError
        check(False, "no pixel counted: %r" % e)
        break
# Sizes: kB below 1 MB.
label = getattr(sf, "size_label", lambda n: "%.2f MB" % (n / 1e6))  # the old script's
check(label(6562) == "6.6 kB", "6562 bytes shown as %r" % label(6562))
check(label(2500000) == "2.50 MB", "2.5e6 bytes shown as %r" % label(2500000))
# The bake's figures from its report: the volume file's own size.
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
vdsh = os.path.join(work, "room-16.vdsh")
try:
    dims, secs, nbytes = sf.bake_volume(bake, "builtin:room", "1.5", "16", "2", vdsh)
except Exception as e:  # the old script had no such step
    check(False, "bake_volume: %r" % e)
else:
    with open(vdsh[:-5] + ".report.json") as f:
        v = json.load(f)["sdf"]
    n = [int(x) for x in dims.split("x")]
    check(len(n) == 3 and max(n) >= 16 and n == v["dims"], "dims %s, report %s" % (dims, v))
    check(nbytes == os.path.getsize(vdsh[:-5] + ".sdf"), "bytes %d vs the .sdf file" % nbytes)
    check(secs >= 0 and v["path"] == vdsh[:-5] + ".sdf", "seconds %g, path %s" % (secs, v["path"]))
sys.exit(fail)
