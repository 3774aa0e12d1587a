// web_cpca_pack.mjs VDSH_CORE - runtime/web/vdsh_core.js's
// vdshCpcaBufferData (a cpca stream kept compressed for the vertex stage)
// against vdshCpcaDecode (decoded at load, to the bit the C reader's):
// random streams of orders 1-16, 1-9 clusters, 1-order^2 basis vectors,
// 2-8 bits per weight, extreme levels included, are packed, then decoded
// here as runtime/shaders/vdsh_buffer.glsl's BUF_KIND 4 reads them (the
// record's words field by field, the model's texels in bufferSequence's
// order, the texture width honoured) in f32. Every coefficient must match
// the load decode within f32 rounding of the other product order
// (level * (step * basis) there, (level * step) * basis here): a field or
// texel out of place is off by whole values. Also: a level out of range
// and a model view too short are refused by both. Streams with a width
// per basis vector (bits 0 and "widths", formats/GLTF.md) are packed the
// same way and decoded through the BUF_CPCA_UNPACK macro that
// vdshCpcaBufferData writes for the shader (its statements executed
// here); a width out of 2..8 and a level beyond its own width's range
// are refused.
import { importCore } from './web_core.mjs';
const { vdshCpcaDecode, vdshCpcaBufferData, bufferSequence } = await importCore(process.argv[2]);

let seed = 12345;
const rnd = () => (seed = (Math.imul(seed, 1103515245) + 12345) >>> 0) / 4294967296;
const fail = (msg) => { console.log('FAIL: ' + msg); process.exitCode = 1; };
const f16ish = (x) => Math.fround(Math.round(x * 1024) / 1024);

// widths: null (every vector `bits` wide) or a width per vector (bits 0)
function stream(N, K, B, bits, nv, widths = null) {
  const nc = N * N, Ls = Array.from({ length: B }, (_, j) => (1 << ((widths ? widths[j] : bits) - 1)) - 1);
  const steps = Array.from({ length: K * B }, () => Math.fround(0.01 + rnd()));  // any f32: products round
  const means = Array.from({ length: K * nc }, () => f16ish(rnd() * 4 - 2));
  const bases = Array.from({ length: K * B * nc }, () => f16ish(rnd() * 2 - 1));
  const bytes = new Uint8Array(4 * (steps.length + means.length + bases.length) + 8);
  const dv = new DataView(bytes.buffer);
  let off = 8;  // not at 0: offsets are honoured
  const put = (a) => { const at = off; a.forEach((x, i) => dv.setFloat32(at + 4 * i, x, true)); off += 4 * a.length; return at; };
  const st = { order: N, cpca: widths ? { clusters: K, basis: B, bits: 0, widths } : { clusters: K, basis: B, bits } };
  st.cpca.steps_offset = put(steps);
  st.cpca.means_offset = put(means);
  st.cpca.bases_offset = put(bases);
  const cluster = new Float32Array(4 * nv), levels = [];
  for (let g = 0; g < Math.ceil(B / 4); g++) levels.push(new Float32Array(4 * nv));
  for (let v = 0; v < nv; v++) {
    cluster[4 * v] = Math.floor(rnd() * K);
    for (let j = 0; j < B; j++)
      levels[j >> 2][4 * v + (j & 3)] = v < 2 ? (v ? -Ls[j] : Ls[j]) : Math.floor(rnd() * (2 * Ls[j] + 1)) - Ls[j];
  }
  return { st, cluster, levels, bytes };
}

// vdsh_buffer.glsl's buf_begin and buf_next (BUF_KIND 4), in f32.
function shaderDecode(cd, N, nv) {
  const seq = bufferSequence(N), nc = N * N, out = new Float32Array(nv * nc), mag = new Float64Array(nv * nc);
  const B = cd.basis;
  const word = (t) => cd.words[(t % cd.width) + Math.floor(t / cd.width) * cd.width];
  const model = (t, k) => cd.model[4 * ((t % cd.width) + Math.floor(t / cd.width) * cd.width) + k];
  for (let v = 0; v < nv; v++) {
    let at = v * cd.stride, w = word(at), shift = 8;
    const texel = (w & 255) * cd.T, wt = [];
    if (cd.bits) {
      for (let j = 0; j < B; j++) {
        if (shift + cd.bits > 32) { w = word(++at); shift = 0; }
        wt.push(((w << (32 - shift - cd.bits)) | 0) >> (32 - cd.bits));
        shift += cd.bits;
      }
    } else {
      // BUF_CPCA_UNPACK(first), statement by statement
      const body = cd.unpack.replace(/^#define BUF_CPCA_UNPACK\(f\)/, '').trim();
      for (const st of body.split(';').map((x) => x.trim()).filter((x) => x)) {
        let m;
        if ((m = /^w = BUF_FETCH\(\(f\) \+ (\d+)\)\.r$/.exec(st))) w = word(v * cd.stride + Number(m[1]));
        else if ((m = /^b_wt\[(\d+)\] = float\(int\(w << (\d+)u\) >> (\d+)\)$/.exec(st)))
          wt[Number(m[1])] = ((w << Number(m[2])) | 0) >> Number(m[3]);
        else throw new Error('BUF_CPCA_UNPACK: unknown statement ' + st);
      }
      if (wt.length !== B || wt.some((x) => x === undefined)) throw new Error('BUF_CPCA_UNPACK: not every weight');
    }
    for (let p = 0; p < seq.length; p++) {
      const t = (texel + (p >> 2)) * (B + 1);
      let a = model(t, p & 3), m = Math.abs(a);
      for (let j = 0; j < B; j++) {
        a = Math.fround(a + Math.fround(wt[j] * model(t + 1 + j, p & 3)));
        m += Math.abs(wt[j] * model(t + 1 + j, p & 3));
      }
      out[v * nc + seq[p]] = a;
      mag[v * nc + seq[p]] = m;
    }
  }
  return { out, mag };
}

let cases = 0;
for (const [N, K, B, bits, width] of [[1, 1, 1, 2, 4096], [2, 3, 4, 8, 4096], [3, 2, 9, 3, 9], [5, 4, 13, 5, 64],
  [12, 8, 54, 4, 4096], [12, 9, 46, 4, 130], [16, 2, 256, 8, 4096], [7, 5, 21, 6, 40], [16, 1, 3, 7, 16]]) {
  const nv = 37, { st, cluster, levels, bytes } = stream(N, K, B, bits, nv);
  const dec = vdshCpcaDecode(st, nv, cluster, levels, bytes);
  const cd = vdshCpcaBufferData(st, nv, cluster, levels, bytes, width);
  const got = shaderDecode(cd, N, nv);
  // each sum's rounding: (B + 2) f32 roundings of at most its terms' sum
  let worst = 0;
  for (let i = 0; i < dec.length; i++)
    worst = Math.max(worst, Math.abs(got.out[i] - dec[i]) / ((B + 2) * 2 ** -23 * got.mag[i] + 1e-30));
  console.log(`order ${N}, ${K},${B},${bits}, width ${cd.width}: ${cd.stride} words per vertex, ` +
    `largest |vertex decode - load decode| ${worst.toFixed(3)} of its rounding bound`);
  if (!(worst <= 1)) fail(`order ${N} ${K},${B},${bits}: decodes differ by ${worst} of the rounding bound`);
  if (cd.stride !== Math.ceil((8 + B * bits) / 32) && 32 % bits === 0)
    fail(`order ${N} ${K},${B},${bits}: ${cd.stride} words per record`);
  cases++;
}
// A width per basis vector (bits 0): mixed widths, fields skipping the
// ends of words; every vector 8 bits; a single 2-bit vector.
const mixed = (B, f) => Array.from({ length: B }, (_, j) => f(j));
for (const [N, K, widths, width] of [[12, 8, mixed(31, (j) => [6, 5, 5, 4, 4, 4][j] || (j < 15 ? 3 : 2)), 4096],
  [3, 6, mixed(9, () => 8), 16], [1, 1, [2], 4096], [16, 3, mixed(100, (j) => 2 + ((j * 3) % 7)), 300]]) {
  const B = widths.length, nv = 37, { st, cluster, levels, bytes } = stream(N, K, B, 0, nv, widths);
  const dec = vdshCpcaDecode(st, nv, cluster, levels, bytes);
  const cd = vdshCpcaBufferData(st, nv, cluster, levels, bytes, width);
  const got = shaderDecode(cd, N, nv);
  let worst = 0;
  for (let i = 0; i < dec.length; i++)
    worst = Math.max(worst, Math.abs(got.out[i] - dec[i]) / ((B + 2) * 2 ** -23 * got.mag[i] + 1e-30));
  let words = 1;
  for (let j = 0, sh = 8; j < B; sh += widths[j], j++) if (sh + widths[j] > 32) { words++; sh = 0; }
  console.log(`order ${N}, ${K},${B}, widths ${widths[0]}..${widths[B - 1]}, width ${cd.width}: ${cd.stride} ` +
    `words per vertex, largest |vertex decode - load decode| ${worst.toFixed(3)} of its rounding bound`);
  if (!(worst <= 1)) fail(`order ${N} ${K},${B} widths: decodes differ by ${worst} of the rounding bound`);
  if (cd.stride !== words || cd.bits !== 0) fail(`order ${N} ${K},${B} widths: ${cd.stride} words, not ${words}`);
  cases++;
}
{
  const widths = [8, 3, 2, 5], { st, cluster, levels, bytes } = stream(4, 2, 4, 0, 5, widths);
  levels[0][4 * 3 + 2] = -2;  // vertex 3, vector 2: 2 bits, -1..1
  for (const f of [() => vdshCpcaDecode(st, 5, cluster, levels, bytes), () => vdshCpcaBufferData(st, 5, cluster, levels, bytes, 4096)])
    try { f(); fail('a weight level of -2 at 2 bits was accepted'); } catch (e) {
      if (!/weight level -2, not within \+-1/.test(e.message)) fail('wrong message: ' + e.message);
    }
  levels[0][4 * 3 + 2] = 0;
  for (const bad of [[8, 3, 1, 5], [8, 3, 2, 9], [8, 3, 2], undefined]) {
    st.cpca.widths = bad;
    try { vdshCpcaBufferData(st, 5, cluster, levels, bytes, 4096); fail('widths ' + bad + ' accepted'); } catch (e) {
      if (!/without "widths"/.test(e.message)) fail('wrong message: ' + e.message);
    }
  }
}
// Refused by both: a level beyond +-(2^(bits-1) - 1), a model view cut short.
const { st, cluster, levels, bytes } = stream(5, 2, 6, 4, 5);
levels[0][4] = 8;
for (const f of [() => vdshCpcaDecode(st, 5, cluster, levels, bytes), () => vdshCpcaBufferData(st, 5, cluster, levels, bytes, 4096)])
  try { f(); fail('a weight level of 8 at 4 bits was accepted'); } catch (e) {
    if (!/weight level 8/.test(e.message)) fail('wrong message: ' + e.message);
  }
levels[0][4] = 0;
for (const f of [() => vdshCpcaDecode(st, 5, cluster, levels, bytes.subarray(0, 40)),
  () => vdshCpcaBufferData(st, 5, cluster, levels, bytes.subarray(0, 40), 4096)])
  try { f(); fail('a short model view was accepted'); } catch (e) {
    if (!/not inside its model view/.test(e.message)) fail('wrong message: ' + e.message);
  }
console.log(`${cases} streams packed and decoded as the vertex stage does`);
