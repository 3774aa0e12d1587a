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
(read by the glTF reader), seen and lit from outside; its --source export
(a scene of many meshes, for three.html) is refused with a message naming
three.html. The page's vertex stage, stream choice and buffer-path data
are vdsh_core.js's (shared with vdsh_three.js), loaded as ES modules.

Orders above 5 and the adaptive order (issue 26: the page was blank for
them): the room's bake also holds an order-12 stream and an adaptive-order
stream (--adaptive-order, up to 12), drawn by the page's buffer path
against vdsh-view's buf12 and adaptive modes, same tolerance.

The default view (issue 26: the page looked at a room's outer wall and lit
an object from inside it): the page opened with no camera and no light
(shaded, its default stream) must draw vdsh-view --render's default
picture of the same .vdsh (the camera, light, colours and fall-off of
vdsh-view, from extras.vdsh.view of the glb), mean absolute RGB difference
below 2/255, with the default light in free space (lights_free) and the
picture not black; for the room and for the engine.

Compressed glb (issue 26: the page said "ready" and drew nothing): the room
rewritten by tests/web_glb_pack.mjs as gltfpack writes it
(KHR_mesh_quantization: uint16 positions dequantised by the node's
transform, int8 normals), and that compressed with EXT_meshopt_compression
(meshoptimizer's encoder, the npm package, installed by
scripts/npm_gltf_tools into MODULES), must draw the order-5 frame as the
plain glb does, and so must vdsh-export --compress's own file; without
meshopt_decoder.cjs beside the page the meshopt
file must be refused with a visible message (#msg). Skipped without node
or MODULES.

A cpca stream (issue 29): the room baked with --encoding cpca at order
12, exported as stored (cluster and weight attributes, the model in a
buffer view; plain and --compress), decoded by the page in its vertex
stage (the default, compressed on the GPU; the page's title says so) and
at load (cpca=load), against vdsh-view's buf12 (decoded in its vertex
stage), same tolerance, and the same with a width per basis vector
(--cpca 8,alloc:32); a cpca glb with 9 bits per weight and an unknown
cpca= are refused on the page.

Errors on the page (issue 26: a GLSL error in the tab title was the only
sign): a file that is not a glb, a glb without VDSH streams (assimp's
engine itself) and one that requires an extension the page does not read
must each show a visible #msg element naming the problem (the DOM as
chromium --dump-dom prints it).
Arguments after ASSIMP_MODELS (optional): NODE MODULES.
Exit 77 when vdsh-view cannot make a GL context or chromium is missing.
"""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

import testlib

bake, export, view, chromium, webdir, work, models = sys.argv[1:8]
node = sys.argv[8] if len(sys.argv) > 8 else ""
modules = sys.argv[9] if len(sys.argv) > 9 else ""
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
for f in ("index.html", "vdsh_web.js", "vdsh_core.js"):
    shutil.copy(os.path.join(webdir, f), work)
# The page's GLSL: runtime/shaders/ (vdsh_common.glsl, vdsh_buffer.glsl),
# found in shaders/ beside the page.
shutil.rmtree(os.path.join(work, "shaders"), ignore_errors=True)
shutil.copytree(os.path.join(webdir, "..", "shaders"), os.path.join(work, "shaders"))


CHROME = [chromium, "--headless=new", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
          "--allow-file-access-from-files", "--hide-scrollbars", "--force-device-scale-factor=1",
          "--window-size=800,600", "--virtual-time-budget=20000"]


def page(query, shot=None):
    """The page at index.html?QUERY: a screenshot into shot, else the DOM."""
    url = "file://%s/index.html?%s" % (os.path.abspath(work), query)
    if shot:
        if os.path.exists(shot):
            os.remove(shot)
        subprocess.run(CHROME + ["--screenshot=" + shot, url], capture_output=True, text=True, timeout=300)
        return os.path.exists(shot)
    p = subprocess.run(CHROME + ["--dump-dom", url], capture_output=True, text=True, timeout=300)
    return p.stdout


def message(dom):
    """The text of a visible #msg element of a dumped DOM, else None."""
    import re
    m = re.search(r'<div id="msg"([^>]*)>(.*?)</div>', dom, re.S)
    if not m or "hidden" in m.group(1) or not m.group(2).strip():
        return None
    return m.group(2).strip()


def glb_json(glb):
    import struct
    d = open(glb, "rb").read()
    jl = struct.unpack_from("<I", d, 12)[0]
    return json.loads(d[20:20 + jl])


def bounds(glb):
    import struct
    d = open(glb, "rb").read()
    jl = struct.unpack_from("<I", d, 12)[0]
    g = json.loads(d[20:20 + jl])
    a = g["accessors"][g["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
    return np.array(a["min"]), np.array(a["max"])


def compare(label, shot, ref, order, rgb=False):
    """The page's screenshot against vdsh-view's frame: mean |difference|
    below 2/255 (grey shadow frames, or RGB pictures)."""
    if rgb:
        a = np.asarray(Image.open(shot).convert("RGB"), float)[:H, :W] / 255
        b = np.asarray(Image.open(ref).convert("RGB"), float) / 255
    else:
        a = np.asarray(Image.open(shot).convert("L"), float)[:H, :W] / 255
        b = np.asarray(Image.open(ref)).astype(float) / 65535
    diff = np.abs(a - b).mean() * 255
    lines, fails = [], []
    if rgb:
        lines.append("%s: mean |web - C| = %.4f/255 (RGB); mean value C %.3f, web %.3f"
                     % (label, diff, b.mean(), a.mean()))
        if b.mean() < 0.01:
            fails.append("%s: vdsh-view's default picture is black" % label)
    else:
        dark = (1 - b).mean()
        mask = (a < 0.99) | (b < 0.99)
        local = np.abs(a - b)[mask].mean() * 255 if mask.any() else 0.0
        lines.append("%s: mean |web - C| = %.4f/255 (%.3f/255 over the %d pixels shadowed in either); "
                     "mean shadow C %.2f%%, web %.2f%%"
                     % (label, diff, local, mask.sum(), 100 * dark, 100 * (1 - a).mean()))
        if dark < (0.0002 if order in (2, 3) else 0.005):
            fails.append("%s: the C frame has too little shadow to compare" % label)
    if not diff < 2.0:
        fails.append("%s: mean abs difference %.3f/255 >= 2/255" % (label, diff))
    return lines, fails


def shot_job(label, query, shot, ref, order, rgb=False):
    """Queue the page's screenshot at query against ref (compare)."""
    def job():
        if not page(query, shot):
            return [], ["%s: no screenshot" % label]
        return compare(label, shot, ref, order, rgb)
    pages.submit(job)


def message_job(label, query, want):
    """Queue the page at query: its visible message must name want."""
    def job():
        msg = message(page(query))
        return (["%s: the page says: %s" % (label, msg)],
                [] if msg and want in msg else
                ["%s: no visible message naming '%s' on the page (got %r)" % (label, want, msg)])
    pages.submit(job)


pages = testlib.Pages(fail)


def scene(name, source, opts, orders, place, modes=None):
    """Bake (orders; opts may add an adaptive stream), export, and compare
    the page with vdsh-view for each of modes: (page's order=, vdsh-view's
    mode), default the orders as vdshN."""
    vd, glb = os.path.join(work, name + ".vdsh"), os.path.join(work, name + ".glb")
    run([bake, source, "-o", vd, "-q", "--orders", ",".join(map(str, orders))] + opts)
    run([export, vd, "-o", glb])
    modes = modes or [(str(o), "vdsh%d" % o) for o in orders]
    eye, target, light = place(*bounds(glb))
    views = os.path.join(work, name + "-views.json")
    testlib.write_view(views, name, W, H, eye, target, [[light]])
    frames = os.path.join(work, "c")
    testlib.view_frames(view, views, frames, sorted({m[1] for m in modes}), vd)
    for order, mode, *extra in modes:
        label = "%s order %s%s" % (name, order, "".join(" " + e for e in extra))
        shot = os.path.join(work, "web-%s-%s%s.png" % (name, order, "".join("-" + e.replace("=", "-") for e in extra)))
        q = ("glb=%s.glb&order=%s&output=shadow&size=%dx%d&eye=%s&target=%s&up=0,1,0&fov=60&light=%s"
             % (name, order, W, H, csv(eye), csv(target), csv(light))) + "".join("&" + e for e in extra)
        shot_job(label, q, shot, os.path.join(frames, "%s-s0-l0-%s.png" % (name, mode)),
                 int(order) if order.isdigit() else 0)
    return vd, glb


def default_view(name, vd, glb):
    """The page with no camera, light or order against vdsh-view --render's
    default picture of the same file."""
    ref = os.path.join(work, "c-%s-default.png" % name)
    p = subprocess.run([view, "-q", "--render", ref, "--size", "%dx%d" % (W, H), vd], capture_output=True, text=True)
    if p.returncode != 0:
        fail.append("%s: vdsh-view --render: %s" % (name, p.stderr))
        return
    v = glb_json(glb)["meshes"][0]["extras"]["vdsh"].get("view")
    if not v or not v.get("lights_free", [False])[0]:
        fail.append("%s: the glb has no default view, or its light 0 is not in free space: %r" % (name, v))
    shot_job("%s default view" % name, "glb=%s&size=%dx%d" % (os.path.basename(glb), W, H),
             os.path.join(work, "web-%s-default.png" % name), ref, 0, rgb=True)


room_vd, room_glb = scene("room", "builtin:room", ["--max-edge", "0.5", "--rays", "256", "--adaptive-order", "0.02",
                                                   "--max-order", "12"], [2, 3, 5, 12],
                          lambda lo, hi: ([7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]),
                          [("2", "vdsh2"), ("3", "vdsh3"), ("5", "vdsh5"), ("12", "buf12"), ("adaptive", "adaptive")])
default_view("room", room_vd, room_glb)
# A cpca stream (issue 29; vdsh-bake --encoding cpca): exported as stored
# (cluster and weight attributes, the model in a buffer view), kept
# compressed and decoded in the page's vertex stage (vdsh_core.js's
# vdshCpcaBufferData, vdsh_buffer.glsl's BUF_KIND 4; the default), and
# decoded at load by vdshCpcaDecode (cpca=load), each against vdsh-view's
# buf12 (decoded in its vertex stage), same tolerance; the page's title
# names the path it took.
# (At edge 1.0, 3,755 receivers: the page's decode does not depend on
# the density, and the encode takes seconds, not the 36 s of edge 0.5.)
cpca_vd, cpca_glb = scene("cpca", "builtin:room", ["--max-edge", "1.0", "--rays", "256", "--encoding", "cpca",
                                                    "--cpca", "8,54,4"], [12],
                          lambda lo, hi: ([7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]),
                          [("12", "buf12"), ("12", "buf12", "cpca=load")])
if "cpca" not in glb_json(cpca_glb)["meshes"][0]["extras"]["vdsh"]["streams"][0]:
    fail.append("cpca.glb: its stream is not exported as cpca")
for query, want in (("", "cpca vertex"), ("&cpca=load", "cpca load")):
    def title_job(query=query, want=want):
        dom = page("glb=cpca.glb&order=12&size=%dx%d%s" % (W, H, query))
        return [], ([] if "<title>ready %dx%d %s</title>" % (W, H, want) in dom else
                    ["cpca.glb%s: the page's title does not say '%s' (a different decode path?)" % (query, want)])
    pages.submit(title_job)
# The same with a width per basis vector (--cpca 8,alloc:32: "bits": 0
# and "widths"; the page's shader unpacks each field with its own width,
# vdshCpcaBufferData's BUF_CPCA_UNPACK).
cpcaw_vd, cpcaw_glb = scene("cpcaw", "builtin:room", ["--max-edge", "1.0", "--rays", "256", "--encoding", "cpca",
                                                      "--cpca", "8,alloc:32"], [12],
                            lambda lo, hi: ([7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]),
                            [("12", "buf12"), ("12", "buf12", "cpca=load")])
cw = glb_json(cpcaw_glb)["meshes"][0]["extras"]["vdsh"]["streams"][0].get("cpca", {})
if cw.get("bits") != 0 or len(set(cw.get("widths", []))) < 2:
    fail.append("cpcaw.glb: not a stream of mixed widths: %r" % {k: cw.get(k) for k in ("bits", "widths")})

# Errors on the page itself.
bad = os.path.join(work, "bad.glb")
open(bad, "wb").write(b"this is not a glb\n" * 4)
draco = os.path.join(work, "draco.glb")
g = glb_json(room_glb)
g["extensionsUsed"] = g["extensionsRequired"] = ["KHR_draco_mesh_compression"]
js = json.dumps(g).encode()
js += b" " * (-len(js) % 4)
import struct
open(draco, "wb").write(struct.pack("<III", 0x46546C67, 2, 20 + len(js)) + struct.pack("<II", len(js), 0x4E4F534A) + js)
# a cpca stream whose model the page cannot read (9 bits per weight)
g = glb_json(cpca_glb)
g["meshes"][0]["extras"]["vdsh"]["streams"][0]["cpca"]["bits"] = 9
js = json.dumps(g).encode()
js += b" " * (-len(js) % 4)
d = open(cpca_glb, "rb").read()
jl = struct.unpack_from("<I", d, 12)[0]
open(os.path.join(work, "cpca-bad.glb"), "wb").write(
    struct.pack("<III", 0x46546C67, 2, 20 + len(js) + len(d) - 20 - jl) + struct.pack("<II", len(js), 0x4E4F534A) + js +
    d[20 + jl:])
errs = [("bad.glb", "not a glb"), ("draco.glb", "KHR_draco_mesh_compression"), ("cpca-bad.glb", "bits 9 out of range"),
        ("cpca.glb&cpca=gpu", "give cpca=vertex or cpca=load"),
        # URL parameters with a typo were ignored, the default drawn
        ("cpca.glb&output=shade", "give output=shadow"), ("cpca.glb&path=buffers", "give path=buffer"),
        ("cpca.glb&lights=0", "lights=0: expected a whole number"), ("cpca.glb&size=640x", "size=640x: expected WxH"),
        ("cpca.glb&fov=abc", "fov=abc: expected degrees")]
plain = os.path.join(models, "glTF2", "2CylinderEngine-glTF-Binary", "2CylinderEngine.glb")
if os.path.exists(plain):
    shutil.copy(plain, os.path.join(work, "plain.glb"))
    errs.append(("plain.glb", "no VDSH streams"))
for f, want in errs:
    message_job(f, "glb=%s&size=%dx%d" % (f, W, H), want)
pages.drain()  # before the page's files change

# A module the page cannot fetch (vdsh_core.js not copied beside it, or the
# page opened from file:// without access to files): said on the page (it
# stayed blank, "loading").
core = os.path.join(work, "vdsh_core.js")
os.rename(core, core + ".off")
msg = message(page("glb=cpca.glb&size=%dx%d" % (W, H)))
os.rename(core + ".off", core)
print("without vdsh_core.js: the page says: %s" % msg)
if not msg or "cannot load vdsh_web.js and vdsh_core.js" not in msg:
    fail.append("without vdsh_core.js: no visible message (got %r)" % msg)

# Compressed files: quantised (KHR_mesh_quantization), meshopt.
if node and modules and os.path.exists(os.path.join(modules, "meshoptimizer", "meshopt_encoder.js")):
    pack = os.path.join(os.path.dirname(os.path.abspath(__file__)), "web_glb_pack.mjs")
    for how in ("quantise", "meshopt"):
        out = os.path.join(work, "room-%s.glb" % how)
        run([node, pack, modules, room_glb, out, how])
    run([export, room_vd, "-o", os.path.join(work, "room-compress.glb"), "--compress", "-q"])
    dec = os.path.join(work, "meshopt_decoder.cjs")
    if os.path.exists(dec):
        os.remove(dec)
    msg = message(page("glb=room-meshopt.glb&size=%dx%d" % (W, H)))
    print("room-meshopt.glb without the decoder: the page says: %s" % msg)
    if not msg or "EXT_meshopt_compression" not in msg:
        fail.append("room-meshopt.glb without meshopt_decoder.cjs: no visible message (got %r)" % msg)
    shutil.copy(os.path.join(modules, "meshoptimizer", "meshopt_decoder.cjs"), work)
    eye, target, light = [7.5, 4.5, 8.0], [-2.0, 1.0, -2.0], [0.5, 1.2, 0.5]
    for how in ("quantise", "meshopt", "compress"):
        q = ("glb=room-%s.glb&order=5&output=shadow&size=%dx%d&eye=%s&target=%s&up=0,1,0&fov=60&light=%s"
             % (how, W, H, csv(eye), csv(target), csv(light)))
        shot_job("room-%s.glb order 5" % how, q, os.path.join(work, "web-room-%s.png" % how),
                 os.path.join(work, "c", "room-s0-l0-vdsh5.png"), 5)
    # the cpca file compressed: its model view too (EXT_meshopt_compression)
    run([export, cpca_vd, "-o", os.path.join(work, "cpca-compress.glb"), "--compress", "-q"])
    q = ("glb=cpca-compress.glb&order=12&output=shadow&size=%dx%d&eye=%s&target=%s&up=0,1,0&fov=60&light=%s"
         % (W, H, csv(eye), csv(target), csv(light)))
    shot_job("cpca-compress.glb order 12", q, os.path.join(work, "web-cpca-compress.png"),
             os.path.join(work, "c", "cpca-s0-l0-buf12.png"), 12)
else:
    print("no node or no meshoptimizer in %r: the compressed glb part skipped" % modules)
def outside(lo, hi):
    c, d = (lo + hi) / 2, np.linalg.norm(hi - lo)
    return (list(c + d * np.array([0.45, 0.35, 0.75])), list(c), list(c + d * np.array([0.2, 0.6, 0.3])))


engine = os.path.join(models, "glTF2", "2CylinderEngine-glTF-Binary", "2CylinderEngine.glb")
if os.path.exists(engine):
    evd, eglb = scene("engine", engine, ["--rays", "64"], [5], outside)
    default_view("engine", evd, eglb)
    # A --source export (the glTF's own scene, many meshes): the page
    # draws the plain export only and says so, naming three.html.
    run([export, evd, "--source", engine, "-o", os.path.join(work, "engine-source.glb"), "-q"])
    message_job("engine-source.glb", "glb=engine-source.glb&size=%dx%d" % (W, H), "three.html")
else:
    print("no %s: the glTF scene part skipped" % engine)

pages.close()
for f in fail:
    print("FAIL:", f)
sys.exit(1 if fail else 0)
