"""The test and validation scenes: one list that the scripts share.

Test scenes are the ones docs/ACCURACY.md reports (the built-in room,
Cornell-Original, Sponza); defaults are chosen on the validation scenes
only (never on a test scene): the seeded rooms builtin:room:N and meshes of
other kinds. Each scene is (name, mesh, max_edge): the name the tables
use, what vdsh-bake reads, and the receivers' refinement as vdsh-bake's
--max-edge text ("0": the mesh's own vertices). A script that needs a
subset or another edge derives it from these lists, so that a scene is
named and found in one place.

Third-party meshes live outside the repository (../shared/scenes, Debian's
assimp-testmodels); scripts skip or refuse those that are absent.
"""
import os
import signal
import sys


def pool_frames(sets, which):
    """A frames cell: vdsh-frames' per-(view, light set) scores of the sets
    with index `which`, pooled over the views (frames_gap, view_pools):
    image RMSE over the counted pixels, recall over the shadowed, false
    area over the lit; nan where there are none."""
    rows = [s for s in sets if s["set"] == which and s["counted"]]
    n = sum(s["counted"] for s in rows)
    sh = sum(s["shadowed"] for s in rows)
    lit = sum(s["lit"] for s in rows)
    nan = float("nan")
    return dict(rmse=(sum(s["rmse_ideal"] ** 2 * s["counted"] for s in rows) / n) ** 0.5
                if n else nan,
                recall=sum(s["recall"] * s["shadowed"] for s in rows if s["shadowed"]) / sh
                if sh else nan,
                false=sum(s["false_area"] * s["lit"] for s in rows if s["lit"]) / lit
                if lit else nan)


def clean_exit_on_signals():
    """SIGTERM and SIGHUP end a script as Ctrl-C does, through Python's
    exception handling: the program it is running is killed
    (subprocess.run does that on any exception) and its temporary folders
    removed (tempfile.TemporaryDirectory). By default they ended Python at
    once, leaving the child running and the folder, gigabytes of frames
    for Sponza, in /tmp. A signal ignored at start (nohup) stays ignored."""
    def leave(sig, _frame):
        sys.exit(128 + sig)
    for sig in (signal.SIGTERM, signal.SIGHUP):
        if signal.getsignal(sig) is not signal.SIG_IGN:
            signal.signal(sig, leave)


# Every script that imports this list is one of the measuring scripts.
clean_exit_on_signals()


def check_output_files(ap, *options):
    """(option, path) pairs of files a script writes at its end (--json,
    --plot): each path's folder must exist, checked before the run (a
    missing one was a FileNotFoundError after all the work). ap.error
    (exit 2) naming the option and the folder; None paths are skipped."""
    for opt, path in options:
        if path is None or path == "-":
            continue
        folder = os.path.dirname(os.path.abspath(path))
        if os.path.isdir(path):
            ap.error("%s %s: a folder, not a file" % (opt, path))
        if not os.path.isdir(folder):
            ap.error("%s %s: no folder %s (create it first)" % (opt, path, folder))

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(ROOT, "..", "shared", "scenes")
ASSIMP = "/usr/share/assimp/models"

CORNELL = os.path.join(SHARED, "cornell_box", "CornellBox-Original.obj")
SPONZA = os.path.join(SHARED, "sponza_dabrovic", "sponza.obj")
LOST_EMPIRE = os.path.join(SHARED, "lost_empire", "lost_empire.obj")
ENGINE = os.path.join(ASSIMP, "glTF2", "2CylinderEngine-glTF-Binary", "2CylinderEngine.glb")

# The reported scenes.
TEST = [("room", "builtin:room", "0.2"),
        ("cornell", CORNELL, "0.05"),
        ("sponza", SPONZA, "0.5")]

# Validation: the seeded rooms (furnished interiors of other sizes and
# layouts) ...
ROOMS = [("val-room-%d" % n, "builtin:room:%d" % n, "0.25") for n in range(1, 9)]
# ... and meshes unlike them.
MESHES = [
    ("teapot", os.path.join(SHARED, "teapot_newell", "teapot.obj"), "0.1"),
    ("rocker-arm", os.path.join(SHARED, "rocker_arm", "rocker-arm.obj"), "0.02"),
    ("fandisk", os.path.join(SHARED, "fandisk", "fandisk.obj"), "0.1"),
    ("lost-empire", LOST_EMPIRE, "0"),
    ("cornell-sphere", os.path.join(SHARED, "cornell_box", "CornellBox-Sphere.obj"), "0.1"),
    ("bunny", os.path.join(SHARED, "bunny_stanford", "bun_zipper_res2.ply"), "0"),
    ("spider", os.path.join(ASSIMP, "OBJ", "spider.obj"), "0"),
]
VALIDATION = ROOMS + MESHES


def by_name(scenes):
    """{name: (mesh, max_edge)} of a list above."""
    return {name: (mesh, edge) for name, mesh, edge in scenes}
