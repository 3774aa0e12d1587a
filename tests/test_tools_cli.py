#!/usr/bin/python3
"""What every vdsh program shares, end to end (tools/, formats/vdsh_output.h):

  json      vdsh-bake --report, vdsh-eval --json, vdsh-info --json (and
            --verify) parse as strict JSON (no NaN) when the paths hold
            quotes, backslashes, tabs, control characters, UTF-8 and bytes
            that are not UTF-8; vdsh-eval reads such a report back
  numbers   one option value means one number in every program (--seed 010
            is ten in the bake and in the evaluation); bad numbers are
            refused by every program with exit 2 and a message naming the
            option
  outputs   every output file is written atomically: a file planted under
            the old fixed temporary name (or a symbolic link there) is
            never touched; a write that fails (a file size limit, /dev/full)
            leaves the old content and no temporary file; concurrent
            bakes to one target all succeed with identical results

Usage: test_tools_cli.py VDSH_BAKE VDSH_EVAL VDSH_INFO VDSH_VIEW VDSH_RAYDUMP WORK_DIR
(vdsh-view is only asked to parse options here: no GL needed.)
"""
import json
import os
import resource
import shutil
import signal
import subprocess
import sys

bake, ev, info, view, work = sys.argv[1:6]
failures = []


def check(ok, what):
    if not ok:
        failures.append(what)
        print("FAIL: " + what, file=sys.stderr)


def run(*args, limit_kib=None):
    """Run a program (arguments may be bytes); (exit code, stdout, stderr)."""
    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        if limit_kib is not None:
            resource.setrlimit(resource.RLIMIT_FSIZE, (limit_kib * 1024, resource.RLIM_INFINITY))
    p = subprocess.run(list(args), capture_output=True, preexec_fn=limit)
    return p.returncode, p.stdout, p.stderr


def strict_json(data):
    """JSON as RFC 8259 has it: UTF-8, no NaN or Infinity."""
    def no_constant(name):
        raise ValueError("non-finite number " + name)
    return json.loads(data.decode("utf-8"), parse_constant=no_constant)


def temporaries(d):
    return [n for n in os.listdir(os.fsencode(d)) if b".tmp" in n]


shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
W = os.fsencode(work)
quick = ["builtin:room", "--max-edge", "2", "--rays", "64", "--method", "paper", "--orders", "2,5",
         "--cube-size", "8", "-q"]

# ---- json: odd paths in every document ----------------------------------
odd_dir = os.path.join(W, b'q"x')
os.makedirs(odd_dir)
odd = os.path.join(odd_dir, b'r\\oom \t\x01caf\xc3\xa9 \xff.vdsh')
odd_report = os.path.join(W, b'rep"ort\\\x02.json')
rc, out, err = run(bake, *quick, "-o", odd, "--report", odd_report)
check(rc == 0, "bake to an odd path: exit %d %s" % (rc, err))
shown = os.fsdecode(odd).encode("utf-8", "surrogateescape").decode("utf-8", "replace")
try:
    rep = strict_json(open(odd_report, "rb").read())
    check(rep["output"] == shown, "report: output %r, want %r" % (rep["output"], shown))
    check(rep["seed"] == 1 and rep["orders"] == [2, 5] and rep["seconds"]["total"] > 0,
          "report: values")
except (ValueError, KeyError, OSError) as e:
    check(False, "bake --report does not parse: %s" % e)

for args in (["--json", "-"], ["--json", "-", "--verify"]):
    rc, out, err = run(info, *args, odd)
    try:
        d = strict_json(out)
        check(rc == 0 and d["file"] == shown and d["valid"], "vdsh-info %s: %r" % (args, d))
    except (ValueError, KeyError) as e:
        check(False, "vdsh-info %s does not parse: %s" % (args, e))
# a file that does not read: the error document parses too
rc, out, err = run(info, "--json", "-", os.path.join(W, b'no"such\\\x03.vdsh'))
try:
    d = strict_json(out)
    check(rc == 1 and not d["valid"] and "no\"such\\" in d["error"], "vdsh-info error JSON")
except (ValueError, KeyError) as e:
    check(False, "vdsh-info error JSON does not parse: %s" % e)

odd_eval = os.path.join(W, b'ev"al\\ \x04.json')
rc, out, err = run(ev, odd, "-q", "--interior", "200", "--points", "300", "--bake-report",
                   odd_report, "--json", odd_eval)
check(rc == 0, "vdsh-eval on the odd path: exit %d %s" % (rc, err))
try:
    e = strict_json(open(odd_eval, "rb").read())
    check(e["file"] == shown, "eval: file %r" % e["file"])
    check(e["bake"]["seconds_from"] == "bake report", "eval read the odd report")
    check(e["scene"]["sources"][0]["name"] == "builtin:room", "eval: sources")
    # NaN became null: a rate with nothing to count exists in a tiny room
    check(all(isinstance(s["vertices"]["shadow_mae"], float) for s in e["streams"]), "numbers")
except (ValueError, KeyError, OSError) as ex:
    check(False, "vdsh-eval --json does not parse: %s" % ex)

# ---- numbers: the same text, the same number everywhere -----------------
seeded = os.path.join(W, b"seeded.vdsh")
rc, _, err = run(bake, *quick, "--seed", "010", "-o", seeded, "--report", seeded + b".json")
check(rc == 0, "bake --seed 010: %s" % err)
rc, out, _ = run(info, "--json", "-", seeded)
check(rc == 0 and strict_json(out)["bake"]["seed"] == 10, "bake --seed 010 stored as 10")
check(strict_json(open(seeded + b".json", "rb").read())["seed"] == 10, "bake report: seed 10")
rc, _, err = run(ev, seeded, "-q", "--seed", "010", "--interior", "0", "--points", "100",
                 "--json", seeded + b".eval.json")
check(rc == 0 and strict_json(open(seeded + b".eval.json", "rb").read())["eval"]["seed"] == 10,
      "vdsh-eval --seed 010 is 10 (was 8: octal): %s" % err)
rc, _, err = run(ev, seeded, "-q", "--threads", "02", "--interior", "0", "--points", "100",
                 "--orders", "05")
check(rc == 0, "vdsh-eval --threads 02 --orders 05: %s" % err)

BAD_INT = ["", "0x10", "1e3", "12abc", " 12", "-1", "+1", "99999999999999999999999", "1.5"]
BAD_REAL = ["", "1e99", "0x1p3", "inf", "nan", "1.5x", " 1", "1,2", "-"]
vd = os.path.join(W, b"x.vdsh")
cases = []
for opt in ("--rays", "--seed", "--threads", "--cube-size"):
    cases += [(bake, opt, v, ["builtin:room", "-o", vd]) for v in BAD_INT]
for opt in ("--max-distance", "--max-edge", "--lambda", "--log-floor"):
    cases += [(bake, opt, v, ["builtin:room", "-o", vd]) for v in BAD_REAL]
cases += [(bake, "--orders", v, ["builtin:room", "-o", vd]) for v in ["", "2,,3", "2,3,", "0x2", "2 ,3", "2,2", "17"]]
for opt in ("--points", "--interior", "--directions", "--seed", "--worst", "--threads"):
    cases += [(ev, opt, v, [seeded]) for v in BAD_INT]
cases += [(ev, "--orders", v, [seeded]) for v in ["", "2,,3", "0x2", "3,3", "17"]]
for opt in ("--frames", "--lights", "--shadow-size"):
    cases += [(view, opt, v, ["--render", os.path.join(W, b"x.png"), seeded]) for v in BAD_INT]
for opt in ("--fov", "--ambient"):
    cases += [(view, opt, v, ["--render", os.path.join(W, b"x.png"), seeded]) for v in BAD_REAL]
for opt, vals in (("--size", ["640", "640x", "0x480", "0x10x0x10", "640x480x1", " 64x48", "1e2x10"]),
                  ("--camera", ["1,2,3,4,5", "1,2,3,4,5,6,7", "1,2,3,4,5,nan", "1,2,3,4,5,0x1"]),
                  ("--light", ["1,2", "1,2,3,4", "1,2,inf", "1,,2"]),
                  ("--attenuation", ["1,0", "1,0,-1", "0,0,0", "1,0,1e99"])):
    cases += [(view, opt, v, ["--render", os.path.join(W, b"x.png"), seeded]) for v in vals]
for prog, opt, value, rest in cases:
    rc, out, err = run(prog, opt, value, *rest)
    name = os.path.basename(prog)
    check(rc == 2 and opt.encode() in err,
          "%s %s '%s': exit %d (want 2), message %r" % (name, opt, value, rc, err[:200]))
check(not os.path.exists(vd) and not os.path.exists(os.path.join(W, b"x.png")),
      "usage errors write nothing")

# ---- outputs: atomic, never following or truncating a planted name -----
out_dir = os.path.join(W, b"out")
os.makedirs(out_dir)
victim = os.path.join(out_dir, b"victim.txt")
open(victim, "w").write("victim")
reports = {
    "bake --report": ([bake, *quick, "-o", os.path.join(out_dir, b"a.vdsh"), "--report"], b"a.json"),
    "bake --export-obj": ([bake, "builtin:room", "-q", "--export-obj"], b"a.obj"),
    "eval --json": ([ev, seeded, "-q", "--interior", "0", "--points", "50", "--json"], b"e.json"),
    "eval --per-vertex": ([ev, seeded, "-q", "--interior", "0", "--points", "50", "--per-vertex"],
                          b"e.pv"),
}
def read_or(path, default):
    try:
        return open(path).read()
    except OSError:
        return default


for what, (cmd, name) in reports.items():
    target = os.path.join(out_dir, name)
    # The name the bake reports were once written through: a symbolic link
    # there must be neither followed nor moved.
    planted = target + b".tmp"
    os.symlink(victim, planted)
    rc, _, err = run(*cmd, target)
    check(rc == 0 and os.path.getsize(target) > 0, "%s: exit %d %s" % (what, rc, err))
    check(read_or(victim, None) == "victim", "%s: a link named NAME.tmp was followed" % what)
    check(os.path.islink(planted) and not os.path.islink(target),
          "%s: a link named NAME.tmp was moved" % what)
    if os.path.lexists(planted):
        os.remove(planted)
    open(victim, "w").write("victim")
    # A write that fails half way (1 KiB file size limit): old content kept.
    # (Not for the bake's report: its .vdsh, written first, fails first.)
    if what != "bake --report":
        open(target, "w").write("old")
        rc, _, err = run(*cmd, target, limit_kib=1)
        check(rc == 1 and target in err and b"File too large" in err,
              "%s: a failed write exits 1 naming the file and why: %d %r" % (what, rc, err[:300]))
        check(read_or(target, None) == "old", "%s: a failed write changed the old file" % what)
    check(temporaries(out_dir) == [], "%s: temporaries left: %s" % (what, temporaries(out_dir)))
    for n in temporaries(out_dir):
        os.remove(os.path.join(out_dir, n))
    if os.path.lexists(target):
        os.remove(target)
# A report to a device that fails every write (through a link in the work
# folder, so that a writer that replaces its target replaces only the
# link): exit 1 naming it, the device still a device, nothing beside it.
full = os.path.join(out_dir, b"full")
os.symlink("/dev/full", full)
rc, _, err = run(bake, *quick, "-o", os.path.join(out_dir, b"b.vdsh"), "--report", full)
check(rc == 1 and full in err and b"No space left" in err, "report to /dev/full: %r" % err)
check(os.path.islink(full), "the link to /dev/full was replaced")
check(temporaries(out_dir) == [], "report to /dev/full left %s" % temporaries(out_dir))
if os.path.lexists(full):
    os.remove(full)
# and to a stream that works: the document on stdout (through a link here
# too: a writer that replaced /dev/stdout itself would break the machine)
stdout_link = os.path.join(out_dir, b"stdout")
os.symlink("/dev/stdout", stdout_link)
rc, out, err = run(ev, seeded, "-q", "--interior", "0", "--points", "50", "--json", stdout_link)
check(os.path.islink(stdout_link), "the link to /dev/stdout was replaced")
os.remove(stdout_link)
try:
    check(rc == 0 and strict_json(out[out.index(b"{"):])["eval"]["seed"] > 0, "--json /dev/stdout")
except ValueError as e:
    check(False, "--json /dev/stdout does not parse: %s" % e)
# concurrent bakes to one target: all succeed, one complete result
target = os.path.join(out_dir, b"same.vdsh")
procs = [subprocess.Popen([bake, *quick, "-o", target, "--report", target + b".json"],
                          stderr=subprocess.PIPE) for _ in range(4)]
codes = [p.wait() for p in procs]
check(codes == [0, 0, 0, 0], "concurrent bakes: %s %s" % (codes, [p.stderr.read() for p in procs]))
ref = os.path.join(out_dir, b"ref.vdsh")
run(bake, *quick, "-o", ref)
check(open(target, "rb").read() == open(ref, "rb").read(), "concurrent bakes: a complete file")
check(strict_json(open(target + b".json", "rb").read())["receivers"] > 0, "concurrent reports")
check(temporaries(out_dir) == [], "concurrent bakes left temporaries: %s" % temporaries(out_dir))

if failures:
    print("%d check(s) failed" % len(failures), file=sys.stderr)
    sys.exit(1)
print("ok")
