// vdsh_three.js - VDSH shadows in three.js: an ES module, no build step.
//
// A mesh that three.js's GLTFLoader read from a glb of vdsh-export
// (formats/GLTF.md: the _VDSH<o>_<k> attributes, the streams in the mesh's
// extras) gets a MeshStandardMaterial whose point lights -- any number,
// the three.js scene's own PointLights -- are shadowed by the VDSH
// visibility, by the C runtime's rule (runtime/shaders/README.md):
//   log-distance streams, and every stream on the buffer path: per vertex
//     the SH sum toward each light, d = vdsh_distance(sum, max_distance),
//     interpolated; per fragment vdsh_compare(d, |light - fragment|);
//   linear streams (distance, distance^2) of orders 2, 3, 5: per vertex
//     vdsh_shadow(sum, max_distance, |light - vertex|), interpolated.
// Orders 2, 3, 5 read their coefficients as vertex attributes (the glb's,
// any component type, normalised or not: three.js binds them as they
// are); every other order (1, 4, 6-16) and the adaptive order (an order
// per vertex) take the buffer path: each vertex's coefficients in a float
// texture, read in the vertex stage and summed by the recurrence of
// vdsh_buffer.glsl (WebGL2 has 16 vertex attributes, order 5 at most).
//
// The GLSL is runtime/shaders/vdsh_common.glsl and vdsh_buffer.glsl, the
// files the C runtime compiles in, fetched at run time from ../shaders/
// next to this file (loadVdshShaders(url) for another place).
//
//   import * as THREE from 'three';
//   import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
//   import { loadVdshShaders, vdshInfo, vdshMaterial } from './vdsh_three.js';
//   const shaders = await loadVdshShaders();
//   const gltf = await new GLTFLoader().loadAsync('room.glb');
//   gltf.scene.traverse((o) => { if (o.isMesh && vdshInfo(o)) vdshMaterial(o, shaders); });
//   scene.add(gltf.scene, new THREE.PointLight(0xffffff, 20));
//
// vdshMaterial(mesh, shaders, options) sets and returns mesh.material;
// options (all optional):
//   order      2..16 or 'adaptive' (default as vdsh-view: 5, else 3, else
//              2, else the adaptive stream, else the highest order)
//   path       'buffer' for the buffer path at orders 2, 3, 5 too
//   material   the MeshStandardMaterial (or MeshPhysicalMaterial) to
//              extend (default a new grey one); it is changed in place
//   frame      the Object3D whose frame is the bake's (default: the
//              world): give gltf.scene to move or scale the loaded scene
//              with its shadows
//   output     'shadow': the visibility of the first point light as grey
//              (vdsh-view --views' frames; tests/test_web_three.py)
// The stream must have been baked for this mesh in this frame: lights are
// taken into the bake's frame, where the coefficients' directions live.
// Only three.js PointLights are shadowed (as vdsh-view's lights); other
// lights light the mesh unshadowed.
import * as THREE from 'three';

const MAX_ORDER = 16;

// The shader files, fetched once per URL.
export async function loadVdshShaders(url = new URL('../shaders/', import.meta.url)) {
  const get = async (name) => {
    const u = new URL(name, url);
    const r = await fetch(u);
    if (!r.ok) throw new Error('cannot load ' + u + ' (HTTP ' + r.status + ')');
    return r.text();
  };
  const [common, buffer] = await Promise.all([get('vdsh_common.glsl'), get('vdsh_buffer.glsl')]);
  return { common, buffer };
}

// The VDSH description of a mesh (formats/GLTF.md: its extras.vdsh, which
// GLTFLoader puts into userData; or a vendor extension holding streams),
// looked for on the mesh and its parents; null when there is none.
export function vdshInfo(mesh) {
  for (let o = mesh; o; o = o.parent) {
    const u = o.userData || {};
    if (u.vdsh && Array.isArray(u.vdsh.streams)) return u.vdsh;
    for (const x of Object.values(u.gltfExtensions || {}))
      if (x && Array.isArray(x.streams)) return x;
  }
  return null;
}

// The stream to draw: order N, 'adaptive', or vdsh-view's default.
export function vdshChooseStream(streams, want) {
  const fixed = (o) => streams.find((s) => s.order === o && !s.variable_order);
  const variable = streams.find((s) => s.variable_order);
  if (want === 'adaptive') {
    if (!variable) throw new Error('no stream with an order per vertex (adaptive order) in this file');
    return variable;
  }
  if (want !== undefined && want !== null && want !== '') {
    const o = Number(want);
    const s = fixed(o) || streams.find((x) => x.order === o);
    if (!s) throw new Error('no stream of order ' + want + ' (the file has ' +
      streams.map((x) => x.order + (x.variable_order ? ' adaptive' : '')).join(', ') + ')');
    return s;
  }
  return fixed(5) || fixed(3) || fixed(2) || variable || streams.reduce((a, b) => (b.order > a.order ? b : a));
}

// K_l^|m| per coefficient index l(l+1)+m (sqrt 2 folded in for m != 0),
// in double then rounded to f32, as runtime/vr_buffer.c (make_ks).
function ksTable(order) {
  const ks = new Float32Array(order * order);
  for (let l = 0; l < order; l++)
    for (let m = 0; m <= l; m++) {
      let kk = (2 * l + 1) / (4 * Math.PI);
      for (let f = l - m + 1; f <= l + m; f++) kk /= f;
      const K = m === 0 ? Math.sqrt(kk) : Math.sqrt(2 * kk);
      ks[l * (l + 1) + m] = K;
      ks[l * (l + 1) - m] = K;
    }
  return ks;
}

// A float as a GLSL literal that reads back as the same f32.
const flit = (x) => {
  const s = Math.fround(x).toPrecision(9);
  return /[.e]/.test(s) ? s : s + '.0';
};

// The order the recurrence consumes coefficients in (vr_buffer_sequence).
function bufferSequence(order) {
  const out = [];
  for (let m = 0; m < order; m++)
    for (let l = m; l < order; l++) {
      out.push(l * (l + 1) + m);
      if (m > 0) out.push(l * (l + 1) - m);
    }
  return out;
}

// The buffer path's texture: each vertex's record (its coefficients up to
// its own order, in the recurrence's order), four to a texel, row by row;
// a_record (first texel) and a_order per vertex. Coefficients are read
// through BufferAttribute.getX.. (normalised or not, interleaved or not).
function bufferTexture(geometry, names, stream, maxTexture) {
  const N = stream.order, nc = N * N;
  const attrs = names.map((n) => geometry.getAttribute(n));
  const nv = attrs[0].count;
  const comp = ['getX', 'getY', 'getZ', 'getW'];
  const get = (v, i) => attrs[i >> 2][comp[i & 3]](v);
  const orders = new Uint32Array(nv), records = new Uint32Array(nv);
  let total = 0;
  for (let v = 0; v < nv; v++) {
    let k = N;
    if (stream.variable_order)  // the vertex's order: its last nonzero band
      for (k = 0; k < N; k++) {
        let zero = true;
        for (let i = k * k; i < nc && zero; i++) zero = get(v, i) === 0;
        if (zero) break;
      }
    orders[v] = k;
    records[v] = total;
    total += Math.ceil(k * k / 4);
  }
  const W = Math.min(maxTexture, 4096), H = Math.max(1, Math.ceil(total / W));
  if (H > maxTexture) throw new Error('the coefficients need ' + total + ' texels, over this GPU\'s textures');
  const texels = new Float32Array(W * H * 4), seqs = [];
  for (let v = 0; v < nv; v++) {
    const k = orders[v], seq = seqs[k] || (seqs[k] = bufferSequence(k));
    for (let p = 0, at = 4 * records[v]; p < seq.length; p++) texels[at + p] = get(v, seq[p]);
  }
  const tex = new THREE.DataTexture(texels, W, H, THREE.RGBAFormat, THREE.FloatType);
  tex.minFilter = tex.magFilter = THREE.NearestFilter;
  tex.generateMipmaps = false;
  tex.needsUpdate = true;
  geometry.setAttribute('a_record', new THREE.BufferAttribute(records, 1));
  geometry.setAttribute('a_order', new THREE.BufferAttribute(orders, 1));
  return { tex, width: W };
}

// Replaces `anchor` in `text` by `by`, or says which three.js shader
// chunk changed (this module is tested with the three.js of
// scripts/npm_gltf_tools).
function patch(text, anchor, by, what) {
  if (!text.includes(anchor)) throw new Error('vdsh_three.js: three.js ' + THREE.REVISION + "'s " + what +
    ' has no "' + anchor + '": a three.js this module does not know');
  return text.replace(anchor, by);
}

export function vdshMaterial(mesh, shaders, options = {}) {
  if (!shaders || typeof shaders.common !== 'string') throw new Error('vdshMaterial: give the shaders of loadVdshShaders()');
  const info = vdshInfo(mesh);
  if (!info || !info.streams.length) throw new Error('vdshMaterial: the mesh ' + (mesh.name || '') +
    ' holds no VDSH streams (extras.vdsh of a glb written by vdsh-export)');
  const stream = vdshChooseStream(info.streams, options.order);
  if (!(stream.order >= 1 && stream.order <= MAX_ORDER)) throw new Error('stream order ' + stream.order + ' out of range 1..16');
  const quantity = { 'distance': 0, 'distance2': 1, 'log-distance': 2 }[stream.quantity];
  if (quantity === undefined) throw new Error('stream quantity ' + stream.quantity + ' unknown');
  const geometry = mesh.geometry;
  const groups = Math.ceil(stream.order * stream.order / 4);
  const names = [];
  for (let g = 0; g < groups; g++) {  // GLTFLoader lower-cases custom attribute names
    const n = (stream.attribute_prefix + g).toLowerCase();
    if (!geometry.getAttribute(n)) throw new Error('attribute ' + stream.attribute_prefix + g + ' is missing');
    names.push(n);
  }
  const buffer = options.path === 'buffer' || !!stream.variable_order || ![2, 3, 5].includes(stream.order);
  const distPath = buffer || quantity === 2;
  const output = options.output === 'shadow' ? 1 : 0;
  const frame = options.frame || null;

  let defines = `#define QUANTITY ${quantity}\n#define COMPARE 0\n#define VDSH_DIST_PATH ${distPath ? 1 : 0}\n` +
    `#define VDSH_OUTPUT ${output}\n`;
  const uniforms = {
    vdshScale: { value: stream.scale },
    vdshMaxDistance: { value: info.max_distance },
    vdshBakeFromWorld: { value: new THREE.Matrix4() },
    vdshBakeFromView: { value: new THREE.Matrix4() },
  };
  let vsDecl = '', vsSums = '';
  if (buffer) {
    const maxTex = options.maxTextureSize || 4096;
    const b = bufferTexture(geometry, names, stream, maxTex);
    const ks = ksTable(stream.order);
    uniforms.u_coef = { value: b.tex };
    defines += `#define BUFFER 1\n#define BUF_TEXTURE_2D 1\n#define BUF_TEX_WIDTH ${b.width}\n#define BUF_KIND 0\n` +
      `#define BUF_VARIABLE 1\n#define BUF_ORDER ${stream.order}\n#define BUF_STRIDE 0\n` +
      `#define BUF_RECEIVER vdshP\n#define BUF_LIGHT(i) vdshL[i]\n#define BUF_SCALE vdshScale\n`;
    vsDecl = `vec3 vdshP;\nvec3 vdshL[NUM_LIGHTS];\n` +
      `const float KS[${ks.length}] = float[${ks.length}](${Array.from(ks, flit).join(', ')});\n` + shaders.buffer;
    vsSums = '  float vdshSum[NUM_LIGHTS];\n  buffer_sums(vdshSum);\n';
  } else {
    // Aliases of the glb's attributes (the same BufferAttribute objects:
    // uploaded once), so the GLSL names do not depend on the prefix.
    for (let g = 0; g < groups; g++) {
      geometry.setAttribute('vdshC' + g, geometry.getAttribute(names[g]));
      vsDecl += `in vec4 vdshC${g};\n`;
    }
    defines += `#define BUFFER 0\n#define VDSH_ORDER ${stream.order}\n`;
    vsDecl += `float vdshSum(vec3 d) {
#if VDSH_ORDER == 2
  return vdshScale * sh_sum4(vdshC0, d);
#elif VDSH_ORDER == 3
  return vdshScale * sh_sum9(vdshC0, vdshC1, vdshC2.x, d);
#else
  vec4 g[7] = vec4[7](vdshC0, vdshC1, vdshC2, vdshC3, vdshC4, vdshC5, vdshC6);
  return vdshScale * vdsh_sh_sum25(g, d);
#endif
}
`;
  }

  // three.js declares its point lights only in the fragment stage; the
  // vertex stage declares the same uniform (same struct, same name) to
  // read their positions too (view space, taken to the bake's frame).
  const pars = THREE.ShaderChunk.lights_pars_begin;
  const struct = pars.match(/struct PointLight \{[^}]*\};/);
  const decl = pars.match(/uniform PointLight pointLights\[ NUM_POINT_LIGHTS \];/);
  if (!struct || !decl) throw new Error('vdsh_three.js: three.js ' + THREE.REVISION + ' declares its point lights otherwise');

  const material = options.material || new THREE.MeshStandardMaterial({ color: 0xcccccc, roughness: 1, metalness: 0 });
  const vsHead = `#define NUM_LIGHTS NUM_POINT_LIGHTS\n${defines}${shaders.common}\n` +
    `uniform float vdshScale;\nuniform float vdshMaxDistance;\nuniform mat4 vdshBakeFromView;\nuniform mat4 vdshBakeFromWorld;\n` +
    `out vec3 vdshPos;\n#if NUM_POINT_LIGHTS > 0\n${struct[0]}\n${decl[0]}\nout float vdshVal[NUM_POINT_LIGHTS];\n` +
    `${vsDecl}#endif\n`;
  const vsMain = `
  vdshPos = (vdshBakeFromWorld * modelMatrix * vec4(position, 1.0)).xyz;
#if NUM_POINT_LIGHTS > 0
#if BUFFER
  vdshP = vdshPos;
  for (int i = 0; i < NUM_POINT_LIGHTS; i++)
    vdshL[i] = (vdshBakeFromView * vec4(pointLights[i].position, 1.0)).xyz;
${vsSums}#endif
  for (int i = 0; i < NUM_POINT_LIGHTS; i++) {
    vec3 lv = (vdshBakeFromView * vec4(pointLights[i].position, 1.0)).xyz - vdshPos;
    float dl = length(lv);
    // A light at the vertex has no direction: distance 0, not NaN.
#if BUFFER
    float dv = dl > 0.0 ? vdsh_distance(vdshSum[i], vdshMaxDistance) : 0.0;
#else
    float dv = dl > 0.0 ? vdsh_distance(vdshSum(lv / dl), vdshMaxDistance) : 0.0;
#endif
#if VDSH_DIST_PATH
    vdshVal[i] = dv;
#else
    vdshVal[i] = vdsh_compare(dv, dl);
#endif
  }
#endif
`;
  const fsHead = `#define NUM_LIGHTS NUM_POINT_LIGHTS\n${defines}${shaders.common}\n` +
    `uniform float vdshMaxDistance;\nuniform mat4 vdshBakeFromView;\nin vec3 vdshPos;\nfloat vdshS0 = 1.0;\n` +
    `#if NUM_POINT_LIGHTS > 0\nin float vdshVal[NUM_POINT_LIGHTS];\n#endif\n` +
    `// The visibility of the point light at view-space position pv.
float vdshVisibility(float val, vec3 pv, int index) {
#if VDSH_DIST_PATH
  float s = vdsh_compare(val, length((vdshBakeFromView * vec4(pv, 1.0)).xyz - vdshPos));
#else
  float s = val;
#endif
  if (index == 0) vdshS0 = s;
  return s;
}
`;
  material.onBeforeCompile = (shader) => {
    Object.assign(shader.uniforms, uniforms);
    let vs = shader.vertexShader, fs = shader.fragmentShader;
    vs = patch(vs, 'void main() {', vsHead + 'void main() {', 'vertex shader');
    const end = vs.lastIndexOf('}');
    vs = vs.slice(0, end) + vsMain + vs.slice(end);
    const anchor = 'getPointLightInfo( pointLight, geometryPosition, directLight );';
    const lights = patch(THREE.ShaderChunk.lights_fragment_begin, anchor,
      anchor + '\n\t\tdirectLight.color *= vdshVisibility( vdshVal[ i ], pointLight.position, UNROLLED_LOOP_INDEX );',
      'lights_fragment_begin');
    fs = patch(fs, '#include <lights_fragment_begin>', lights, 'fragment shader');
    fs = patch(fs, 'void main() {', fsHead + 'void main() {', 'fragment shader');
    fs = patch(fs, '#include <dithering_fragment>',
      '#include <dithering_fragment>\n#if VDSH_OUTPUT == 1\n\tgl_FragColor = vec4(vec3(vdshS0), 1.0);\n#endif', 'fragment shader');
    shader.vertexShader = vs;
    shader.fragmentShader = fs;
  };
  const key = 'vdsh:' + stream.attribute_prefix + ':' + (buffer ? 'buffer' : 'attr') + ':' + output;
  const prevKey = material.customProgramCacheKey.bind(material);
  material.customProgramCacheKey = () => prevKey() + key;
  // The bake's frame: world -> bake, view -> bake, before every draw.
  const bakeFromWorld = new THREE.Matrix4();
  const prevBefore = mesh.onBeforeRender;
  mesh.onBeforeRender = function (renderer, scene, camera, ...rest) {
    if (frame) {
      frame.updateWorldMatrix(true, false);
      bakeFromWorld.copy(frame.matrixWorld).invert();
    }
    uniforms.vdshBakeFromWorld.value.copy(bakeFromWorld);
    uniforms.vdshBakeFromView.value.multiplyMatrices(bakeFromWorld, camera.matrixWorld);
    if (prevBefore) prevBefore.call(this, renderer, scene, camera, ...rest);
  };
  material.needsUpdate = true;
  material.userData.vdsh = { order: stream.order, adaptive: !!stream.variable_order, path: buffer ? 'buffer' : 'attributes',
    quantity: stream.quantity };
  mesh.material = material;
  return material;
}
