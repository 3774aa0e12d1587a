// vdsh_web.js - a raw WebGL2 viewer of a glb written by vdsh-export
// (formats/GLTF.md): the receiver mesh lit by point lights with VDSH
// shadows, by the C runtime's shadow rule (runtime/vr_glsl.c):
//   log-distance streams (any order): per vertex the whole SH sum toward
//     each light, d = min(exp(min(sum, 80)), max_distance), interpolated;
//     per fragment visibility = compare(d, |light - fragment|);
//   linear streams (distance, distance^2): per vertex the distance and the
//     comparison, the visibility interpolated (the C runtime's path for
//     orders 2 and 3; its order-5 split path is not reproduced here).
// compare: smooth clamp(1.5 d / dl - 0.5, 0, 1) (formats/vdsh_shadow.h).
// The camera is formats/vdsh_camera.h's (gluLookAt basis, vertical fov).
//
// URL parameters (all optional except glb): glb=FILE, order=N, eye=x,y,z,
// target=x,y,z, up=x,y,z, fov=DEG, light=x,y,z (repeatable, as
// light=..&light=..), size=WxH (canvas size; default the window),
// output=shadow (shadow factor of light 0 as grey,
// white where no surface: vdsh-view's --views frames) or shaded (default).
// Mouse: drag orbits the camera around the target, wheel zooms,
// shift+drag moves light 0 in the view plane. window.vdshReady is set to
// true (and document.title to "ready") once the first frame is drawn, or
// document.title to "error: ..." on failure.
'use strict';

const SH = {
  C00: 0.28209479177387814, C1: 0.4886025119029199, C2A: 1.0925484305920792,
  C20: 0.31539156525252005, C22: 0.5462742152960396, C33: 0.5900435899266435,
  C32: 2.890611442640554, C31: 0.4570457994644658, C30: 0.3731763325901154,
  C32B: 1.445305721320277, C44: 2.5033429417967046, C43: 1.7701307697799304,
  C42: 0.9461746957575601, C41: 0.6690465435572892, C40: 0.10578554691520431,
  C42B: 0.47308734787878004, C44B: 0.6258357354491761,
};

function glsl(order, quantity, lights, output) {
  const consts = Object.entries(SH).map(([k, v]) => `const float ${k} = ${v.toPrecision(17)};`).join('\n');
  const groups = Math.ceil(order * order / 4);
  const head = `#version 300 es
precision highp float;
#define ORDER ${order}
#define QUANTITY ${quantity}
#define NUM_LIGHTS ${lights}
#define OUTPUT ${output}
#define LOG_PATH ${quantity === 2 ? 1 : 0}
${consts}
float vdsh_distance(float sum, float md) {
#if QUANTITY == 1
  float d = sum > 0.0 ? sqrt(sum) : 0.0;
#elif QUANTITY == 2
  float d = exp(min(sum, 80.0));
#else
  float d = sum > 0.0 ? sum : 0.0;
#endif
  return d > md ? md : d;
}
float vdsh_compare(float dv, float dl) {
  if (!(dl > 0.0)) return 1.0;
  if (isinf(dv) && dv > 0.0) return 1.0;
  return clamp(1.5 * (dv / dl) - 0.5, 0.0, 1.0);
}
`;
  let attrs = '';
  for (let g = 0; g < groups; g++) attrs += `in vec4 a_c${g};\n`;
  let coef = 'float c[28];\n';
  for (let g = 0; g < groups; g++)
    for (let k = 0; k < 4; k++) coef += `  c[${4 * g + k}] = a_c${g}[${k}];\n`;
  const vs = head + `
in vec3 a_position;
in vec3 a_normal;
${attrs}
uniform mat4 u_view_proj;
uniform float u_scale;
uniform float u_max_distance;
uniform vec3 u_light_pos[NUM_LIGHTS];
out vec3 v_position;
out vec3 v_normal;
out float v_val[NUM_LIGHTS];
float sh_sum(float c[28], vec3 d) {
  float x = d.x, y = d.y, z = d.z, x2 = x * x, y2 = y * y, z2 = z * z;
  float s = c[0] * C00 - c[1] * C1 * y + c[2] * C1 * z - c[3] * C1 * x;
#if ORDER >= 3
  s += c[4] * C2A * x * y - c[5] * C2A * y * z + c[6] * C20 * (3.0 * z2 - 1.0) - c[7] * C2A * x * z + c[8] * C22 * (x2 - y2);
#endif
#if ORDER >= 4
  s += -c[9] * C33 * y * (3.0 * x2 - y2) + c[10] * C32 * x * y * z - c[11] * C31 * y * (5.0 * z2 - 1.0)
       + c[12] * C30 * z * (5.0 * z2 - 3.0) - c[13] * C31 * x * (5.0 * z2 - 1.0) + c[14] * C32B * z * (x2 - y2)
       - c[15] * C33 * x * (x2 - 3.0 * y2);
#endif
#if ORDER >= 5
  s += c[16] * C44 * x * y * (x2 - y2) - c[17] * C43 * y * z * (3.0 * x2 - y2) + c[18] * C42 * x * y * (7.0 * z2 - 1.0)
       - c[19] * C41 * y * z * (7.0 * z2 - 3.0) + c[20] * C40 * (35.0 * z2 * z2 - 30.0 * z2 + 3.0)
       - c[21] * C41 * x * z * (7.0 * z2 - 3.0) + c[22] * C42B * (x2 - y2) * (7.0 * z2 - 1.0)
       - c[23] * C43 * x * z * (x2 - 3.0 * y2) + c[24] * C44B * (x2 * x2 - 6.0 * x2 * y2 + y2 * y2);
#endif
  return s;
}
void main() {
  ${coef}
  v_position = a_position;
  v_normal = a_normal;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
  for (int i = 0; i < NUM_LIGHTS; i++) {
    vec3 lv = u_light_pos[i] - a_position;
    float dl = length(lv);
    float dv = dl > 0.0 ? vdsh_distance(u_scale * sh_sum(c, lv / dl), u_max_distance) : 0.0;
#if LOG_PATH
    v_val[i] = dv;
#else
    v_val[i] = vdsh_compare(dv, dl);
#endif
  }
}`;
  const fs = head + `
in vec3 v_position;
in vec3 v_normal;
in float v_val[NUM_LIGHTS];
uniform vec3 u_light_pos[NUM_LIGHTS];
uniform vec3 u_light_att;
uniform float u_ambient;
out vec4 o_color;
void main() {
  vec3 n = normalize(v_normal);
  vec3 acc = vec3(u_ambient);
  float s0 = 1.0;
  for (int i = 0; i < NUM_LIGHTS; i++) {
    vec3 lv = u_light_pos[i] - v_position;
    float dl = length(lv);
#if LOG_PATH
    float s = vdsh_compare(v_val[i], dl);
#else
    float s = v_val[i];
#endif
    if (i == 0) s0 = s;
    float ndl = dl > 0.0 ? max(dot(n, lv) / dl, 0.0) : 1.0;
    float att = 1.0 / dot(u_light_att, vec3(1.0, dl, dl * dl));
    acc += vec3(s * ndl * att * 0.8);
  }
#if OUTPUT == 1
  o_color = vec4(s0, s0, s0, 1.0);
#else
  o_color = vec4(pow(acc, vec3(1.0 / 2.2)), 1.0);
#endif
}`;
  return { vs, fs, groups };
}

function parseGlb(buf) {
  const dv = new DataView(buf);
  if (dv.getUint32(0, true) !== 0x46546C67) throw new Error('not a glb');
  const jl = dv.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(new Uint8Array(buf, 20, jl)));
  const bl = dv.getUint32(20 + jl, true);
  return { json, bin: new Uint8Array(buf, 28 + jl, bl) };
}

const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const norm = (a) => { const l = Math.hypot(a[0], a[1], a[2]); return [a[0] / l, a[1] / l, a[2] / l]; };

// formats/vdsh_camera.c: view (gluLookAt) and projection, column-major.
function viewProj(cam, aspect, zn, zf) {
  const f = norm(sub(cam.target, cam.eye));
  const up = cam.up && dot(cam.up, cam.up) > 0 ? cam.up : [0, 1, 0];
  const s = norm(cross(f, up)), u = cross(s, f);
  const v = [s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
    -dot(s, cam.eye), -dot(u, cam.eye), dot(f, cam.eye), 1];
  const t = 1 / Math.tan(0.5 * (cam.fov || 60) * Math.PI / 180);
  const p = [t / aspect, 0, 0, 0, 0, t, 0, 0, 0, 0, (zf + zn) / (zn - zf), -1, 0, 0, 2 * zf * zn / (zn - zf), 0];
  const m = new Float32Array(16);
  for (let c = 0; c < 4; c++)
    for (let r = 0; r < 4; r++) {
      let x = 0;
      for (let k = 0; k < 4; k++) x += p[k * 4 + r] * v[c * 4 + k];
      m[c * 4 + r] = x;
    }
  return { m, s, u, f };
}

async function main() {
  const q = new URLSearchParams(location.search);
  const vec = (s) => s.split(',').map(Number);
  const buf = await new Promise((ok, fail) => {
    const x = new XMLHttpRequest();  // XHR: works for file:// with --allow-file-access-from-files
    x.open('GET', q.get('glb') || 'scene.glb');
    x.responseType = 'arraybuffer';
    x.onload = () => (x.status === 200 || x.status === 0) && x.response ? ok(x.response) : fail(new Error('load ' + x.status));
    x.onerror = () => fail(new Error('cannot load ' + q.get('glb')));
    x.send();
  });
  const { json, bin } = parseGlb(buf);
  const prim = json.meshes[0].primitives[0];
  const vx = json.meshes[0].extras.vdsh;
  const want = q.get('order') ? Number(q.get('order')) : Math.max(...vx.streams.map((s) => s.order));
  const stream = vx.streams.find((s) => s.order === want);
  if (!stream) throw new Error('no stream of order ' + want);
  const quantity = { 'distance': 0, 'distance2': 1, 'log-distance': 2 }[stream.quantity];
  const pmin = json.accessors[prim.attributes.POSITION].min, pmax = json.accessors[prim.attributes.POSITION].max;
  const centre = [0, 1, 2].map((k) => 0.5 * (pmin[k] + pmax[k]));
  const diag = Math.hypot(...[0, 1, 2].map((k) => pmax[k] - pmin[k]));
  const cam = {
    eye: q.get('eye') ? vec(q.get('eye')) : [centre[0], centre[1], centre[2] + 0.4 * diag],
    target: q.get('target') ? vec(q.get('target')) : centre,
    up: q.get('up') ? vec(q.get('up')) : [0, 1, 0],
    fov: q.get('fov') ? Number(q.get('fov')) : 60,
  };
  const lights = q.getAll('light').length ? q.getAll('light').map(vec) : [[centre[0], pmax[1] - 0.1 * (pmax[1] - pmin[1]), centre[2]]];
  const output = q.get('output') === 'shadow' ? 1 : 0;

  const canvas = document.getElementById('c');
  if (q.get('size')) {  // a fixed size WxH (CSS pixels) instead of the window's
    const [w, h] = q.get('size').split('x').map(Number);
    canvas.style.width = w + 'px';
    canvas.style.height = h + 'px';
  }
  const gl = canvas.getContext('webgl2', { antialias: false, preserveDrawingBuffer: true });
  if (!gl) throw new Error('no WebGL2');
  const src = glsl(want, quantity, lights.length, output);
  const sh = (type, s) => {
    const o = gl.createShader(type);
    gl.shaderSource(o, s);
    gl.compileShader(o);
    if (!gl.getShaderParameter(o, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(o));
    return o;
  };
  const prog = gl.createProgram();
  gl.attachShader(prog, sh(gl.VERTEX_SHADER, src.vs));
  gl.attachShader(prog, sh(gl.FRAGMENT_SHADER, src.fs));
  gl.linkProgram(prog);
  if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
  gl.useProgram(prog);
  const vao = gl.createVertexArray();
  gl.bindVertexArray(vao);
  const attrib = (name, ai) => {
    const loc = gl.getAttribLocation(prog, name);
    if (loc < 0) return;
    const a = json.accessors[ai], v = json.bufferViews[a.bufferView];
    const b = gl.createBuffer();
    gl.bindBuffer(gl.ARRAY_BUFFER, b);
    gl.bufferData(gl.ARRAY_BUFFER, bin.subarray(v.byteOffset, v.byteOffset + v.byteLength), gl.STATIC_DRAW);
    gl.enableVertexAttribArray(loc);
    gl.vertexAttribPointer(loc, { VEC3: 3, VEC4: 4 }[a.type], a.componentType, !!a.normalized, 0, a.byteOffset || 0);
  };
  attrib('a_position', prim.attributes.POSITION);
  attrib('a_normal', prim.attributes.NORMAL);
  for (let g = 0; g < src.groups; g++) attrib('a_c' + g, prim.attributes[stream.attribute_prefix + g]);
  const ia = json.accessors[prim.indices], iv = json.bufferViews[ia.bufferView];
  const ib = gl.createBuffer();
  gl.bindBuffer(gl.ELEMENT_ARRAY_BUFFER, ib);
  gl.bufferData(gl.ELEMENT_ARRAY_BUFFER, bin.subarray(iv.byteOffset, iv.byteOffset + iv.byteLength), gl.STATIC_DRAW);
  const U = (n) => gl.getUniformLocation(prog, n);
  gl.uniform1f(U('u_scale'), stream.scale);
  gl.uniform1f(U('u_max_distance'), vx.max_distance);
  gl.uniform3f(U('u_light_att'), 1, 0, 1 / Math.pow(0.3 * diag, 2));
  gl.uniform1f(U('u_ambient'), 0.03);
  gl.enable(gl.DEPTH_TEST);

  function draw() {
    const W = canvas.width = canvas.clientWidth, H = canvas.height = canvas.clientHeight;
    gl.viewport(0, 0, W, H);
    if (output) gl.clearColor(1, 1, 1, 1); else gl.clearColor(0.1, 0.1, 0.12, 1);
    gl.clear(gl.COLOR_BUFFER_BIT | gl.DEPTH_BUFFER_BIT);
    const far = 4 * diag;
    gl.uniformMatrix4fv(U('u_view_proj'), false, viewProj(cam, W / H, far / 4000, far).m);
    gl.uniform3fv(U('u_light_pos'), new Float32Array(lights.flat()));
    gl.drawElements(gl.TRIANGLES, ia.count, ia.componentType, 0);
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
  document.title = 'ready ' + canvas.width + 'x' + canvas.height;
}

main().catch((e) => { document.title = 'error: ' + e.message; console.error(e); });
