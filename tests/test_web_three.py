"""test_web_three.py BAKE EXPORT VIEW CHROMIUM RUNTIMEDIR WORKDIR NODE MODULES [ASSIMP_MODELS] - the
three.js module (runtime/web/vdsh_three.js) and the shader files in GLSL
ES 3.00, in headless Chromium (WebGL2 on SwiftShader).

three.js: builtin:room is baked (orders 2, 3, 5, 12 and an adaptive-order
stream up to 12; log distance, the default), exported with vdsh-export,
loaded by three.js's GLTFLoader in runtime/web/three.html (a three.js
scene with its own PointLights, the material of vdsh_three.js on the
loaded mesh, output=shadow: the visibility of the first point light as
grey) and compared with vdsh-view --views' shadow frame of the same camera
and light (vdsh2, vdsh3, vdsh5, buf12, adaptive): mean absolute difference
below 2/255, and the C frame must hold shadows (so a page drawing no
shadow cannot pass). Also:
  - three lights in the three.js scene (light 0 first): light 0's
    visibility against vdsh-view's frame of light 0 of the same light set
    (order 5 and the buffer path at 12: the multi-light code);
  - the paper method (distance, a linear quantity: the per-vertex
    visibility path) at orders 2, 3, 5;
  - the room as vdsh-export --compress writes it (KHR_mesh_quantization,
    EXT_meshopt_compression; orders 5 and 12), and as gltfpack would
    (tests/web_glb_pack.mjs, meshopt), against the same frames;
  - a glTF scene of its own: Debian assimp-testmodels' 2CylinderEngine
    (82 nodes, 34 materials) baked and exported with --source (root
    extension VDSH_visibility_distance, attributes on every primitive),
    plain and --compress, drawn with vdshApply and the source's own
    materials, against vdsh-view's frame of the same bake;
  - a cpca stream (issue 29: --encoding cpca, order 12; the default
    16,alloc:32, a width per basis vector), exported as
    stored, kept compressed by vdshLoadCpca and decoded in the vertex
    stage (plain and --compress, 1 and 3 lights) or decoded at load
    (cpca=load), against vdsh-view's buf12 (decoded in its vertex stage),
    the page's title naming the path taken;
  - the glTF scene moved: gltf.scene translated and given as `frame`, the
    camera and light moved with it: the same frame.
GLSL ES 3.00: runtime/shaders/es_check (this test's page es_check.html)
compiles and links, as "#version 300 es" with a precision header, the C
runtime's own programs from the same files (vdsh_common.glsl,
vr_vertex.glsl, vdsh_buffer.glsl with BUF_TEXTURE_2D, vr_vertex_main.glsl,
vr_fragment.glsl) for every path and 1 and 4 lights; every one must
compile and link.
The pages are served over HTTP (ES modules, fetch) from WORKDIR by a
Python server on 127.0.0.1. Exit 77 without chromium, node's three.js
(MODULES from scripts/npm_gltf_tools) or a GL context for vdsh-view.
"""
import functools
import http.server
import json
import os
import shutil
import subprocess
import sys
import threading

import numpy as np
from PIL import Image

import testlib

bake, export, view, chromium, rtdir, work, node, modules = sys.argv[1:9]
models = sys.argv[9] if len(sys.argv) > 9 else ""
if not shutil.which(chromium):
    print("no chromium: skipped")
    sys.exit(77)
three = os.path.join(modules, "three")
if not os.path.exists(os.path.join(three, "build", "three.module.js")):
    print("no three.js in %s (scripts/npm_gltf_tools): skipped" % modules)
    sys.exit(77)
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
shutil.copytree(os.path.join(rtdir, "web"), os.path.join(work, "web"))
shutil.copytree(os.path.join(rtdir, "shaders"), os.path.join(work, "shaders"))
os.symlink(os.path.abspath(three), os.path.join(work, "web", "three"))
shutil.copy(os.path.join(os.path.dirname(os.path.abspath(__file__)), "es_check.html"), os.path.join(work, "web"))

handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=work)
handler.func.log_message = lambda *a: None
server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
threading.Thread(target=server.serve_forever, daemon=True).start()
base = "http://127.0.0.1:%d/web/" % server.server_address[1]

CHROME = [chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
          "--hide-scrollbars", "--force-device-scale-factor=1", "--window-size=800,600",
          "--virtual-time-budget=30000"]
W, H = 320, 240
fail = []
csv = lambda v: ",".join("%g" % x for x in v)


def run(cmd):
    p = subprocess.run(cmd, capture_output=True, text=True)
    if p.returncode != 0:
        print("FAIL: %s: rc %d\n%s" % (" ".join(cmd), p.returncode, p.stderr))
        sys.exit(1)
    return p


def dom(url):
    return subprocess.run(CHROME + ["--dump-dom", url], capture_output=True, text=True, timeout=300).stdout


def title_of(d):
    import re
    m = re.search(r"<title>(.*?)</title>", d, re.S)
    return m.group(1) if m else "(no title)"


def shot(query, out):
    """The page's screenshot into out and its title, in one launch."""
    if os.path.exists(out):
        os.remove(out)
    d = dom_shot(base + "three.html?" + query, out)
    return os.path.exists(out), title_of(d)


def dom_shot(url, out):
    return subprocess.run(CHROME + ["--screenshot=" + out, "--dump-dom", url], capture_output=True, text=True,
                          timeout=300).stdout


def title_error(query):
    return title_of(dom(base + "three.html?" + query))


def compare(label, png, ref, min_dark):
    """(lines, fails) of the page's frame against the C frame."""
    a = np.asarray(Image.open(png).convert("L"), float)[:H, :W] / 255
    b = np.asarray(Image.open(ref)).astype(float) / 65535
    diff = np.abs(a - b).mean() * 255
    dark = (1 - b).mean()
    lines = ["%s: mean |three.js - C| = %.4f/255; mean shadow C %.2f%%, three.js %.2f%%"
             % (label, diff, 100 * dark, 100 * (1 - a).mean())]
    fails = []
    if dark < min_dark:
        fails.append("%s: the C frame has too little shadow to compare" % label)
    if not diff < 2.0:
        fails.append("%s: mean abs difference %.3f/255 >= 2/255" % (label, diff))
    return lines, fails


pages = testlib.Pages(fail)


def frames(name, vd, eye, target, light_set, modes):
    views = os.path.join(work, name + "-views.json")
    testlib.write_view(views, name, W, H, eye, target, [light_set])
    testlib.view_frames(view, views, os.path.join(work, "c"), modes, vd)
    return lambda mode: os.path.join(work, "c", "%s-s0-l0-%s.png" % (name, mode))


def check(label, glb, order, eye, target, lights, ref, min_dark, extra="", path=None):
    q = ("glb=../%s&order=%s&output=shadow&size=%dx%d&eye=%s&target=%s&up=0,1,0&fov=60%s%s"
         % (glb, order, W, H, csv(eye), csv(target), "".join("&light=" + csv(l) for l in lights), extra))
    png = os.path.join(work, "three-%s.png" % label.replace(" ", "-"))

    def job():
        ok, t = shot(q, png)
        if not ok:
            return [], ["%s: no screenshot" % label]
        if not t.startswith("ready"):
            return [], ["%s: the page says %r" % (label, t)]
        lines, fails = compare(label, png, ref, min_dark)
        if path and t.split()[-1] != path:
            fails.append("%s: drawn on the path %r, not %r" % (label, t.split()[-1], path))
        return lines, fails
    pages.submit(job)


eye, target, light = [7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]
more = [[2.0, 1.5, -3.0], [-3.0, 2.0, 2.0]]

# The room, log distance: the attribute path (2, 3, 5), the buffer path
# (12, adaptive); one light, then three.
vd, glb = os.path.join(work, "room.vdsh"), os.path.join(work, "room.glb")
run([bake, "builtin:room", "-o", vd, "-q", "--orders", "2,3,5,12", "--max-edge", "0.5", "--rays", "256",
     "--adaptive-order", "0.02", "--max-order", "12"])
run([export, vd, "-o", glb])
modes = [("2", "vdsh2"), ("3", "vdsh3"), ("5", "vdsh5"), ("12", "buf12"), ("adaptive", "adaptive")]
ref = frames("room", vd, eye, target, [light], [m for _, m in modes])
for order, mode in modes:
    check("room order %s" % order, "room.glb", order, eye, target, [light], ref(mode),
          0.0002 if order in ("2", "3") else 0.005)
ref3 = frames("room3", vd, eye, target, [light] + more, ["vdsh5", "buf12"])
for order, mode in (("5", "vdsh5"), ("12", "buf12")):
    check("room order %s 3 lights" % order, "room.glb", order, eye, target, [light] + more, ref3(mode), 0.005)

# A cpca stream (issue 29: vdsh-bake --encoding cpca), exported as stored,
# kept compressed by vdshLoadCpca and decoded in the vertex stage
# (three.html's default), plain and --compress, and decoded at load
# (cpca=load), against vdsh-view's buf12 (decoded in its vertex stage), 1
# and 3 lights; the page's title names the path taken.
# (At edge 1.0, 3,755 receivers: the encode takes seconds.)
cvd = os.path.join(work, "cpca.vdsh")
run([bake, "builtin:room", "-o", cvd, "-q", "--orders", "12", "--max-edge", "1.0", "--rays", "256",
     "--encoding", "cpca"])
run([export, cvd, "-o", os.path.join(work, "cpca.glb")])
run([export, cvd, "-o", os.path.join(work, "cpca-compress.glb"), "--compress", "-q"])
cref, cref3 = frames("cpca", cvd, eye, target, [light], ["buf12"]), frames("cpca3", cvd, eye, target, [light] + more, ["buf12"])
for f in ("cpca", "cpca-compress"):
    check("%s order 12" % f, f + ".glb", "12", eye, target, [light], cref("buf12"), 0.005, path="cpca")
check("cpca order 12 decoded at load", "cpca.glb", "12", eye, target, [light], cref("buf12"), 0.005, "&cpca=load",
      path="buffer")
check("cpca order 12 3 lights", "cpca.glb", "12", eye, target, [light] + more, cref3("buf12"), 0.005, path="cpca")

# A linear quantity (the paper's distance): per-vertex visibility.
pvd, pglb = os.path.join(work, "paper.vdsh"), os.path.join(work, "paper.glb")
run([bake, "builtin:room", "-o", pvd, "-q", "--orders", "2,3,5", "--max-edge", "0.5", "--rays", "256",
     "--method", "paper"])
run([export, pvd, "-o", pglb])
pref = frames("paper", pvd, eye, target, [light], ["vdsh2", "vdsh3", "vdsh5"])
for order in ("2", "3", "5"):
    check("paper order %s" % order, "paper.glb", order, eye, target, [light], pref("vdsh" + order), 0.0002)

# The scene moved in three.js: gltf.scene translated (frame=), the camera
# and light with it.
shift = [3.0, -1.0, 2.0]
mv = lambda p: [p[k] + shift[k] for k in range(3)]
check("room order 5 moved", "room.glb", "5", mv(eye), mv(target), [mv(light)], ref("vdsh5"), 0.005,
      "&move=" + csv(shift))

# Compressed: vdsh-export --compress (KHR_mesh_quantization and
# EXT_meshopt_compression: GLTFLoader with meshopt's decoder), the
# attribute path (5) and the buffer path (12); and a third-party writer's
# layout (tests/web_glb_pack.mjs: gltfpack's quantisation, meshopt).
cglb = os.path.join(work, "room-compress.glb")
run([export, vd, "-o", cglb, "--compress", "-q"])
for order, mode in (("5", "vdsh5"), ("12", "buf12")):
    check("room-compress order %s" % order, "room-compress.glb", order, eye, target, [light], ref(mode), 0.005)
pack = os.path.join(os.path.dirname(os.path.abspath(__file__)), "web_glb_pack.mjs")
if node and os.path.exists(os.path.join(modules, "meshoptimizer", "meshopt_encoder.js")):
    run([node, pack, modules, glb, os.path.join(work, "room-meshopt.glb"), "meshopt"])
    check("room-meshopt order 5", "room-meshopt.glb", "5", eye, target, [light], ref("vdsh5"), 0.005)
else:
    fail.append("no node or meshoptimizer in %s for the compressed files" % modules)

# A glTF scene of its own (vdsh-export --source: 82 nodes, 29 meshes, 34
# materials; metadata in the root extension VDSH_visibility_distance, VDSH
# attributes on every primitive), plain and --compress: vdshApply on the
# loaded scene, the source's materials kept, against vdsh-view's frame of
# the same bake (the receivers are the source's vertices, in its world
# frame), seen and lit from outside.
engine = os.path.join(models, "glTF2", "2CylinderEngine-glTF-Binary", "2CylinderEngine.glb") if models else ""
if os.path.exists(engine):
    evd = os.path.join(work, "engine.vdsh")
    run([bake, engine, "-o", evd, "-q", "--orders", "5", "--rays", "64"])
    run([export, evd, "-o", os.path.join(work, "engine.glb"), "-q"])
    d = open(os.path.join(work, "engine.glb"), "rb").read()
    g = json.loads(d[20:20 + int.from_bytes(d[12:16], "little")])
    a = g["accessors"][g["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    lo, hi = np.array(a["min"]), np.array(a["max"])
    c, r = (lo + hi) / 2, np.linalg.norm(hi - lo)
    eeye, etarget, elight = list(c + r * np.array([0.45, 0.35, 0.75])), list(c), list(c + r * np.array([0.2, 0.6, 0.3]))
    eref = frames("engine", evd, eeye, etarget, [elight], ["vdsh5"])
    for tag, opt in (("source", []), ("source-compress", ["--compress"])):
        out = "engine-%s.glb" % tag
        run([export, evd, "--source", engine, "-o", os.path.join(work, out), "-q"] + opt)
        check("engine %s order 5" % tag, out, "5", eeye, etarget, [elight], eref("vdsh5"), 0.005)
else:
    print("no %s: the --source part skipped" % engine)

# URL parameters with a typo: said on the page (they were drawn as the
# default, or as NaN: eye=a,b gave a black frame).
for q, want in (("eye=1,2", "eye=1,2: expected x,y,z"), ("light=a,b,c", "light=a,b,c: expected x,y,z"),
                ("output=shade", "give output=shadow"), ("path=buffers", "give path=buffer"),
                ("size=320", "size=320: expected WxH"), ("fov=0", "fov=0: expected degrees"),
                # three.js not where the page looks: stayed "loading", no message (and
                # three=DIR without "./" was taken by the import map as a bare name)
                ("three=nowhere/", "/web/nowhere/ (build/three.module.js")):
    def typo(q=q, want=want):
        t = title_error("glb=../room.glb&" + q)
        return (["three.html?%s: %s" % (q, t)],
                [] if want in t else ["three.html?%s: no message naming '%s' (title %r)" % (q, want, t)])
    pages.submit(typo)


# GLSL ES 3.00: the C runtime's programs from the same files.
def es_check():
    import re
    m = re.search(r'<pre id="out">(.*?)</pre>', dom(base + "es_check.html"), re.S)
    out = m.group(1).strip() if m else ""
    return (["es_check: " + (out.splitlines()[-1] if out else "(no output)")],
            [] if out.endswith("ok") and "FAIL" not in out else ["GLSL ES 3.00 check: %s" % out[-3000:]])


pages.submit(es_check)
pages.close()
server.shutdown()
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
