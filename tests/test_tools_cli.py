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

  conventions  every program takes --help and --version (exit 0), starts
            its help with "usage: PROG", names itself bare (never argv[0]'s
            path) in every message, getopt's too; vdsh-bake's help names
            glTF input; every -q is "nothing on stderr but errors"
  same file an output that is an input (by device and inode: a hard link,
            a symbolic link) is refused by every program that writes, exit 1,
            the input untouched
  early     a bad output folder (of the .vdsh or of the cubemaps) is found
            before the meshes load, and the message names that path
  together  a bake that fails while writing leaves the old basis cubemaps
  twice     -o given twice is a usage error (vdsh-bake, -merge, -export,
            -frames), and so is every other option naming one file or folder
            (--plan, --report, --json, --views, --render, ...) in every
            program
  orders    vdsh-export takes orders 1..16
  strict    every JSON document any program writes parses with a strict
            parser that also refuses duplicate keys (vdsh-frames views and
            score too)
  progress  without a terminal vdsh-bake prints progress as lines of their
            own (no \\r), ending at 100%, the ETA not far off; -q: nothing

Usage: test_tools_cli.py VDSH_BAKE VDSH_EVAL VDSH_INFO VDSH_VIEW VDSH_MERGE VDSH_EXPORT
                         VDSH_FRAMES WORK_DIR
(vdsh-view is only asked to parse options here: no GL needed.)
"""
import json
import os
import resource
import shutil
import signal
import subprocess
import sys

bake, ev, info, view, merge, export, frames, work = sys.argv[1:9]
PROGRAMS = {"vdsh-bake": bake, "vdsh-eval": ev, "vdsh-info": info, "vdsh-view": view,
            "vdsh-merge": merge, "vdsh-export": export, "vdsh-frames": frames}
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
    """JSON as RFC 8259 has it: UTF-8, no NaN or Infinity, and no key twice
    in one object (parsers keep one of the two: the other is lost)."""
    def no_constant(name):
        raise ValueError("non-finite number " + name)

    def no_duplicates(pairs):
        keys = [k for k, _ in pairs]
        dup = sorted({k for k in keys if keys.count(k) > 1})
        if dup:
            raise ValueError("duplicate key(s) %s" % dup)
        return dict(pairs)
    return json.loads(data.decode("utf-8"), parse_constant=no_constant,
                      object_pairs_hook=no_duplicates)


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
# The light pool's placement (method decision: between the BVH build and
# the trace) has its own seconds, within the total; none for paper.
pool_report = os.path.join(W, b"pool.json")
rc, out, err = run(bake, *[a if a != "paper" else "decision" for a in quick], "-o",
                   os.path.join(W, b"pool.vdsh"), "--report", pool_report)
check(rc == 0, "bake, method decision: exit %d %s" % (rc, err))
try:
    sec = strict_json(open(pool_report, "rb").read())["seconds"]
    parts = sum(sec[k] for k in ("load", "refine", "build", "pool", "trace"))
    check(sec["pool"] > 0 and parts <= sec["total"],
          "report, method decision: seconds %r (pool > 0, the parts within total)" % sec)
    check(rep["seconds"]["pool"] == 0, "report, method paper: pool seconds %r" % rep["seconds"])
    # The streams' encoding (cpca's fit among it) has its own seconds, within write.
    check(0 <= sec["encode"] <= sec["write"],
          "report: encode seconds %r (within write)" % sec)
except (ValueError, KeyError, OSError) as e:
    check(False, "bake --report (decision): %s" % e)

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
                  ("--camera", ["1,2,3,4,5", "1,2,3,4,5,6,7", "1,2,3,4,5,nan", "1,2,3,4,5,0x1",
                               # no image plane: eye at the target, or straight above it
                               "1,2,3,1,2,3", "0,5,0,0,0,0", "2,-4,1,2,3,1"]),
                  ("--light", ["1,2", "1,2,3,4", "1,2,inf", "1,,2", "1,2,3,-1,0,0"]),
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

# ---- conventions: --help, --version, the bare name in every message -----
for name, prog in PROGRAMS.items():
    rc, out, err = run(prog, "--help")
    check(rc == 0 and out.startswith(("usage: %s " % name).encode()),
          "%s --help: exit %d, first line %r (want 'usage: %s ...')"
          % (name, rc, out[:60], name))
    rc, out, err = run(prog, "--version")
    check(rc == 0 and out.startswith(("%s " % name).encode()) and b"." in out,
          "%s --version: exit %d, %r" % (name, rc, out[:80]))
    # getopt's message and ours: the bare name, never the path it ran as
    args = ["views", "--no-such-option"] if name == "vdsh-frames" else ["--no-such-option"]
    rc, out, err = run(prog, *args)
    lines = err.decode("utf-8", "replace").splitlines()
    check(rc == 2 and lines and all(l.startswith(name + ":") or l.startswith(name + " ")
                                    or l == "Try '%s --help'." % name for l in lines)
          and ("Try '%s --help'." % name) in lines and os.path.dirname(prog) not in err.decode(),
          "%s --no-such-option: exit %d, stderr %r" % (name, rc, err[:300]))
    rc, out, err = run(prog)  # nothing given: a usage error in the same words
    check(rc == 2 and err.startswith((name + ": ").encode()) and
          ("Try '%s --help'." % name).encode() in err,
          "%s without arguments: exit %d, stderr %r" % (name, rc, err[:200]))
rc, out, _ = run(bake, "--help")
check(b"glTF" in out and b".glb" in out, "vdsh-bake --help names glTF input")
# -q means one thing in every program that takes it: nothing on stderr
# but errors (vdsh-export kept its notes and warnings under -q while
# vdsh-bake silenced its own); each help says so (the behaviour:
# test_gltf_source_match.py, vdsh-export's notes and warnings, and the
# bake's "progress" above)
for name, prog in PROGRAMS.items():
    rc, out, _ = run(prog, "--help")
    if b"--quiet" not in out:
        continue
    said = b" ".join(out.split(b"--quiet", 1)[1].split(b"\n  -")[0].split())
    check(rc == 0 and said.startswith(b"nothing on stderr but errors"),
          "%s --help: -q is %r, not 'nothing on stderr but errors'" % (name, said[:80]))

# ---- same file: an output that is an input is refused --------------------
sf = os.path.join(W, b"same")
os.makedirs(sf)
mesh = os.path.join(sf, b"m.obj")
open(mesh, "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n")
os.link(mesh, os.path.join(sf, b"hard.obj"))
os.symlink(b"m.obj", os.path.join(sf, b"soft.obj"))
sv = os.path.join(sf, b"s.vdsh")
rc, _, err = run(bake, *quick, "-o", sv)
check(rc == 0, "bake s.vdsh: %s" % err)
os.link(sv, os.path.join(sf, b"s-hard.vdsh"))
part = os.path.join(sf, b"p.vdsh")
run(bake, *quick, "--shard", "0/1", "-o", part)
def same_file_case(what, cmd, inp):
    before = open(inp, "rb").read()
    rc, _, err = run(*cmd)
    after = open(inp, "rb").read()
    check(rc == 1 and b"same file" in err and after == before,
          "%s: exit %d (want 1), %r; the input %s" % (
              what, rc, err[:200], "kept" if after == before else "CHANGED"))
    if after != before:  # the next case starts from the same input
        open(inp, "wb").write(before)
same_file_case("bake m.obj -o m.obj", [bake, mesh, "-q", "-o", mesh], mesh)
same_file_case("bake m.obj -o hard link", [bake, mesh, "-q", "-o", os.path.join(sf, b"hard.obj")], mesh)
same_file_case("bake m.obj -o symbolic link", [bake, os.path.join(sf, b"soft.obj"), "-q", "-o", mesh], mesh)
same_file_case("bake --report m.obj", [bake, mesh, "-q", "-o", os.path.join(sf, b"o.vdsh"),
                                       "--report", mesh], mesh)
same_file_case("bake --export-obj m.obj", [bake, mesh, "-q", "--export-obj", mesh], mesh)
same_file_case("bake --plan over the mesh", [bake, mesh, "-q", "--plan",
                                             os.path.join(sf, b"hard.obj")], mesh)
same_file_case("export a.vdsh -o a.vdsh", [export, sv, "-o", sv], sv)
same_file_case("export a.vdsh -o its hard link", [export, sv, "-o", os.path.join(sf, b"s-hard.vdsh")], sv)
same_file_case("merge p.vdsh -o p.vdsh", [merge, part, "-q", "-o", part], part)
same_file_case("eval --json a.vdsh", [ev, sv, "-q", "--json", sv], sv)
same_file_case("eval --per-vertex a.vdsh", [ev, sv, "-q", "--per-vertex", sv], sv)
same_file_case("info --json a.vdsh", [info, "--json", sv, sv], sv)
same_file_case("frames views -o a.vdsh", [frames, "views", sv, "-q", "-o", sv], sv)
same_file_case("view --render a.vdsh", [view, "--render", sv, sv], sv)
# the sources a .vdsh records are inputs of the programs that read them
# (vdsh-eval, vdsh-frames views), found as recorded without being named
mv = os.path.join(sf, b"m.vdsh")
rc, _, err = run(bake, mesh, "--rays", "16", "--cube-size", "0", "-q", "-o", mv)
check(rc == 0, "bake m.vdsh: %s" % err)
same_file_case("eval --per-vertex over the recorded source", [ev, mv, "-q", "--points", "16",
               "--interior", "16", "--per-vertex", mesh], mesh)
same_file_case("eval --json over the recorded source", [ev, mv, "-q", "--points", "16",
               "--interior", "16", "--json", os.path.join(sf, b"hard.obj")], mesh)
same_file_case("frames views -o the recorded source", [frames, "views", mv, "-q", "-o", mesh],
               mesh)
check(not [n for n in os.listdir(sf) if b".tmp" in n], "same-file refusals left temporaries")

# ---- stdout: '-' is stdout for JSON only; a file output refuses it --------
# (each wrote a file named '-' in the working folder, exit 0)
dd = os.path.join(W, b"dash")
os.makedirs(dd)
for prog, args, opt in (
        (bake, [mesh, "--rays", "16", "-q", "-o", "-"], "-o"),
        (bake, [mesh, "-q", "--export-obj", "-"], "--export-obj"),
        (bake, [mesh, "--max-edge", "1", "-q", "--plan", "-"], "--plan"),
        (merge, [part, "-q", "-o", "-"], "-o"),
        (ev, [sv, "-q", "--points", "16", "--per-vertex", "-"], "--per-vertex"),
        (export, [sv, "-q", "-o", "-"], "-o"),
        (view, [sv, "-q", "--render", "-"], "--render"),
        (view, [sv, "-q", "--grid", "-"], "--grid"),
        (frames, ["truth", sv, "-q", "--views", os.path.join(W, b"none.json"), "-o", "-"], "-o")):
    p = subprocess.run([prog, *args], capture_output=True, cwd=dd)
    name = os.path.basename(prog)
    check(p.returncode == 2 and (opt + " -").encode() in p.stderr and not os.listdir(dd),
          "%s %s -: exit %d (want 2), %r, left %s" % (name, opt, p.returncode, p.stderr[:200],
                                                     os.listdir(dd)))
    for n in os.listdir(dd):
        os.remove(os.path.join(dd, n))
# ---- -o given twice: a usage error in every program that takes it ---------
# (the last one silently won: a typo in a script wrote somewhere unexpected)
for prog, args in ((bake, [mesh, "--rays", "16", "-q"]), (merge, [part, "-q"]),
                   (export, [sv, "-q"]), (frames, ["views", sv, "-q"])):
    p = subprocess.run([prog, *args, "-o", "a.out", "--output=b.out"], capture_output=True, cwd=dd)
    name = os.path.basename(prog)
    check(p.returncode == 2 and b"-o given twice ('a.out', then 'b.out')" in p.stderr and
          not os.listdir(dd),
          "%s -o a.out -o b.out: exit %d (want 2), %r, left %s" % (name, p.returncode,
                                                                   p.stderr[:200], os.listdir(dd)))
    for n in os.listdir(dd):
        os.remove(os.path.join(dd, n))
# ... and so is every other option that names one file or folder, in every
# program (--plan, --report, --json, ...: the last one silently won)
twice = [(bake, [mesh, "--rays", "16", "-q", "-o", "x.vdsh"], o)
         for o in ("--report", "--export-obj", "--plan", "--receivers", "--cubemap-dir")]
twice += [(ev, [sv, "-q"], o) for o in ("--json", "--per-vertex", "--bake-report")]
twice += [(frames, ["truth", sv, "-q", "-o", "t"], o) for o in ("--views", "--sdf")]
twice += [(frames, ["score", sv, "-q"], o) for o in ("--views", "--truth", "--frames", "--json")]
twice += [(export, [sv, "-q"], "--source"), (info, [sv], "--json")]
twice += [(view, [sv, "-q"], o)
          for o in ("--render", "--grid", "--sdf", "--screenshot", "--views", "--frames")]
for prog, args, opt in twice:
    p = subprocess.run([prog, *args, opt, "a.out", opt + "=b.out"], capture_output=True, cwd=dd)
    name = os.path.basename(prog)
    check(p.returncode == 2 and
          ("%s given twice ('a.out', then 'b.out')" % opt).encode() in p.stderr and
          not os.listdir(dd),
          "%s %s a.out %s b.out: exit %d (want 2), %r, left %s" % (
              name, opt, opt, p.returncode, p.stderr[:200], os.listdir(dd)))
    for n in os.listdir(dd):
        os.remove(os.path.join(dd, n))
# vdsh-export writes binary glTF: an output named .gltf (JSON text) is refused
p = subprocess.run([export, sv, "-q", "-o", "x.gltf"], capture_output=True, cwd=dd)
check(p.returncode == 2 and b"x.gltf" in p.stderr and b".glb" in p.stderr and not os.listdir(dd),
      "export -o x.gltf: exit %d (want 2), %r" % (p.returncode, p.stderr[:200]))
p = subprocess.run([bake, mesh, "--rays", "16", "--cube-size", "0", "-q", "-o",
                    os.path.join(dd, b"r.vdsh"), "--report", "-"], capture_output=True, cwd=dd)
check(p.returncode == 0 and strict_json(p.stdout) and sorted(os.listdir(dd)) == [b"r.vdsh"],
      "bake --report - (stdout): exit %d, left %s" % (p.returncode, os.listdir(dd)))

# ---- early: a bad output folder, found before the meshes load ------------
ed = os.path.join(W, b"early")
os.makedirs(ed)
loud = [a for a in quick if a != "-q"]
for what, extra, named in (
        (".vdsh in a missing folder", ["-o", os.path.join(ed, b"nodir", b"r.vdsh")],
         os.path.join(ed, b"nodir", b"r.vdsh")),
        ("cubemaps in a missing folder", ["-o", os.path.join(ed, b"r.vdsh"), "--cubemap-dir",
                                          os.path.join(ed, b"nocube")],
         os.path.join(ed, b"nocube", b"r.sh09-12.exr")),
        ("report in a missing folder", ["-o", os.path.join(ed, b"r.vdsh"), "--report",
                                        os.path.join(ed, b"nodir", b"r.json")],
         os.path.join(ed, b"nodir", b"r.json")),
        (".vdsh is a folder", ["-o", ed], ed)):
    rc, _, err = run(bake, *loud, *extra)
    check(rc == 1 and named in err and b"builtin:room:" not in err and b"tracing" not in err,
          "bake, %s: exit %d, want 1 before loading, naming %r: %r" % (what, rc, named, err[:300]))
# the case: --cubemap-dir . -o nodir/r.vdsh left the old cubemaps rewritten
cube_names = [b"r.sh09-12.exr", b"r.sh13-16.exr", b"r.sh17-20.exr", b"r.sh21-24.exr"]
for n in cube_names:
    open(os.path.join(ed, n), "w").write("old")
rc, _, err = run(bake, *quick, "--cubemap-dir", ed, "-o", os.path.join(ed, b"nodir", b"r.vdsh"))
check(rc == 1 and all(open(os.path.join(ed, n), "rb").read() == b"old" for n in cube_names),
      "a bake to a missing folder rewrote the cubemaps: %r" % err[:200])
# merge: a missing folder, before any part is read
rc, _, err = run(merge, part, "-o", os.path.join(ed, b"nodir", b"m.vdsh"))
check(rc == 1 and os.path.join(ed, b"nodir", b"m.vdsh") in err, "merge to a missing folder: %r" % err)

# ---- together: a bake that fails while writing keeps the old cubemaps ----
# A 16 KiB file size limit: the 8x8 cubemaps (~1.4 KB) fit, the .vdsh does
# not; the cubemaps were once renamed before the .vdsh failed.
td = os.path.join(W, b"together")
os.makedirs(td)
for n in cube_names:
    open(os.path.join(td, n), "w").write("old")
rc, _, err = run(bake, *quick, "--cubemap-dir", td, "-o", os.path.join(td, b"r.vdsh"),
                 limit_kib=16)
check(rc == 1 and b"File too large" in err, "bake under a 16 KiB limit: exit %d %r" % (rc, err[:300]))
check(all(open(os.path.join(td, n), "rb").read() == b"old" for n in cube_names),
      "a failed bake replaced the basis cubemaps")
check(not os.path.exists(os.path.join(td, b"r.vdsh")) and temporaries(td) == [],
      "a failed bake left %s" % os.listdir(td))
rc, _, err = run(bake, *quick, "--cubemap-dir", td, "-o", os.path.join(td, b"r.vdsh"))
check(rc == 0 and all(open(os.path.join(td, n), "rb").read() != b"old" for n in cube_names),
      "the bake without a limit writes them: %r" % err[:200])
# vdsh-eval's --json and --per-vertex change together, whichever fails:
# the room (--points 50: JSON ~15 KB, per-vertex ~95 KB) under a 24 KiB
# limit, where the JSON was once renamed before the per-vertex file
# failed; a 4-vertex mesh (per-vertex ~0.2 KB) under 4 KiB, the JSON failing.
for vd, npts, kib, fails in ((sv, "50", 24, b"e.pv"), (mv, "4", 4, b"e.json")):
    pj, pp = os.path.join(td, b"e.json"), os.path.join(td, b"e.pv")
    open(pj, "w").write("old")
    open(pp, "w").write("old")
    eargs = [ev, vd, "-q", "--points", npts, "--interior", "0", "--json", pj, "--per-vertex", pp]
    rc, _, err = run(*eargs, limit_kib=kib)
    check(rc == 1 and b"File too large" in err and os.path.join(td, fails) in err,
          "eval under a %d KiB limit: exit %d %r" % (kib, rc, err[:300]))
    check(open(pp, "rb").read() == b"old" and open(pj, "rb").read() == b"old" and
          temporaries(td) == [], "a failed eval (%s) replaced an output or left %s" % (
              fails, os.listdir(td)))
    rc, _, err = run(*eargs)
    check(rc == 0 and os.path.getsize(pp) > 3 and strict_json(open(pj, "rb").read()),
          "eval without a limit writes both: %r" % err[:200])

# ---- orders: vdsh-export takes 1..16 -------------------------------------
o16 = os.path.join(W, b"o16.vdsh")
rc, _, err = run(bake, "builtin:room", "--max-edge", "4", "--rays", "64", "--orders", "2,16",
                 "-q", "-o", o16)
check(rc == 0, "bake --orders 2,16: %s" % err)
rc, _, err = run(export, o16, "--orders", "16", "-q", "-o", os.path.join(W, b"o16.glb"))
check(rc == 0 and os.path.getsize(os.path.join(W, b"o16.glb")) > 0,
      "vdsh-export --orders 16: exit %d %r" % (rc, err))
rc, _, err = run(export, o16, "--orders", "17", "-o", os.path.join(W, b"o17.glb"))
check(rc == 2 and b"1..16" in err, "vdsh-export --orders 17: exit %d %r" % (rc, err))
# An order the file does not have: exit 1, naming the orders it has, and
# no output.
rc, _, err = run(export, o16, "--orders", "5", "-o", os.path.join(W, b"o5.glb"))
check(rc == 1 and b"the file has orders 2, 16" in err and not os.path.exists(os.path.join(W, b"o5.glb")),
      "vdsh-export --orders 5 of orders 2, 16: exit %d %r" % (rc, err))

# ---- strict: every JSON document the programs write ----------------------
jd = os.path.join(W, b"json")
os.makedirs(jd)
def strict_file(what, path):
    try:
        return strict_json(open(path, "rb").read())
    except (ValueError, OSError) as e:
        check(False, "%s: not strict JSON: %s" % (what, e))
        return None
rc, _, err = run(bake, *quick, "--trace-only", "--report", os.path.join(jd, b"bare.json"))
check(rc == 0, "bake --trace-only --report: %s" % err)
strict_file("bake --trace-only --report", os.path.join(jd, b"bare.json"))
rc, _, err = run(bake, *quick, "--adaptive", "0.02", "--max-edge", "2", "--rays", "64",
                 "-o", os.path.join(jd, b"ad.vdsh"), "--report", os.path.join(jd, b"ad.json"))
strict_file("bake --adaptive --report", os.path.join(jd, b"ad.json"))
rc, out, err = run(info, "--json", "-", sv, seeded)
try:
    docs = strict_json(out)
    check(rc == 0 and isinstance(docs, list) and len(docs) == 2, "vdsh-info --json - A B: an array")
except ValueError as e:
    check(False, "vdsh-info --json - of two files: %s" % e)
rc, _, err = run(info, "--json", os.path.join(jd, b"info.json"), sv)
d = strict_file("vdsh-info --json FILE", os.path.join(jd, b"info.json"))
check(rc == 0 and d is not None and d.get("valid"), "vdsh-info --json FILE: %s" % err)
rc, out, err = run(ev, sv, "-q", "--interior", "0", "--points", "50", "--json", "-")
try:
    check(rc == 0 and strict_json(out)["file"], "vdsh-eval --json -")
except (ValueError, KeyError) as e:
    check(False, "vdsh-eval --json -: %s" % e)
views = os.path.join(jd, b"v.json")
rc, _, err = run(frames, "views", sv, "-q", "--cameras", "1", "--size", "64x48", "-o", views)
check(rc == 0, "vdsh-frames views: %s" % err)
strict_file("vdsh-frames views", views)
truth = os.path.join(jd, b"truth")
rc, _, err = run(frames, "truth", sv, "-q", "--views", views, "-o", truth)
check(rc == 0, "vdsh-frames truth: %s" % err)
# a view straight down (along its up vector) has no image plane: refused
down = os.path.join(jd, b"down.json")
vs = json.loads(open(views, "rb").read())
vs["views"] = vs["views"][:1]
vs["views"][0]["target"] = [vs["views"][0]["eye"][0], 0.0, vs["views"][0]["eye"][2]]
vs["views"][0]["eye"][1] += 1.0
open(down, "w").write(json.dumps(vs))
for args in (["truth", sv, "-q", "--views", down, "-o", os.path.join(jd, b"down")],
             ["score", sv, "-q", "--views", down, "--truth", truth, "--frames", truth,
              "--modes", "ideal"]):
    rc, _, err = run(frames, *args)
    check(rc == 1 and b"down.json" in err and b"along 'up'" in err,
          "vdsh-frames %s, a view straight down: exit %d (want 1), %r" % (args[0], rc, err[:200]))
score = os.path.join(jd, b"score.json")
rc, _, err = run(frames, "score", sv, "-q", "--views", views, "--truth", truth, "--frames", truth,
                 "--modes", "ideal,hard", "--json", score)
check(rc == 0, "vdsh-frames score: %s" % err)
d = strict_file("vdsh-frames score --json", score)
if d:
    s0 = d["modes"][0]["sets"][0]
    check(isinstance(s0["frames"], int) and len(s0["per_frame"]) == s0["frames"],
          "score: a set's frames (count) and per_frame (scores): %r" % list(s0))

# ---- progress: lines in a log, nothing with -q ---------------------------
import time
pd = os.path.join(W, b"progress")
os.makedirs(pd)
slow = ["builtin:room", "--max-edge", "0.5", "--rays", "256", "--cube-size", "0"]
t0 = time.monotonic()
rc, _, err = run(bake, *slow, "-o", os.path.join(pd, b"p.vdsh"))
took = time.monotonic() - t0
import re
prog = [l for l in err.decode().splitlines() if re.match(r"vdsh-bake: +[0-9.]+%  ", l)]
check(rc == 0 and prog and prog[-1].startswith("vdsh-bake: 100.0%") and b"\r" not in err,
      "progress without a terminal: lines of their own ending at 100%%: %r" % err[:600])
for l in prog[:-1]:
    eta = l.rsplit("ETA ", 1)[-1].split()[0] if "ETA " in l else "-"
    check(eta == "-" or float(eta) < 10 * took + 1,
          "an ETA far off: %r (the whole bake took %.1f s)" % (l, took))
rc, _, err = run(bake, *slow, "-q", "-o", os.path.join(pd, b"q.vdsh"))
check(rc == 0 and err == b"", "-q: nothing on stderr: %r" % err[:200])

if failures:
    print("%d check(s) failed" % len(failures), file=sys.stderr)
    sys.exit(1)
print("ok")
