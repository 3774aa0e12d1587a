"""scripts/cpca_study's cache (--work): each cached file is named by what
made it, so a rerun with other settings makes its own instead of reusing
stale results (it named the bakes and the truth by scene and fit only: a
rerun with another --rays, edge or mesh scored the first run's bakes).

cache_paths, the names scene() uses: the same settings give the same
names (a rerun reuses them); another --rays, edge, method, mesh file
content or built-in scene gives other bakes (and truth); another view
set's bytes another truth (the same bakes) and other score names for
the order-5 and compressed streams' frames; another --light-pool or
--light-seed or mesh another light pool (the same bakes); a rebuilt
vdsh-bake that writes other bytes other bakes (and truth), a rebuilt
vdsh-frames another truth, a rebuilt light_pool_tool another pool (the
key held none of the tools: a rebuilt baker's run scored the old one's
bakes); a tool rebuilt to the same bytes the same names. --views-dir
DIR: scene NAME's view set is DIR/NAME.views.json; --help names the
option, and a folder or view set that is not there is refused, named,
before anything is baked.

Usage: test_cpca_study_cache.py SCRIPTS_DIR WORK_DIR
"""
import argparse
import os
import subprocess
import sys

from testlib import load_script

scripts, work = sys.argv[1:3]
os.makedirs(work, exist_ok=True)
cs = load_script(os.path.join(scripts, "cpca_study"))
fail = 0


def check(ok, what):
    global fail
    if not ok:
        print("FAIL:", what, file=sys.stderr)
        fail = 1


mesh, views = os.path.join(work, "m.obj"), os.path.join(work, "v.views.json")
open(mesh, "w").write("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
open(views, "w").write('{"width": 64, "height": 48, "views": []}\n')
build = os.path.join(work, "build")
TOOLS = {"bake": os.path.join(build, "bake", "vdsh-bake"),
         "frames": os.path.join(build, "bake", "vdsh-frames"),
         "pool": os.path.join(build, "tests", "light_pool_tool")}


def tool(which, text):
    os.makedirs(os.path.dirname(TOOLS[which]), exist_ok=True)
    with open(TOOLS[which], "w") as f:
        f.write(text)


for which in TOOLS:
    tool(which, "#!/bin/sh\n# %s 1\n" % which)


def paths(rays=625, pool=2048, seed=1, m=mesh, edge="0.25", method="decision"):
    a = argparse.Namespace(work=work, build=build, rays=rays, light_pool=pool, light_seed=seed)
    p = cs.cache_paths(a, "s", m, edge, method, views)
    return dict(ref=p["ref"], o5=p["o5"], truth=p["truth"], pool=p["pool"](False),
                box=p["pool"](True), o5_frames=p["frames"](p["o5"]),
                cpca_frames=p["frames"](p["ref"] + ".cpca"))


base = paths()
check(paths() == base, "the same settings: the same names (a rerun reuses them)")
check(all(os.path.dirname(v) == work for v in base.values()), "all in --work")
check(len(set(base.values())) == len(base), "one name each")
for what, other in (("--rays 64", paths(rays=64)), ("edge 0.5", paths(edge="0.5")),
                    ("method shadow", paths(method="shadow"))):
    check(other["ref"] != base["ref"] and other["o5"] != base["o5"] and other["truth"] != base["truth"],
          "%s: other bakes and truth" % what)
    if what != "method shadow":  # a pool is the scene's and fit's (its name's), not the bake's
        check(other["pool"] == base["pool"], "%s: the same light pool" % what)
check(paths(m="builtin:room")["ref"] != paths(m="builtin:room:1")["ref"], "builtin scenes: their own bakes")
for what, other in (("--light-pool 512", paths(pool=512)), ("--light-seed 2", paths(seed=2))):
    check(other["pool"] != base["pool"] and other["box"] != base["box"], "%s: another pool" % what)
    check(other["ref"] == base["ref"] and other["truth"] == base["truth"], "%s: the same bakes" % what)

# The tools that made them: a rebuilt tool with other bytes (the same
# bytes again, e.g. a relink: the same names).
frames = ("o5_frames", "cpca_frames")  # the streams' scores: named by the bake and the truth
for which, changes in (("bake", ("ref", "o5", "truth") + frames), ("frames", ("truth",) + frames),
                       ("pool", ("pool", "box"))):
    tool(which, "#!/bin/sh\n# %s 2\n" % which)
    other = paths()
    for k in base:
        check((other[k] != base[k]) == (k in changes),
              "a rebuilt %s: %s %s" % (which, k, "kept" if k in changes else "changed"))
    tool(which, "#!/bin/sh\n# %s 1\n" % which)
    check(paths() == base, "%s rebuilt to the same bytes: the same names" % which)

# The files' bytes, not their names: an edited mesh or view set.
open(views, "w").write('{"width": 64, "height": 48, "views": [], "note": 1}\n')
v2 = paths()
check(v2["truth"] != base["truth"] and v2["ref"] == base["ref"], "another view set: another truth")
check(v2["o5_frames"] != base["o5_frames"] and v2["cpca_frames"] != base["cpca_frames"],
      "another view set: other frames and scores of the streams (not over the first set's)")
open(mesh, "w").write("v 0 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\n")
m2 = paths()
check(m2["ref"] != base["ref"] and m2["pool"] != base["pool"], "an edited mesh: other bakes and pool")

# --views-dir: DIR/NAME.views.json; refused when not there, before any bake.
check(cs.views_path("/some/dir", "val-x") == "/some/dir/val-x.views.json", "views_path: DIR/NAME.views.json")
script = os.path.join(scripts, "cpca_study")
r = subprocess.run([sys.executable, script, "--help"], capture_output=True, text=True)
check(r.returncode == 0 and "--views-dir" in r.stdout, "--help names --views-dir")
run_work = os.path.join(work, "run")
for vdir, want in ((os.path.join(work, "nowhere"), "--views-dir %s: no such folder" % os.path.join(work, "nowhere")),
                   (work, "no view set %s" % os.path.join(work, "s.views.json"))):
    r = subprocess.run([sys.executable, script, "--work", run_work, "--views-dir", vdir,
                        "--build", os.path.join(work, "nobuild"), "--scenes", "s=%s:0.25" % mesh,
                        "--methods", "decision", "--settings", "1.8.8"], capture_output=True, text=True)
    check(r.returncode != 0 and want in r.stderr,
          "--views-dir %s: refused naming %s (%s)" % (vdir, want, r.stderr.strip()[:200]))
    check(not os.path.isdir(run_work) or not os.listdir(run_work), "--views-dir %s: nothing baked" % vdir)
sys.exit(fail)
