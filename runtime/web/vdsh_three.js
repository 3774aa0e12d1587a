// vdsh_three.js - VDSH shadows in three.js: an ES module, no build step.
//
// A mesh that three.js's GLTFLoader read from a glb of vdsh-export
// (formats/GLTF.md: the _VDSH<o>_<k> attributes; the streams in the mesh's
// extras.vdsh, or for `vdsh-export --source` in the root extension
// VDSH_visibility_distance, many meshes each with its attributes; plain or
// --compress: give GLTFLoader meshopt's decoder) gets a MeshStandardMaterial
// whose point lights -- any number, the three.js scene's own PointLights --
// are shadowed by the VDSH
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
// next to this file (loadVdshShaders(url) for another place). The vertex
// stage's VDSH code, the stream choice and the buffer path's data are
// vdsh_core.js's, shared with the web viewer (vdsh_web.js).
//
//   import * as THREE from 'three';
//   import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
//   import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
//   import { loadVdshShaders, vdshApply } from './vdsh_three.js';
//   const shaders = await loadVdshShaders();
//   const gltf = await new GLTFLoader().setMeshoptDecoder(MeshoptDecoder).loadAsync('room.glb');
//   vdshApply(gltf, shaders);
//   scene.add(gltf.scene, new THREE.PointLight(0xffffff, 20));
//
// A cpca stream (vdsh-bake --encoding cpca) is prepared by
// vdshLoadCpca(gltf) (await it before vdshApply): kept compressed and
// decoded in the vertex stage (default), or decoded at load into the
// buffer path (vdshLoadCpca(gltf, { decode: 'load' })).
//
// vdshApply(gltf, shaders, options) gives every mesh that has the VDSH
// attributes its material (below); vdshMaterial(mesh, shaders, options)
// does one mesh, sets and returns mesh.material; options (all optional):
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
//   info       the metadata (vdshInfo(gltf)) for a mesh of a --source export
// The stream must have been baked for this mesh in this frame: lights are
// taken into the bake's frame, where the coefficients' directions live.
// Only three.js PointLights are shadowed (as vdsh-view's lights); other
// lights light the mesh unshadowed.
import * as THREE from 'three';
import { loadVdshShaders, vdshChooseStream, vdshStreamPlan, vdshBufferData, vdshVertexGlsl, vdshCpcaDecode,
  vdshCpcaBufferData, VDSH_EXT } from './vdsh_core.js';

export { loadVdshShaders, vdshChooseStream };

const isInfo = (x) => (x && Array.isArray(x.streams) ? x : null);

// The VDSH description (formats/GLTF.md): of a GLTFLoader result, the
// root extension VDSH_visibility_distance (vdsh-export --source: the
// source's scene, VDSH attributes on each primitive), which GLTFLoader
// puts into gltf.userData.gltfExtensions; of a mesh, the plain export's
// extras.vdsh (GLTFLoader's userData.vdsh) on the mesh or a parent. Null
// when there is none.
export function vdshInfo(o) {
  if (!o) return null;
  if (!o.isObject3D && o.scene) {  // a GLTFLoader result
    const x = isInfo((o.userData && o.userData.gltfExtensions || {})[VDSH_EXT]);
    if (x) return x;
    let found = null;
    o.scene.traverse((m) => { if (!found && m.isMesh) found = vdshInfo(m); });
    return found;
  }
  for (let p = o; p; p = p.parent) {
    const u = p.userData || {};
    if (isInfo(u.vdsh)) return u.vdsh;
    if (isInfo((u.gltfExtensions || {})[VDSH_EXT])) return u.gltfExtensions[VDSH_EXT];
  }
  return null;
}

// The three.js names of a stream's attributes in a geometry (GLTFLoader
// lower-cases custom attribute names), or null when one is missing; a
// cpca stream kept compressed by vdshLoadCpca: [] (its data is
// cpcaData's).
function streamAttributes(geometry, stream) {
  if (cpcaData(geometry, stream)) return [];
  const names = [];
  for (let g = 0; g < Math.ceil(stream.order * stream.order / 4); g++) {
    const n = (stream.attribute_prefix + g).toLowerCase();
    if (!geometry || !geometry.getAttribute(n)) return null;
    names.push(n);
  }
  return names;
}

// A cpca stream's data for the vertex-stage decode (vdshCpcaBufferData's
// result), kept by vdshLoadCpca in the geometry's userData; or undefined.
const cpcaData = (geometry, stream) =>
  stream.cpca && geometry && ((geometry.userData || {}).vdshCpca || {})[stream.attribute_prefix];

// cpca streams (vdsh-bake --encoding cpca; formats/GLTF.md "cpca
// streams": cluster and weight attributes, the model in a buffer view),
// for every mesh of the GLTFLoader result `gltf` whose extras.vdsh has
// one. options.decode 'vertex' (default): kept compressed (about 32 GPU
// bytes per vertex at order 12 and the model) and decoded in the vertex
// stage, as vdsh-view does (vdsh_buffer.glsl's BUF_KIND 4; the data in
// geometry.userData.vdshCpca); 'load': decoded here, the coefficients
// becoming its <prefix><k> attributes (float; 576 GPU bytes per vertex
// at order 12), drawn on the buffer path as any stream. Call it (await)
// before vdshApply and vdshMaterial. Returns the number of streams
// prepared; throws on a broken stream or an unknown options.decode.
export async function vdshLoadCpca(gltf, options = {}) {
  if (!gltf || !gltf.scene || !gltf.parser) throw new Error('vdshLoadCpca: give the result of GLTFLoader');
  const decode = options.decode || 'vertex';
  if (decode !== 'vertex' && decode !== 'load')
    throw new Error("vdshLoadCpca: options.decode '" + decode + "': give 'vertex' or 'load'");
  const meshes = [];
  gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
  let n = 0;
  for (const mesh of meshes) {
    const info = vdshInfo(mesh), geometry = mesh.geometry;
    if (!info || !geometry) continue;
    for (const stream of info.streams) {
      const cp = stream.cpca;
      if (!cp || geometry.getAttribute((stream.attribute_prefix + '0').toLowerCase()) || cpcaData(geometry, stream))
        continue;
      const get = (name) => {
        const a = geometry.getAttribute(name.toLowerCase());
        if (!a) throw new Error('the mesh ' + (mesh.name || '') + ' has no attribute ' + name + ' of its cpca stream');
        const out = new Float32Array(4 * a.count);  // raw values: levels and the cluster index are not normalised
        for (let v = 0; v < a.count; v++) {
          out[4 * v] = a.getX(v); out[4 * v + 1] = a.getY(v); out[4 * v + 2] = a.getZ(v); out[4 * v + 3] = a.getW(v);
        }
        return out;
      };
      const cluster = get(cp.cluster_attribute);
      const levels = Array.from({ length: cp.weight_attributes }, (_, g) => get(cp.weight_prefix + g));
      const model = new Uint8Array(await gltf.parser.getDependency('bufferView', cp.model_view));
      const nv = cluster.length / 4, nc = stream.order * stream.order;
      if (decode === 'vertex') {
        geometry.userData.vdshCpca = Object.assign(geometry.userData.vdshCpca || {}, {
          [stream.attribute_prefix]: vdshCpcaBufferData(stream, nv, cluster, levels, model, options.maxTextureSize || 4096) });
        n++;
        continue;
      }
      const dec = vdshCpcaDecode(stream, nv, cluster, levels, model);
      for (let g = 0; g < Math.ceil(nc / 4); g++) {
        const a = new Float32Array(4 * nv);
        for (let v = 0; v < nv; v++)
          for (let k = 0; k < 4 && 4 * g + k < nc; k++) a[4 * v + k] = dec[v * nc + 4 * g + k];
        geometry.setAttribute((stream.attribute_prefix + g).toLowerCase(), new THREE.BufferAttribute(a, 4));
      }
      n++;
    }
  }
  return n;
}

// VDSH shadows on every mesh of a loaded glTF that holds them: `root` is
// GLTFLoader's result (gltf) or an Object3D (gltf.scene). Each mesh with
// the chosen stream's attributes gets vdshMaterial; the metadata is the
// root extension of a --source export, else each mesh's extras.vdsh.
// options as vdshMaterial's, and:
//   material  a Material to extend (cloned per mesh); 'own' (the mesh's
//             own MeshStandardMaterial, cloned: the default for a --source
//             export, whose materials are the source's); 'grey' (a new
//             grey one: the default for the plain export, whose glTF
//             default material is metallic)
//   frame     default the loaded scene (root.scene, or root): move it and
//             the shadows follow
// Returns the meshes it changed.
export function vdshApply(root, shaders, options = {}) {
  const top = root && !root.isObject3D && root.scene ? root.scene : root;
  if (!top || !top.isObject3D) throw new Error('vdshApply: give the result of GLTFLoader or an Object3D');
  const rootInfo = root !== top ? isInfo((root.userData && root.userData.gltfExtensions || {})[VDSH_EXT]) : null;
  const meshes = [];
  top.traverse((o) => { if (o.isMesh) meshes.push(o); });
  const done = [];
  for (const mesh of meshes) {
    const info = options.info || rootInfo || vdshInfo(mesh);
    if (!info || !info.streams.length) continue;
    if (!streamAttributes(mesh.geometry, vdshChooseStream(info.streams, options.order))) continue;
    let material = options.material;
    const own = mesh.material && !Array.isArray(mesh.material) && mesh.material.isMeshStandardMaterial;
    if (material === 'own' || (material === undefined && info === rootInfo))
      material = own ? mesh.material.clone() : undefined;
    else if (material === 'grey' || material === undefined)
      material = undefined;
    else
      material = material.clone();
    vdshMaterial(mesh, shaders, Object.assign({}, options, { info, material,
      frame: options.frame === undefined ? top : options.frame }));
    done.push(mesh);
  }
  return done;
}

// A texture of exact texels: no filtering, no mipmaps.
function dataTexture(data, w, h, format, type) {
  const tex = new THREE.DataTexture(data, w, h, format, type);
  tex.minFilter = tex.magFilter = THREE.NearestFilter;
  tex.generateMipmaps = false;
  tex.needsUpdate = true;
  return tex;
}

// The buffer path's texture (vdsh_core.js's records) and a_record,
// a_order per vertex. Coefficients are read through BufferAttribute.getX..
// (normalised or not, interleaved or not).
function bufferTexture(geometry, names, stream, maxTexture) {
  const attrs = names.map((n) => geometry.getAttribute(n));
  const comp = ['getX', 'getY', 'getZ', 'getW'];
  const b = vdshBufferData((v, i) => attrs[i >> 2][comp[i & 3]](v), attrs[0].count, stream, maxTexture);
  const tex = dataTexture(b.texels, b.width, b.height, THREE.RGBAFormat, THREE.FloatType);
  geometry.setAttribute('a_record', new THREE.BufferAttribute(b.records, 1));
  geometry.setAttribute('a_order', new THREE.BufferAttribute(b.orders, 1));
  return { tex, width: b.width };
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
  const info = isInfo(options.info) || vdshInfo(mesh);
  if (!info || !info.streams.length) throw new Error('vdshMaterial: the mesh ' + (mesh.name || '') +
    ' holds no VDSH streams (extras.vdsh of a glb written by vdsh-export; for a --source export ' +
    'give options.info = vdshInfo(gltf), or use vdshApply(gltf, ...))');
  const stream = vdshChooseStream(info.streams, options.order);
  const plan = vdshStreamPlan(stream, options.path);
  const geometry = mesh.geometry;
  const names = streamAttributes(geometry, stream);
  if (!names) throw new Error('the mesh ' + (mesh.name || '') + ' has no attributes ' + stream.attribute_prefix +
    '0..' + (plan.groups - 1) + (stream.cpca ? ' (a cpca stream: decode it first, await vdshLoadCpca(gltf))' : ''));
  const buffer = plan.buffer;
  const output = options.output === 'shadow' ? 1 : 0;
  const frame = options.frame || null;
  const uniforms = {
    vdshScale: { value: stream.scale },
    vdshMaxDistance: { value: info.max_distance },
    vdshBakeFromWorld: { value: new THREE.Matrix4() },
    vdshBakeFromView: { value: new THREE.Matrix4() },
  };
  let width = 0;
  const cd = cpcaData(geometry, stream);
  if (cd) {  // kept compressed: decoded in the vertex stage
    const words = dataTexture(cd.words, cd.width, cd.height, THREE.RedIntegerFormat, THREE.UnsignedIntType);
    words.internalFormat = 'R32UI';
    uniforms.u_coef = { value: words };
    uniforms.u_model = { value: dataTexture(cd.model, cd.width, cd.modelHeight, THREE.RGBAFormat, THREE.FloatType) };
    width = cd.width;
  } else if (buffer) {
    const b = bufferTexture(geometry, names, stream, options.maxTextureSize || 4096);
    uniforms.u_coef = { value: b.tex };
    width = b.width;
  } else {
    // Aliases of the glb's attributes (the same BufferAttribute objects:
    // uploaded once), so the GLSL names do not depend on the prefix.
    for (let g = 0; g < plan.groups; g++) geometry.setAttribute('vdshC' + g, geometry.getAttribute(names[g]));
  }
  const vg = vdshVertexGlsl(plan, shaders, width, cd);
  const defines = vg.defines + `#define VDSH_OUTPUT ${output}\n`;

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
    `${vg.decl}#endif\n`;
  const vsMain = `
  vdshPos = (vdshBakeFromWorld * modelMatrix * vec4(position, 1.0)).xyz;
#if NUM_POINT_LIGHTS > 0
  vec3 vdshLights[NUM_POINT_LIGHTS];
  for (int i = 0; i < NUM_POINT_LIGHTS; i++)
    vdshLights[i] = (vdshBakeFromView * vec4(pointLights[i].position, 1.0)).xyz;
  float vdshV[NUM_POINT_LIGHTS];
  vdsh_vertex(vdshPos, vdshLights, vdshV);
  for (int i = 0; i < NUM_POINT_LIGHTS; i++) vdshVal[i] = vdshV[i];
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
  const key = 'vdsh:' + stream.attribute_prefix + ':' + (cd ? 'cpca' : buffer ? 'buffer' : 'attr') + ':' + output;
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
  material.userData.vdsh = { order: stream.order, adaptive: !!stream.variable_order,
    path: cd ? 'cpca' : buffer ? 'buffer' : 'attributes',
    quantity: stream.quantity };
  mesh.material = material;
  return material;
}
