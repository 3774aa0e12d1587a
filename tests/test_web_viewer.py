"""test_web_viewer.py BAKE EXPORT VIEW CHROMIUM WEBDIR WORKDIR ASSIMP_MODELS - the web
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
The same for order 5 of Debian assimp-testmodels' 2CylinderEngine.glb
(read by the glTF reader), seen and lit from outside.
Exit 77 when vdsh-view cannot make a GL context or chromium is missing.
"""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

bake, export, view, chromium, webdir, work, models = sys.argv[1:8]
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


fail = []
csv = lambda v: ",".join("%g" % x for x in v)
W, H = 320, 240
for f in ("index.html", "vdsh_web.js"):
    shutil.copy(os.path.join(webdir, f), work)


def bounds(glb):
    import struct
    d = open(glb, "rb").read()
    jl = struct.unpack_from("<I", d, 12)[0]
    g = json.loads(d[20:20 + jl])
    a = g["accessors"][g["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    return np.array(a["min"]), np.array(a["max"])


def scene(name, source, opts, orders, place):
    vd, glb = os.path.join(work, name + ".vdsh"), os.path.join(work, name + ".glb")
    run([bake, source, "-o", vd, "-q", "--orders", ",".join(map(str, orders))] + opts)
    run([export, vd, "-o", glb])
    eye, target, light = place(*bounds(glb))
    views = os.path.join(work, name + "-views.json")
    json.dump({"width": W, "height": H, "views": [{"name": name, "eye": eye, "target": target, "up": [0, 1, 0],
                                                   "fov_y": 60, "light_sets": [[light]]}]}, open(views, "w"))
    frames = os.path.join(work, "c")
    p = subprocess.run([view, "-q", "--views", views, "--frames", frames,
                        "--modes", ",".join("vdsh%d" % o for o in orders), vd], capture_output=True, text=True)
    if p.returncode != 0:
        if "EGL" in p.stderr or "context" in p.stderr or "display" in p.stderr:
            print("no GL context: skipped\n" + p.stderr)
            sys.exit(77)
        print("FAIL: vdsh-view: " + p.stderr)
        sys.exit(1)
    for order in orders:
        shot = os.path.join(work, "web-%s-%d.png" % (name, order))
        if os.path.exists(shot):
            os.remove(shot)
        url = ("file://%s/index.html?glb=%s.glb&order=%d&output=shadow&size=%dx%d&eye=%s&target=%s&up=0,1,0"
               "&fov=60&light=%s" % (os.path.abspath(work), name, order, W, H, csv(eye), csv(target), csv(light)))
        subprocess.run([chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader",
                        "--enable-unsafe-swiftshader", "--allow-file-access-from-files", "--hide-scrollbars",
                        "--force-device-scale-factor=1", "--window-size=800,600", "--virtual-time-budget=20000",
                        "--screenshot=" + shot, url], capture_output=True, text=True, timeout=300)
        if not os.path.exists(shot):
            fail.append("%s order %d: no screenshot" % (name, order))
            continue
        a = np.asarray(Image.open(shot).convert("L"), float)[:H, :W] / 255
        b = np.asarray(Image.open(os.path.join(frames, "%s-s0-l0-vdsh%d.png" % (name, order)))).astype(float) / 65535
        diff = np.abs(a - b).mean() * 255
        dark = (1 - b).mean()
        mask = (a < 0.99) | (b < 0.99)
        local = np.abs(a - b)[mask].mean() * 255 if mask.any() else 0.0
        print("%s order %d: mean |web - C| = %.4f/255 (%.3f/255 over the %d pixels shadowed in either); "
              "mean shadow C %.2f%%, web %.2f%%" % (name, order, diff, local, mask.sum(), 100 * dark,
                                                   100 * (1 - a).mean()))
        if dark < (0.005 if order == 5 else 0.0002):
            fail.append("%s order %d: the C frame has too little shadow to compare" % (name, order))
        if not diff < 2.0:
            fail.append("%s order %d: mean abs difference %.3f/255 >= 2/255" % (name, order, diff))


scene("room", "builtin:room", ["--max-edge", "0.5", "--rays", "256"], [2, 3, 5],
      lambda lo, hi: ([7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]))


def outside(lo, hi):
    c, d = (lo + hi) / 2, np.linalg.norm(hi - lo)
    return (list(c + d * np.array([0.45, 0.35, 0.75])), list(c), list(c + d * np.array([0.2, 0.6, 0.3])))


engine = os.path.join(models, "glTF2", "2CylinderEngine-glTF-Binary", "2CylinderEngine.glb")
if os.path.exists(engine):
    scene("engine", engine, ["--rays", "64"], [5], outside)
else:
    print("no %s: the glTF scene part skipped" % engine)

for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
