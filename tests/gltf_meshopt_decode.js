// gltf_meshopt_decode.js NODE_MODULES IN.glb OUT.glb - a glb with
// EXT_meshopt_compression rewritten with every compressed buffer view
// decoded by meshoptimizer's decoder (the npm package meshoptimizer, not
// the library vdsh-export encodes with) into one plain BIN buffer: the
// views keep their indices and byteStride, so accessors read as before
// (tests/test_gltf_export.py compares them with the uncompressed export).
const path = require('path');
const fs = require('fs');
const MeshoptDecoder = require(path.join(process.argv[2], 'meshoptimizer', 'meshopt_decoder.cjs'));
const [input, output] = process.argv.slice(3);
(async () => {
  await MeshoptDecoder.ready;
  const d = fs.readFileSync(input);
  const jl = d.readUInt32LE(12);
  const json = JSON.parse(d.subarray(20, 20 + jl).toString());
  const bin = d.subarray(28 + jl, 28 + jl + d.readUInt32LE(20 + jl));
  const parts = [];
  let size = 0;
  for (const v of json.bufferViews) {
    const x = v.extensions && v.extensions.EXT_meshopt_compression;
    let bytes;
    if (x) {
      const src = new Uint8Array(bin.buffer, bin.byteOffset + (x.byteOffset || 0), x.byteLength);
      bytes = new Uint8Array(x.count * x.byteStride);
      MeshoptDecoder.decodeGltfBuffer(bytes, x.count, x.byteStride, src, x.mode, x.filter || 'NONE');
      delete v.extensions;
    } else {
      bytes = bin.subarray(v.byteOffset || 0, (v.byteOffset || 0) + v.byteLength);
    }
    v.buffer = 0;
    v.byteOffset = size;
    v.byteLength = bytes.length;
    parts.push(Buffer.from(bytes));
    size += bytes.length;
    const pad = (4 - (size % 4)) % 4;
    if (pad) { parts.push(Buffer.alloc(pad)); size += pad; }
  }
  json.buffers = [{ byteLength: size }];
  json.extensionsUsed = (json.extensionsUsed || []).filter((e) => e !== 'EXT_meshopt_compression');
  json.extensionsRequired = (json.extensionsRequired || []).filter((e) => e !== 'EXT_meshopt_compression');
  let js = Buffer.from(JSON.stringify(json));
  js = Buffer.concat([js, Buffer.alloc((4 - (js.length % 4)) % 4, 0x20)]);
  const body = Buffer.concat(parts);
  const head = Buffer.alloc(20);
  head.writeUInt32LE(0x46546C67, 0);
  head.writeUInt32LE(2, 4);
  head.writeUInt32LE(28 + js.length + body.length, 8);
  head.writeUInt32LE(js.length, 12);
  head.writeUInt32LE(0x4E4F534A, 16);
  const bh = Buffer.alloc(8);
  bh.writeUInt32LE(body.length, 0);
  bh.writeUInt32LE(0x004E4942, 4);
  fs.writeFileSync(output, Buffer.concat([head, js, bh, body]));
})().catch((e) => { console.error(input + ': ' + e); process.exit(1); });
