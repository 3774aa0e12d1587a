// vdsh_web.js - a WebGL2 viewer of a glb written by vdsh-export
// (formats/GLTF.md): the receiver mesh lit by point lights with VDSH
// shadows, by the C runtime's shadow rule and with its GLSL functions
// (runtime/shaders/vdsh_common.glsl and vdsh_buffer.glsl, loaded from
// shaders/ beside the page or ../shaders/, or shaders=URL). An ES module
// (index.html loads it with type="module"): the vertex stage's VDSH code,
// the stream choice and the buffer path's data are vdsh_core.js's, the
// same as the three.js module's (vdsh_three.js); what is the page's own is
// vdsh-view's shading (Lambert, its lights), so that its default picture
// is vdsh-view's, and the glb reader (no three.js needed). A three.js
// scene, and a --source export (the source's own scene), use vdsh_three.js
// (three.html):
//   log-distance streams (any order): per vertex the whole SH sum toward
//     each light, d = min(exp(min(sum, 80)), max_distance), interpolated;
//     per fragment visibility = compare(d, |light - fragment|);
//   linear streams (distance, distance^2) of orders 2 and 3 (and 5): per
//     vertex the distance and the comparison, the visibility interpolated
//     (the C runtime's path for orders 2 and 3; its order-5 split path is
//     not reproduced here).
// Orders 2, 3 and 5 read their coefficients as vertex attributes. Every
// other order (1, 4, 6-16) and a stream with an order per vertex
// (vdsh-bake --adaptive-order) take the buffer path, as vdsh-view's bufN
// and adaptive modes do (runtime/shaders/vdsh_buffer.glsl): each vertex's
// coefficients in a float texture, read front to back in the vertex stage
// and summed by the associated-Legendre recurrence for any order, then the
// distance path above for every quantity. (WebGL2 vertex attributes stop
// at 16 VEC4, order 5 at most with position and normal.) A cpca stream
// (vdsh-bake --encoding cpca) stays compressed on the GPU: its records in
// an integer texture and its model in a float one, each vertex's
// coefficients decoded in the vertex stage as vdsh-view does
// (vdsh_buffer.glsl's BUF_KIND 4); cpca=load decodes it at load instead
// (576 GPU bytes per vertex at order 12 against about 32).
// compare: smooth clamp(1.5 d / dl - 0.5, 0, 1) (formats/vdsh_shadow.h).
// The camera is formats/vdsh_camera.h's (gluLookAt basis, vertical fov).
// Shading is vdsh-view's (runtime/vdsh_view_core.c): albedo 0.8, ambient
// 0.03, light colours and fall-off as its default lights; no gamma.
//
// Default view: vdsh-view's, which vdsh-export writes into
// meshes[0].extras.vdsh.view (formats/vdsh_scene_view.h: a room seen from
// inside, an object framed from outside, lights moved into free space).
// A file without it (an older export) is framed from outside, lit from
// in its light region (vdsh_core.js's vdshFallbackView:
// vdsh_view_fit_camera and an object's preferred lights, moved into free
// space by vdsh-view's rule), as vdsh-view frames an object; a flat one (a
// triangle, a panel) from its front.
//
// Files: glTF 2.0 binary; attributes of any component type, normalised or
// not, interleaved or not, and the node's transform (KHR_mesh_quantization,
// as gltfpack and glTF-Transform write it); buffer views compressed with
// EXT_meshopt_compression (or KHR_meshopt_compression) are decoded with
// meshoptimizer's decoder, meshopt_decoder.cjs of the npm package
// meshoptimizer, loaded from next to the page (or meshopt=URL) only when a
// file needs it. Any other required extension (Draco, ...) is refused.
//
// URL parameters (all optional except glb): glb=FILE, order=N or
// order=adaptive (default: as vdsh-view, order 5, else 3, else 2, else
// the adaptive stream, else the highest order), path=buffer (the buffer
// path for orders 2, 3, 5 too: vdsh-view's bufN), eye=x,y,z, target=x,y,z,
// up=x,y,z, fov=DEG, light=x,y,z (repeatable, as light=..&light=..),
// shaders=URL (the folder of the shader files),
// lights=N (default lights, 1..4, default 1), size=WxH (canvas size;
// default the window), output=shadow (shadow factor of light 0 as grey,
// white where no surface: vdsh-view's --views frames) or shaded (default:
// vdsh-view --render's picture), meshopt=URL, cpca=vertex (default) or
// cpca=load (a cpca stream decoded in the vertex stage, or at load).
// Mouse: drag orbits the camera around the target, wheel zooms,
// shift+drag moves light 0 in the view plane. window.vdshReady is set to
// true (and document.title to "ready") once the first frame is drawn. On
// failure the message is shown on the page (#msg), in document.title
// ("error: ...") and in window.vdshError.
import { VDSH_EXT, vdshChooseStream, vdshStreamPlan, vdshBufferData, vdshVertexGlsl, vdshCpcaDecode,
  vdshCpcaBufferData, vdshFallbackView } from './vdsh_core.js';

// The program: vdsh_core.js's vertex stage (the VDSH value per light,
// interpolated), then vdsh-view's shading per fragment.
// cfg: plan (vdshStreamPlan), lights, output (0 shaded, 1 shadow),
// texWidth (buffer path); shaders: the texts of runtime/shaders/
// vdsh_common.glsl (the SH sums, vdsh_distance, vdsh_compare: the C
// runtime's own) and vdsh_buffer.glsl (the buffer path's recurrence).
function glsl(cfg, shaders) {
  const vg = vdshVertexGlsl(cfg.plan, shaders, cfg.texWidth, cfg.cpca);
  const head = `#version 300 es
precision highp float;
precision highp int;
#define NUM_LIGHTS ${cfg.lights}
#define OUTPUT ${cfg.output}
${vg.defines}${shaders.common}
`;
  const vs = head + `
in vec3 a_position;
in vec3 a_normal;
uniform mat4 u_view_proj;
uniform float vdshScale;
uniform float vdshMaxDistance;
uniform vec3 u_light_pos[NUM_LIGHTS];
out vec3 v_position;
out vec3 v_normal;
out float v_val[NUM_LIGHTS];
${vg.decl}
void main() {
  v_position = a_position;
  v_normal = a_normal;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
  float val[NUM_LIGHTS];
  vdsh_vertex(a_position, u_light_pos, val);
  for (int i = 0; i < NUM_LIGHTS; i++) v_val[i] = val[i];
}`;
  const fs = head + `
in vec3 v_position;
in vec3 v_normal;
in float v_val[NUM_LIGHTS];
uniform vec3 u_light_pos[NUM_LIGHTS];
uniform vec3 u_light_color[NUM_LIGHTS];  // times the albedo
uniform vec3 u_light_att[NUM_LIGHTS];
uniform vec3 u_ambient;                  // times the albedo
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  vec3 acc = vec3(0.0);
  float s0 = 1.0;
  for (int i = 0; i < NUM_LIGHTS; i++) {
    vec3 lv = u_light_pos[i] - v_position;
    float dl = length(lv);
#if VDSH_DIST_PATH
    float s = vdsh_compare(v_val[i], dl);
#else
    float s = v_val[i];
#endif
    if (i == 0) s0 = s;
    float ndl = dl > 0.0 ? max(dot(n, lv) / dl, 0.0) : 1.0;
    float att = 1.0 / dot(u_light_att[i], vec3(1.0, dl, dl * dl));
    acc += s * u_light_color[i] * (ndl * att);
  }
#if OUTPUT == 1
  o_color = vec4(s0, s0, s0, 1.0);
#else
  o_color = vec4(u_ambient + acc, 1.0);
#endif
}`;
  return { vs, fs };
}

// ---- the file ------------------------------------------------------------

function parseGlb(buf) {
  if (buf.byteLength < 20) throw new Error('not a glb (binary glTF) file: ' + buf.byteLength + ' bytes');
  const dv = new DataView(buf);
  if (dv.getUint32(0, true) !== 0x46546C67) throw new Error('not a glb (binary glTF) file: no "glTF" magic');
  if (dv.getUint32(4, true) !== 2) throw new Error('glb version ' + dv.getUint32(4, true) + ', not 2');
  const total = Math.min(dv.getUint32(8, true), buf.byteLength);
  const jl = dv.getUint32(12, true);
  if (dv.getUint32(16, true) !== 0x4E4F534A || 20 + jl > total) throw new Error('glb: no JSON chunk, or a truncated one');
  let json;
  try {
    json = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 20, jl)));
  } catch (e) {
    throw new Error('glb: its JSON chunk does not parse: ' + e.message);
  }
  let bin = null;
  const at = 20 + jl;
  if (at + 8 <= total && dv.getUint32(at + 4, true) === 0x004E4942) {
    const bl = dv.getUint32(at, true);
    if (at + 8 + bl > total) throw new Error('glb: the BIN chunk is truncated (' + bl + ' bytes announced, ' + (total - at - 8) + ' there)');
    bin = new Uint8Array(buf, at + 8, bl);
  }
  return { json, bin };
}

const READ_EXTENSIONS = ['KHR_mesh_quantization', 'EXT_meshopt_compression', 'KHR_meshopt_compression'];
const COMPONENTS = {  // componentType: bytes, DataView getter, normalisation divisor, signed
  5120: [1, 'getInt8', 127, true], 5121: [1, 'getUint8', 255, false],
  5122: [2, 'getInt16', 32767, true], 5123: [2, 'getUint16', 65535, false],
  5125: [4, 'getUint32', 0, false], 5126: [4, 'getFloat32', 0, true],
};
const TYPES = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4 };

// meshoptimizer's decoder, loaded once, from next to the page.
let meshopt = null;
function meshoptDecoder(url) {
  if (!meshopt)
    meshopt = (window.MeshoptDecoder ? Promise.resolve() : new Promise((ok, fail) => {
      const s = document.createElement('script');
      s.src = url;
      s.onload = ok;
      s.onerror = () => fail(new Error(
        'this file is compressed with EXT_meshopt_compression, and its decoder ' + url +
        ' is not next to the page: copy meshopt_decoder.cjs of the npm package meshoptimizer ' +
        'beside index.html (or give meshopt=URL)'));
      document.head.appendChild(s);
    })).then(() => {
      if (!window.MeshoptDecoder) throw new Error(url + ' did not define MeshoptDecoder');
      return window.MeshoptDecoder.ready.then(() => window.MeshoptDecoder);
    });
  return meshopt;
}

// The glTF's data: buffer views (decoded when compressed) and accessors
// as plain arrays.
class Gltf {
  constructor(json, bin, meshoptUrl) {
    this.json = json;
    this.bin = bin;
    this.meshoptUrl = meshoptUrl;
    this.views = [];
  }

  buffer(i) {
    const b = (this.json.buffers || [])[i];
    if (!b) throw new Error('buffer ' + i + ' does not exist');
    if (i === 0 && b.uri === undefined && this.bin) return this.bin;
    if (b.uri !== undefined) throw new Error('buffer ' + i + ' is an external file (' + String(b.uri).slice(0, 40) + '): give a .glb that holds its data');
    throw new Error('buffer ' + i + ' has no data in this glb');
  }

  // Every buffer view the accessors use, decompressed (async: the decoder).
  async prepare(accessors) {
    for (const ai of accessors) {
      const a = this.json.accessors[ai];
      if (!a) throw new Error('accessor ' + ai + ' does not exist');
      if (a.bufferView !== undefined) await this.viewBytes(a.bufferView, 'accessor ' + ai + ': ');
    }
  }

  // The bytes of buffer view vi, decompressed.
  async viewBytes(vi, what = '') {
    if (this.views[vi]) return this.views[vi];
    const v = (this.json.bufferViews || [])[vi];
    if (!v) throw new Error(what + 'buffer view ' + vi + ' does not exist');
    const x = v.extensions && (v.extensions.EXT_meshopt_compression || v.extensions.KHR_meshopt_compression);
    if (x) {
      const dec = await meshoptDecoder(this.meshoptUrl);
      const src = this.buffer(x.buffer).subarray(x.byteOffset || 0, (x.byteOffset || 0) + x.byteLength);
      const out = new Uint8Array(x.count * x.byteStride);
      dec.decodeGltfBuffer(out, x.count, x.byteStride, src, x.mode, x.filter || 'NONE');
      this.views[vi] = out;
    } else {
      const b = this.buffer(v.buffer), o = v.byteOffset || 0;
      if (o + v.byteLength > b.length) throw new Error('buffer view ' + vi + ' runs past its buffer');
      this.views[vi] = b.subarray(o, o + v.byteLength);
    }
    return this.views[vi];
  }

  // Accessor ai as numbers (normalised integers as glTF defines them), in
  // an array of type T (Float32Array by default).
  read(ai, T = Float32Array) {
    const a = this.json.accessors[ai];
    if (!a) throw new Error('accessor ' + ai + ' does not exist');
    if (a.sparse) throw new Error('accessor ' + ai + ' is sparse: not read');
    const c = COMPONENTS[a.componentType], n = TYPES[a.type];
    if (!c || !n) throw new Error('accessor ' + ai + ': component type ' + a.componentType + ' ' + a.type + ' not read');
    const out = new T(a.count * n);
    if (a.bufferView === undefined) return out;  // all zeros
    const bytes = this.views[a.bufferView];
    const stride = this.json.bufferViews[a.bufferView].byteStride || c[0] * n;
    const off = a.byteOffset || 0;
    if (a.count > 0 && off + (a.count - 1) * stride + n * c[0] > bytes.length)
      throw new Error('accessor ' + ai + ' runs past its buffer view');
    const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    const get = dv[c[1]].bind(dv), norm = a.normalized && c[2];
    for (let i = 0; i < a.count; i++)
      for (let k = 0; k < n; k++) {
        let x = get(off + i * stride + k * c[0], true);
        if (norm) x = c[3] ? Math.max(x / c[2], -1) : x / c[2];
        out[i * n + k] = x;
      }
    return out;
  }
}

// ---- matrices and the view -----------------------------------------------

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const norm = (a) => { const l = Math.hypot(a[0], a[1], a[2]); return [a[0] / l, a[1] / l, a[2] / l]; };
const mul4 = (a, b) => {  // column-major a * b
  const m = new Array(16).fill(0);
  for (let c = 0; c < 4; c++)
    for (let r = 0; r < 4; r++)
      for (let k = 0; k < 4; k++) m[c * 4 + r] += a[k * 4 + r] * b[c * 4 + k];
  return m;
};
const IDENTITY = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

function nodeMatrix(n) {
  if (n.matrix) return n.matrix.slice();
  const [x, y, z, w] = n.rotation || [0, 0, 0, 1], [sx, sy, sz] = n.scale || [1, 1, 1], t = n.translation || [0, 0, 0];
  return [(1 - 2 * (y * y + z * z)) * sx, 2 * (x * y + z * w) * sx, 2 * (x * z - y * w) * sx, 0,
    2 * (x * y - z * w) * sy, (1 - 2 * (x * x + z * z)) * sy, 2 * (y * z + x * w) * sy, 0,
    2 * (x * z + y * w) * sz, 2 * (y * z - x * w) * sz, (1 - 2 * (x * x + y * y)) * sz, 0,
    t[0], t[1], t[2], 1];
}

// The world matrix of the first node that draws mesh 0 (identity when no
// node does): KHR_mesh_quantization's dequantisation lives there.
function meshMatrix(json) {
  const nodes = json.nodes || [];
  const scene = (json.scenes || [])[json.scene || 0];
  const roots = scene ? scene.nodes || [] : nodes.map((_, i) => i);
  const walk = (i, parent, depth) => {
    const n = nodes[i];
    if (!n || depth > 64) return null;
    const m = mul4(parent, nodeMatrix(n));
    if (n.mesh === 0) return m;
    for (const c of n.children || []) {
      const r = walk(c, m, depth + 1);
      if (r) return r;
    }
    return null;
  };
  for (const r of roots) {
    const m = walk(r, IDENTITY, 0);
    if (m) return m;
  }
  return IDENTITY;
}

// formats/vdsh_camera.c: view (gluLookAt) and projection, column-major.
function viewProj(cam, aspect, zn, zf) {
  const f = norm(sub(cam.target, cam.eye));
  const up = cam.up && dot(cam.up, cam.up) > 0 ? cam.up : [0, 1, 0];
  const s = norm(cross(f, up)), u = cross(s, f);
  const v = [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
    -dot(s, cam.eye), -dot(u, cam.eye), dot(f, cam.eye), 1];
  const t = 1 / Math.tan(0.5 * (cam.fov || 60) * Math.PI / 180);
  const p = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (zf + zn) / (zn - zf), -1, 0, 0, 2 * zf * zn / (zn - zf), 0];
  return { m: new Float32Array(mul4(p, v)), s, u, f };
}

// ---- the page ------------------------------------------------------------

function load(url) {
  return new Promise((ok, fail) => {
    const x = new XMLHttpRequest();  // XHR: works for file:// with --allow-file-access-from-files
    x.open('GET', url);
    x.responseType = 'arraybuffer';
    x.onload = () => (x.status === 200 || x.status === 0) && x.response ? ok(x.response)
      : fail(new Error('cannot load ' + url + ' (HTTP ' + x.status + ')'));
    x.onerror = () => fail(new Error('cannot load ' + url));
    x.send();
  });
}

// The shader files (runtime/shaders/): from shaders=URL, else shaders/
// beside the page, else ../shaders/ (the repository's layout).
async function loadShaders(where) {
  const text = (url) => load(url).then((b) => new TextDecoder().decode(b));
  let last = null;
  for (const dir of where ? [where.replace(/\/?$/, '/')] : ['shaders/', '../shaders/']) {
    try {
      const [common, buffer] = await Promise.all([text(dir + 'vdsh_common.glsl'), text(dir + 'vdsh_buffer.glsl')]);
      return { common, buffer };
    } catch (e) {
      last = e;
    }
  }
  throw new Error('the shader files (runtime/shaders/vdsh_common.glsl, vdsh_buffer.glsl) are not beside the page ' +
    '(shaders/ or ../shaders/; or give shaders=URL): ' + last.message);
}

async function main() {
  const q = new URLSearchParams(location.search);
  const vec = (name, s) => {
    const v = s.split(',').map(Number);
    if (v.length !== 3 || !v.every(Number.isFinite)) throw new Error(name + '=' + s + ': expected x,y,z');
    return v;
  };
  // The other parameters, checked before the file is read: a typo is said
  // on the page, not drawn as the default.
  const oneOf = (name, allowed) => {
    const v = q.get(name);
    if (v !== null && !allowed.includes(v))
      throw new Error(name + '=' + v + ': give ' + allowed.map((a) => name + '=' + a).join(' or ') + ', or leave it out');
  };
  oneOf('output', ['shadow']);
  oneOf('path', ['buffer']);
  if (q.get('size') !== null && !/^[1-9][0-9]{0,4}x[1-9][0-9]{0,4}$/.test(q.get('size')))
    throw new Error('size=' + q.get('size') + ': expected WxH, whole numbers of CSS pixels (640x400)');
  if (q.get('lights') !== null && !/^[1-9][0-9]{0,3}$/.test(q.get('lights')))
    throw new Error('lights=' + q.get('lights') + ': expected a whole number >= 1');
  if (q.get('fov') !== null && !(Number(q.get('fov')) > 0 && Number(q.get('fov')) < 180))
    throw new Error('fov=' + q.get('fov') + ': expected degrees between 0 and 180');
  const url = q.get('glb') || 'scene.glb';
  const { json, bin } = parseGlb(await load(url));
  for (const e of json.extensionsRequired || [])
    if (!READ_EXTENSIONS.includes(e))
      throw new Error(url + ' needs the glTF extension ' + e + ', which this viewer does not read (it reads ' +
        READ_EXTENSIONS.join(', ') + ')');
  const mesh = (json.meshes || [])[0];
  const vx = mesh && mesh.extras && mesh.extras.vdsh;
  if ((!vx || !Array.isArray(vx.streams)) && json.extensions && json.extensions[VDSH_EXT])
    throw new Error(url + ' is a glTF scene of its own with VDSH attributes (vdsh-export --source): ' +
      'this page draws the plain export (one mesh); open it with three.html (vdsh_three.js)');
  if (!vx || !Array.isArray(vx.streams) || !vx.streams.length)
    throw new Error(url + ' holds no VDSH streams (meshes[0].extras.vdsh): not a file of vdsh-export, ' +
      'or a tool that rewrote it dropped its extras (gltfpack: keep them with -ke -kv)');
  const prim = mesh.primitives[0];
  if (prim.mode !== undefined && prim.mode !== 4) throw new Error('primitive mode ' + prim.mode + ': only triangles are drawn');
  const stream = vdshChooseStream(vx.streams, q.get('order'));
  const plan = vdshStreamPlan(stream, q.get('path'));
  const attrNames = [];
  const cp = stream.cpca;  // a cpca stream: cluster and weight attributes (and the model)
  const want = cp ? [cp.cluster_attribute, ...Array.from({ length: cp.weight_attributes }, (_, g) => cp.weight_prefix + g)]
    : Array.from({ length: plan.groups }, (_, g) => stream.attribute_prefix + g);
  for (const name of want) {
    if (prim.attributes[name] === undefined) throw new Error('attribute ' + name + ' is missing (a tool dropped it? gltfpack: -kv)');
    attrNames.push(name);
  }
  if (prim.attributes.POSITION === undefined || prim.attributes.NORMAL === undefined)
    throw new Error('POSITION or NORMAL is missing');
  const gltf = new Gltf(json, bin, q.get('meshopt') || 'meshopt_decoder.cjs');
  const used = [prim.attributes.POSITION, prim.attributes.NORMAL, ...attrNames.map((n) => prim.attributes[n])];
  if (prim.indices !== undefined) used.push(prim.indices);
  await gltf.prepare(used);
  const model = cp ? await gltf.viewBytes(cp.model_view) : null;

  // Positions and normals in world space (the node's transform applied).
  const M = meshMatrix(json);
  const pos = gltf.read(prim.attributes.POSITION), nrm = gltf.read(prim.attributes.NORMAL);
  const nv = pos.length / 3;
  if (nrm.length !== 3 * nv) throw new Error('NORMAL and POSITION counts differ');
  const cof = [  // cofactors of the 3x3 part: normals' matrix up to a scale
    M[5] * M[10] - M[6] * M[9], M[6] * M[8] - M[4] * M[10], M[4] * M[9] - M[5] * M[8],
    M[2] * M[9] - M[1] * M[10], M[0] * M[10] - M[2] * M[8], M[1] * M[8] - M[0] * M[9],
    M[1] * M[6] - M[2] * M[5], M[2] * M[4] - M[0] * M[6], M[0] * M[5] - M[1] * M[4]];
  const identity = M.every((x, i) => x === IDENTITY[i]);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < nv; i++) {
    const p = [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]];
    if (!identity) {
      for (let k = 0; k < 3; k++) pos[3 * i + k] = M[k] * p[0] + M[4 + k] * p[1] + M[8 + k] * p[2] + M[12 + k];
      const n = [nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]];
      const w = [0, 1, 2].map((k) => cof[3 * k] * n[0] + cof[3 * k + 1] * n[1] + cof[3 * k + 2] * n[2]);
      const l = Math.hypot(w[0], w[1], w[2]) || 1;
      for (let k = 0; k < 3; k++) nrm[3 * i + k] = w[k] / l;
    }
    for (let k = 0; k < 3; k++) {
      lo[k] = Math.min(lo[k], pos[3 * i + k]);
      hi[k] = Math.max(hi[k], pos[3 * i + k]);
    }
  }
  const indices = prim.indices !== undefined ? gltf.read(prim.indices, Uint32Array) : Uint32Array.from({ length: nv }, (_, i) => i);
  for (let i = 0; i < indices.length; i++)
    if (indices[i] >= nv) throw new Error('index ' + indices[i] + ' out of range (' + nv + ' vertices)');
  const centre = [0, 1, 2].map((k) => 0.5 * (lo[k] + hi[k]));
  const diag = Math.hypot(...[0, 1, 2].map((k) => hi[k] - lo[k])) || 1;

  // The view: URL, else vdsh-view's default (extras.vdsh.view), else from
  // outside.
  const dv = vx.view && Array.isArray(vx.view.eye) && Array.isArray(vx.view.lights) && vx.view.lights.length
    ? vx.view : vdshFallbackView(lo, hi, pos, nrm, indices);
  const cam = {
    eye: q.get('eye') ? vec('eye', q.get('eye')) : dv.eye.slice(),
    target: q.get('target') ? vec('target', q.get('target')) : dv.target.slice(),
    up: q.get('up') ? vec('up', q.get('up')) : (dv.up || [0, 1, 0]).slice(),
    fov: q.get('fov') ? Number(q.get('fov')) : dv.fov_y || 60,
  };
  // Lights as vdsh-view's (vv_default_lights, vv_scene_lights): colours
  // and fall-off; the albedo 0.8 folded into colours and ambient.
  const ALBEDO = 0.8;
  let lights, colors, atts;
  const r03 = 0.3 * diag;
  if (q.getAll('light').length) {
    lights = q.getAll('light').map((s) => vec('light', s));
    colors = lights.map(() => [1.6, 1.6, 1.6]);
    atts = lights.map(() => [1, 0, 1 / (r03 * r03)]);
  } else {
    const COLORS = [[1.0, 0.92, 0.8], [0.55, 0.7, 1.0], [1.0, 0.62, 0.4], [0.7, 1.0, 0.7]];
    const n = Math.max(1, Math.min(dv.lights.length, Number(q.get('lights') || 1)));
    lights = dv.lights.slice(0, n).map((l) => l.slice());
    const intensity = Math.fround(1.6 / (1 + 0.6 * (n - 1)));
    colors = lights.map((_, i) => COLORS[i % 4].map((c) => intensity * c));
    atts = lights.map((l) => {
      let r = r03;
      if (!dv.interior) r = Math.hypot(...sub(l, centre)) || 1;
      return [1, 0, 1 / (r * r)];
    });
  }
  const output = q.get('output') === 'shadow' ? 1 : 0;
  const buffer = plan.buffer;
  window.vdshView = { eye: cam.eye, target: cam.target, lights, order: stream.order,
    adaptive: !!stream.variable_order, path: buffer ? 'buffer' : 'attributes',
    cpca: cp ? (q.get('cpca') === 'load' ? 'load' : 'vertex') : null, defaultView: dv.fallback ? 'fallback' : 'file' };

  const canvas = document.getElementById('c');
  if (q.get('size')) {  // a fixed size WxH (CSS pixels) instead of the window's
    const [w, h] = q.get('size').split('x').map(Number);
    canvas.style.width = w + 'px';
    canvas.style.height = h + 'px';
  }
  const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });
  if (!gl) throw new Error('this browser gives no WebGL2 context');
  const coef = attrNames.map((n) => gltf.read(prim.attributes[n]));
  let bd = null, cd = null;
  const maxTexture = gl.getParameter(gl.MAX_TEXTURE_SIZE);
  const cpcaLoad = q.get('cpca') === 'load';
  if (q.get('cpca') !== null && !cpcaLoad && q.get('cpca') !== 'vertex')
    throw new Error('cpca=' + q.get('cpca') + ': give cpca=vertex or cpca=load');
  if (cp && !cpcaLoad)  // kept compressed, decoded in the vertex stage (vdsh_core.js)
    cd = vdshCpcaBufferData(stream, nv, coef[0], coef.slice(1), model, maxTexture);
  else if (cp) {  // decoded at load (vdsh_core.js), then the buffer path
    const dec = vdshCpcaDecode(stream, nv, coef[0], coef.slice(1), model), nc = stream.order * stream.order;
    bd = vdshBufferData((v, i) => dec[v * nc + i], nv, stream, maxTexture);
  } else if (buffer)  // each vertex's coefficients in a float texture (vdsh_core.js)
    bd = vdshBufferData((v, i) => coef[i >> 2][4 * v + (i & 3)], nv, stream, maxTexture);
  const src = glsl({ plan, lights: lights.length, output, texWidth: bd ? bd.width : cd ? cd.width : 0, cpca: cd },
    await loadShaders(q.get('shaders')));
  const sh = (type, s) => {
    const o = gl.createShader(type);
    gl.shaderSource(o, s);
    gl.compileShader(o);
    if (!gl.getShaderParameter(o, gl.COMPILE_STATUS))
      throw new Error('the ' + (type === gl.VERTEX_SHADER ? 'vertex' : 'fragment') + ' shader does not compile: ' + gl.getShaderInfoLog(o));
    return o;
  };
  const prog = gl.createProgram();
  gl.attachShader(prog, sh(gl.VERTEX_SHADER, src.vs));
  gl.attachShader(prog, sh(gl.FRAGMENT_SHADER, src.fs));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error('the shaders do not link: ' + gl.getProgramInfoLog(prog));
  gl.useProgram(prog);
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const attrib = (name, data, size) => {
    const loc = gl.getAttribLocation(prog, name);
    if (loc < 0) return;
    gl.bindBuffer(gl.ARRAY_BUFFER, gl.createBuffer());
    gl.bufferData(gl.ARRAY_BUFFER, data, gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc);
    if (data instanceof Uint32Array) gl.vertexAttribIPointer(loc, size, gl.UNSIGNED_INT, 0, 0);
    else gl.vertexAttribPointer(loc, size, gl.FLOAT, false, 0, 0);
  };
  attrib('a_position', pos, 3);
  attrib('a_normal', nrm, 3);
  const U = (n) => gl.getUniformLocation(prog, n);
  const texture = (unit, format, w, h, fmt, type, data) => {
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, gl.createTexture());
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    gl.texImage2D(gl.TEXTURE_2D, 0, format, w, h, 0, fmt, type, data);
  };
  if (cd) {
    texture(0, gl.R32UI, cd.width, cd.height, gl.RED_INTEGER, gl.UNSIGNED_INT, cd.words);
    texture(1, gl.RGBA32F, cd.width, cd.modelHeight, gl.RGBA, gl.FLOAT, cd.model);
    gl.uniform1i(U('u_coef'), 0);
    gl.uniform1i(U('u_model'), 1);
  } else if (buffer) {
    attrib('a_record', bd.records, 1);
    attrib('a_order', bd.orders, 1);
    texture(0, gl.RGBA32F, bd.width, bd.height, gl.RGBA, gl.FLOAT, bd.texels);
    gl.uniform1i(U('u_coef'), 0);
  } else {
    for (let g = 0; g < plan.groups; g++) attrib('vdshC' + g, coef[g], 4);
  }
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, gl.createBuffer());
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, indices, gl.STATIC_DRAW);
  gl.uniform1f(U('vdshScale'), stream.scale);
  gl.uniform1f(U('vdshMaxDistance'), vx.max_distance);
  gl.uniform3fv(U('u_light_color'), new Float32Array(colors.flat().map((c) => ALBEDO * c)));
  gl.uniform3fv(U('u_light_att'), new Float32Array(atts.flat()));
  gl.uniform3f(U('u_ambient'), ALBEDO * 0.03, ALBEDO * 0.03, ALBEDO * 0.03);
  gl.enable(gl.DEPTH_TEST);
  const err = gl.getError();
  if (err) throw new Error('WebGL error 0x' + err.toString(16) + ' while uploading the scene');

  function draw() {
    const W = canvas.width = canvas.clientWidth, H = canvas.height = canvas.clientHeight;
    gl.viewport(0, 0, W, H);
    if (output) gl.clearColor(1, 1, 1, 1); else gl.clearColor(0, 0, 0, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const far = 4 * diag + Math.hypot(...sub(cam.eye, centre));
    gl.uniformMatrix4fv(U('u_view_proj'), false, viewProj(cam, W / H, far / 4000, far).m);
    gl.uniform3fv(U('u_light_pos'), new Float32Array(lights.flat()));
    gl.drawElements(gl.TRIANGLES, indices.length, gl.UNSIGNED_INT, 0);
  }
  draw();
  // Orbit (drag), zoom (wheel), move light 0 (shift+drag).
  let last = null;
  canvas.addEventListener('pointerdown', (e) => { last = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointerup', () => { last = null; });
  canvas.addEventListener('pointermove', (e) => {
    if (!last) return;
    const dx = e.clientX - last[0], dy = e.clientY - last[1];
    last = [e.clientX, e.clientY];
    const b = viewProj(cam, 1, 1, 2);
    if (e.shiftKey) {
      const k = 0.002 * diag;
      for (let i = 0; i < 3; i++) lights[0][i] += k * (dx * b.s[i] - dy * b.u[i]);
    } else {
      const o = sub(cam.eye, cam.target), r = Math.hypot(...o);
      let yaw = Math.atan2(o[0], o[2]) - 0.01 * dx, pitch = Math.asin(o[1] / r) + 0.01 * dy;
      pitch = Math.max(-1.5, Math.min(1.5, pitch));
      cam.eye = [cam.target[0] + r * Math.cos(pitch) * Math.sin(yaw), cam.target[1] + r * Math.sin(pitch),
        cam.target[2] + r * Math.cos(pitch) * Math.cos(yaw)];
    }
    draw();
  });
  canvas.addEventListener('wheel', (e) => {
    const k = Math.exp(0.001 * e.deltaY);
    cam.eye = cam.eye.map((x, i) => cam.target[i] + (x - cam.target[i]) * k);
    draw();
  });
  gl.finish();
  window.vdshReady = true;
  document.title = 'ready ' + canvas.width + 'x' + canvas.height + (cp ? ' cpca ' + window.vdshView.cpca : '');
}

function showError(e) {
  const msg = e && e.message ? e.message : String(e);
  window.vdshError = msg;
  document.title = 'error: ' + msg;
  const el = document.getElementById('msg');
  if (el) {
    el.textContent = 'VDSH viewer: ' + msg;
    el.hidden = false;
  }
  console.error(e);
}

main().catch(showError);
