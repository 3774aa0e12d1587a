// web_glb_pack.mjs MODULES IN.glb OUT.glb quantise|meshopt - a glb of
// vdsh-export rewritten as the standard compressors write it, for the web
// viewer's test (tests/test_web_viewer.py):
//   quantise: KHR_mesh_quantization as gltfpack does it: POSITION as
//     uint16 (byteStride 8) with the dequantisation (one scale, a
//     translation) in the node's transform, NORMAL as normalised int8
//     (byteStride 4); the VDSH attributes stay normalised int16;
//   meshopt: the same, then every buffer view compressed with
//     EXT_meshopt_compression (meshoptimizer's encoder from MODULES, the
//     npm package meshoptimizer: ATTRIBUTES for vertex data, TRIANGLES for
//     indices), the uncompressed data left out (a fallback buffer).
// Extras (the VDSH streams, the default view) are kept.
import { readFileSync, writeFileSync } from 'node:fs';
import { pathToFileURL } from 'node:url';

const [modules, input, output, how] = process.argv.slice(2);
const d = readFileSync(input);
const jl = d.readUInt32LE(12);
const json = JSON.parse(d.subarray(20, 20 + jl).toString());
const binAt = 20 + jl;
const bin = d.subarray(binAt + 8, binAt + 8 + d.readUInt32LE(binAt));

const chunks = [];  // the new BIN: [Buffer]
let size = 0;
const put = (b) => {
  const at = size;
  chunks.push(Buffer.from(b));
  size += b.length;
  const pad = (4 - (size % 4)) % 4;
  if (pad) { chunks.push(Buffer.alloc(pad)); size += pad; }
  return at;
};
const views = [];
const addView = (bytes, stride, target) => {
  const v = { buffer: 0, byteOffset: put(bytes), byteLength: bytes.length, target };
  if (stride) v.byteStride = stride;
  views.push(v);
  return views.length - 1;
};
const viewBytes = (ai) => {
  const a = json.accessors[ai], v = json.bufferViews[a.bufferView];
  return bin.subarray((v.byteOffset || 0) + (a.byteOffset || 0), (v.byteOffset || 0) + v.byteLength);
};

const prim = json.meshes[0].primitives[0];
const pa = json.accessors[prim.attributes.POSITION], n = pa.count;
const lo = pa.min, hi = pa.max;
const ext = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
const s = ext / 65535;
const pb = viewBytes(prim.attributes.POSITION), pf = new Float32Array(Uint8Array.from(pb.subarray(0, 12 * n)).buffer);
const qp = Buffer.alloc(8 * n), qmin = [65535, 65535, 65535], qmax = [0, 0, 0];
for (let i = 0; i < n; i++)
  for (let k = 0; k < 3; k++) {
    const q = Math.max(0, Math.min(65535, Math.round((pf[3 * i + k] - lo[k]) / s)));
    qp.writeUInt16LE(q, 8 * i + 2 * k);
    qmin[k] = Math.min(qmin[k], q);
    qmax[k] = Math.max(qmax[k], q);
  }
const nb = viewBytes(prim.attributes.NORMAL), nf = new Float32Array(Uint8Array.from(nb.subarray(0, 12 * n)).buffer);
const qn = Buffer.alloc(4 * n);
for (let i = 0; i < n; i++)
  for (let k = 0; k < 3; k++) qn.writeInt8(Math.max(-127, Math.min(127, Math.round(nf[3 * i + k] * 127))), 4 * i + k);

const accessors = [];
const attributes = {};
const acc = (a) => { accessors.push(a); return accessors.length - 1; };
attributes.POSITION = acc({ bufferView: addView(qp, 8, 34962), componentType: 5123, count: n, type: 'VEC3', min: qmin, max: qmax });
attributes.NORMAL = acc({ bufferView: addView(qn, 4, 34962), componentType: 5120, normalized: true, count: n, type: 'VEC3' });
for (const [name, ai] of Object.entries(prim.attributes)) {
  if (name === 'POSITION' || name === 'NORMAL') continue;
  const a = json.accessors[ai];
  const bytes = viewBytes(ai).subarray(0, a.count * 8);
  attributes[name] = acc({ bufferView: addView(bytes, 8, 34962), componentType: a.componentType, normalized: a.normalized, count: a.count, type: a.type });
}
const ia = json.accessors[prim.indices];
const isz = ia.componentType === 5125 ? 4 : 2;
const indices = acc({ bufferView: addView(viewBytes(prim.indices).subarray(0, ia.count * isz), 0, 34963), componentType: ia.componentType, count: ia.count, type: 'SCALAR' });

const out = JSON.parse(JSON.stringify(json));
out.meshes[0].primitives = [{ attributes, indices, mode: 4 }];
out.accessors = accessors;
out.nodes = [{ mesh: 0, translation: lo, scale: [s, s, s] }];
out.scenes = [{ nodes: [0] }];
out.scene = 0;
out.extensionsUsed = ['KHR_mesh_quantization'];
out.extensionsRequired = ['KHR_mesh_quantization'];
let body = Buffer.concat(chunks);
if (how === 'meshopt') {
  const { MeshoptEncoder } = await import(pathToFileURL(modules + '/meshoptimizer/meshopt_encoder.js'));
  await MeshoptEncoder.ready;
  const packed = [];
  let at = 0;
  for (const v of views) {
    const src = new Uint8Array(body.buffer, body.byteOffset + v.byteOffset, v.byteLength);
    const index = v.target === 34963;
    const stride = index ? isz : v.byteStride;
    const count = v.byteLength / stride;
    const mode = index ? 'TRIANGLES' : 'ATTRIBUTES';
    const enc = MeshoptEncoder.encodeGltfBuffer(src, count, stride, mode);
    v.buffer = 1;  // the uncompressed data: the fallback buffer, not stored
    v.extensions = { EXT_meshopt_compression: { buffer: 0, byteOffset: at, byteLength: enc.length, byteStride: stride, mode, count } };
    packed.push(Buffer.from(enc));
    at += enc.length;
    const pad = (4 - (at % 4)) % 4;
    if (pad) { packed.push(Buffer.alloc(pad)); at += pad; }
  }
  out.buffers = [{ byteLength: at }, { byteLength: body.length, extensions: { EXT_meshopt_compression: { fallback: true } } }];
  body = Buffer.concat(packed);
  out.extensionsUsed.push('EXT_meshopt_compression');
  out.extensionsRequired.push('EXT_meshopt_compression');
} else {
  out.buffers = [{ byteLength: body.length }];
}
out.bufferViews = views;
let js = Buffer.from(JSON.stringify(out));
js = Buffer.concat([js, Buffer.alloc((4 - (js.length % 4)) % 4, 0x20)]);
const head = Buffer.alloc(20);
head.writeUInt32LE(0x46546C67, 0);
head.writeUInt32LE(2, 4);
head.writeUInt32LE(12 + 8 + js.length + 8 + body.length, 8);
head.writeUInt32LE(js.length, 12);
head.writeUInt32LE(0x4E4F534A, 16);
const bh = Buffer.alloc(8);
bh.writeUInt32LE(body.length, 0);
bh.writeUInt32LE(0x004E4942, 4);
writeFileSync(output, Buffer.concat([head, js, bh, body]));
console.log(`${output}: ${12 + 8 + js.length + 8 + body.length} bytes (${how}; from ${d.length})`);
