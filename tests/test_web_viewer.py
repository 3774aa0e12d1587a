"""test_web_viewer.py BAKE EXPORT VIEW CHROMIUM WEBDIR WORKDIR - the web
viewer (runtime/web) in headless Chromium against vdsh-view.

builtin:room is baked (orders 2, 3, 5; the default method, shadow, stores
log distance), exported with vdsh-export, and drawn for one camera and
light (views.json) by vdsh-view --views (the shadow factor of the light as
a 16-bit grey PNG) and by the web page in Debian's chromium (headless,
WebGL2 on SwiftShader, output=shadow). The two shadow-only frames must
agree: mean absolute difference below 2/255 for every order (both draw
the per-vertex distance path: the same per-vertex sums, interpolated, and
the same ramp per pixel; what differs is rasterisation of edges and
float rounding, so the difference is far below one grey level on
average; it is also printed over the shadowed pixels alone). The frames
must hold shadows (so a blank page cannot pass).
Exit 77 when vdsh-view cannot make a GL context or chromium is missing.
"""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

bake, export, view, chromium, webdir, work = sys.argv[1:7]
os.makedirs(work, exist_ok=True)
if not shutil.which(chromium):
    print("no chromium: skipped")
    sys.exit(77)


def run(cmd, **kw):
    p = subprocess.run(cmd, capture_output=True, text=True, **kw)
    if p.returncode != 0:
        print("FAIL: %s: rc %d\n%s" % (" ".join(cmd), p.returncode, p.stderr))
        sys.exit(1)
    return p


vd, glb = os.path.join(work, "room.vdsh"), os.path.join(work, "room.glb")
run([bake, "builtin:room", "--max-edge", "0.5", "--rays", "256", "--orders", "2,3,5", "-o", vd, "-q"])
run([export, vd, "-o", glb])
W, H = 320, 240
eye, target, light = [7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]
json.dump({"width": W, "height": H, "views": [{"name": "v", "eye": eye, "target": target, "up": [0, 1, 0],
                                               "fov_y": 60, "light_sets": [[light]]}]},
          open(os.path.join(work, "views.json"), "w"))
frames = os.path.join(work, "c")
p = subprocess.run([view, "-q", "--views", os.path.join(work, "views.json"), "--frames", frames,
                    "--modes", "vdsh2,vdsh3,vdsh5", vd], capture_output=True, text=True)
if p.returncode != 0:
    if "EGL" in p.stderr or "context" in p.stderr or "display" in p.stderr:
        print("no GL context: skipped\n" + p.stderr)
        sys.exit(77)
    print("FAIL: vdsh-view: " + p.stderr)
    sys.exit(1)
for f in ("index.html", "vdsh_web.js"):
    shutil.copy(os.path.join(webdir, f), work)
fail = []
csv = lambda v: ",".join("%g" % x for x in v)
for order in (2, 3, 5):
    shot = os.path.join(work, "web-%d.png" % order)
    if os.path.exists(shot):
        os.remove(shot)
    url = "file://%s/index.html?glb=room.glb&order=%d&output=shadow&size=%dx%d&eye=%s&target=%s&up=0,1,0&fov=60&light=%s" % (
        os.path.abspath(work), order, W, H, csv(eye), csv(target), csv(light))
    subprocess.run([chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                    "--allow-file-access-from-files", "--hide-scrollbars", "--force-device-scale-factor=1",
                    "--window-size=800,600", "--virtual-time-budget=20000", "--screenshot=" + shot, url],
                   capture_output=True, text=True, timeout=300)
    if not os.path.exists(shot):
        fail.append("order %d: no screenshot" % order)
        continue
    a = np.asarray(Image.open(shot).convert("L"), float)[:H, :W] / 255
    b = np.asarray(Image.open(os.path.join(frames, "v-s0-l0-vdsh%d.png" % order))).astype(float) / 65535
    diff = np.abs(a - b).mean() * 255
    dark = (1 - b).mean()
    print("order %d: mean |web - C| = %.4f/255, mean shadow (C) %.2f%%, (web) %.2f%%" % (
        order, diff, 100 * dark, 100 * (1 - a).mean()))
    mask = (a < 0.99) | (b < 0.99)
    local = np.abs(a - b)[mask].mean() * 255 if mask.any() else 0.0
    print("order %d: mean |web - C| where either is shadowed (%d pixels): %.3f/255" % (order, mask.sum(), local))
    if dark < (0.005 if order == 5 else 0.0002):
        fail.append("order %d: the C frame has too little shadow to compare" % order)
    if not diff < 2.0:
        fail.append("order %d: mean abs difference %.3f/255 >= 2/255" % (order, diff))
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
