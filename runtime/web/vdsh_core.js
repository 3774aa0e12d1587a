// vdsh_core.js - what the web viewer (vdsh_web.js, raw WebGL2) and the
// three.js module (vdsh_three.js) share: an ES module without three.js.
//   - the shader files (runtime/shaders/), fetched;
//   - the choice of a stream (vdsh-view's default);
//   - the buffer path's data (each vertex's coefficients in a float
//     texture, as runtime/vr_buffer.c lays them out) and its K table;
//   - the vertex stage's VDSH code: per light the value interpolated to
//     the fragment stage (the C runtime's rule, runtime/shaders/README.md):
//       log-distance streams, and every stream on the buffer path: the
//         distance vdsh_distance(sum, max_distance) (the fragment compares
//         it with |light - fragment|: VDSH_DIST_PATH 1);
//       linear streams (distance, distance^2) on the attribute path: the
//         visibility vdsh_compare(distance, |light - vertex|).
// What each caller adds is its lighting: vdsh_web.js vdsh-view's Lambert
// and lights (its default picture is vdsh-view --render's), vdsh_three.js
// three.js's own materials and PointLights.

export const MAX_ORDER = 16;
export const VDSH_EXT = 'VDSH_visibility_distance';

// The shader files, from the folder `url` (default ../shaders/ next to
// this file, the source tree's and the installed layout).
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

// The stream to draw: order N, 'adaptive', or vdsh-view's default (5,
// else 3, else 2, else the adaptive stream, else the highest order).
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

// How a stream is drawn: its quantity's number, attribute groups, the
// buffer path or not (orders other than 2, 3, 5, an order per vertex, a
// cpca stream, or path 'buffer'), and whether the fragment stage compares
// distances.
export function vdshStreamPlan(stream, path) {
  if (!(stream.order >= 1 && stream.order <= MAX_ORDER)) throw new Error('stream order ' + stream.order + ' out of range 1..16');
  const quantity = { 'distance': 0, 'distance2': 1, 'log-distance': 2 }[stream.quantity];
  if (quantity === undefined) throw new Error('stream quantity ' + stream.quantity + ' unknown');
  const buffer = path === 'buffer' || !!stream.variable_order || !!stream.cpca || ![2, 3, 5].includes(stream.order);
  return { order: stream.order, quantity, groups: Math.ceil(stream.order * stream.order / 4), buffer,
    distPath: buffer || quantity === 2 };
}

// K_l^|m| per coefficient index l(l+1)+m (sqrt 2 folded in for m != 0),
// in double then rounded to f32, as runtime/vr_buffer.c (make_ks).
export function ksTable(order) {
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
export const flit = (x) => {
  const s = Math.fround(x).toPrecision(9);
  return /[.e]/.test(s) ? s : s + '.0';
};

// The order the recurrence consumes coefficients in (vr_buffer_sequence):
// m outside, l inside, +m before -m.
export function bufferSequence(order) {
  const out = [];
  for (let m = 0; m < order; m++)
    for (let l = m; l < order; l++) {
      out.push(l * (l + 1) + m);
      if (m > 0) out.push(l * (l + 1) - m);
    }
  return out;
}

// The buffer path's data: each vertex's record (its coefficients up to
// its own order -- the last nonzero band of an adaptive stream -- in the
// recurrence's order), four to a texel, row by row in a width x height
// RGBA float texture; records (first texel) and orders per vertex.
// get(v, i): coefficient i of vertex v (as stored: times the scale in the
// shader).
export function vdshBufferData(get, nv, stream, maxTexture) {
  const N = stream.order, nc = N * N;
  const orders = new Uint32Array(nv), records = new Uint32Array(nv);
  let total = 0;
  for (let v = 0; v < nv; v++) {
    let k = N;
    if (stream.variable_order)
      for (k = 0; k < N; k++) {
        let zero = true;
        for (let i = k * k; i < nc && zero; i++) zero = get(v, i) === 0;
        if (zero) break;
      }
    orders[v] = k;
    records[v] = total;
    total += Math.ceil(k * k / 4);
  }
  const width = Math.min(maxTexture, 4096), height = Math.max(1, Math.ceil(total / width));
  if (height > maxTexture) throw new Error('the coefficients need ' + total + ' texels, over this GPU\'s texture (' +
    maxTexture + ' x ' + maxTexture + ')');
  const texels = new Float32Array(width * height * 4), seqs = [];
  for (let v = 0; v < nv; v++) {
    const k = orders[v], seq = seqs[k] || (seqs[k] = bufferSequence(k));
    for (let p = 0, at = 4 * records[v]; p < seq.length; p++) texels[at + p] = get(v, seq[p]);
  }
  return { orders, records, texels, width, height };
}

// A cpca stream's model (formats/GLTF.md "cpca streams"): its steps,
// means and bases as f32, read from the bytes of its buffer view and
// checked. cluster, levels: the cluster attribute's values (VEC4, x used)
// and the weight attributes' (VEC4 each). at(v, j): vertex v's cluster
// (j < 0) or weight level j, checked against the stream's ranges.
function cpcaModel(stream, cluster, levels, model) {
  const c = stream.cpca, N = stream.order, nc = N * N;
  const K = c.clusters, B = c.basis;
  const bad = (what) => new Error('cpca stream of order ' + N + ': ' + what);
  if (!(K >= 1 && K <= 256 && B >= 1 && B <= nc && (c.bits === 0 || (c.bits >= 2 && c.bits <= 8))))
    throw bad('clusters ' + K + ', basis ' + B + ', bits ' + c.bits + ' out of range');
  // bits 0: a width per basis vector (formats/GLTF.md "cpca streams")
  if (c.bits === 0 && !(Array.isArray(c.widths) && c.widths.length === B &&
      c.widths.every((x) => Number.isInteger(x) && x >= 2 && x <= 8)))
    throw bad('bits 0 without "widths", ' + B + ' integers 2..8');
  const widths = c.bits ? new Array(B).fill(c.bits) : c.widths.slice();
  const Ls = widths.map((x) => (1 << (x - 1)) - 1);
  if (levels.length !== Math.ceil(B / 4)) throw bad(levels.length + ' weight attributes, not ' + Math.ceil(B / 4));
  const dv = new DataView(model.buffer, model.byteOffset, model.byteLength);
  const floats = (off, n, what) => {
    if (!(off >= 0 && off % 4 === 0 && off + 4 * n <= model.byteLength))
      throw bad('its ' + what + ' (' + n + ' floats at byte ' + off + ') are not inside its model view of ' +
        model.byteLength + ' bytes');
    const a = new Float32Array(n);
    for (let i = 0; i < n; i++) {
      a[i] = dv.getFloat32(off + 4 * i, true);
      if (!Number.isFinite(a[i])) throw bad('a ' + what + ' value is not finite');
    }
    return a;
  };
  const at = (v, j) => {
    if (j < 0) {
      const k = cluster[4 * v];
      if (!(k >= 0 && k < K && Number.isInteger(k))) throw bad('vertex ' + v + ' has cluster ' + k + ', not below ' + K);
      return k;
    }
    const q = levels[j >> 2][4 * v + (j & 3)];
    if (!(Math.abs(q) <= Ls[j] && Number.isInteger(q)))
      throw bad('vertex ' + v + ' has weight level ' + q + ', not within +-' + Ls[j]);
    return q;
  };
  return { N, nc, K, B, bits: c.bits, widths, at, steps: floats(c.steps_offset, K * B, 'steps'),
    means: floats(c.means_offset, K * nc, 'means'), bases: floats(c.bases_offset, K * B * nc, 'bases') };
}

// A cpca stream of a glb decoded at load into plain coefficients, which
// then take the buffer path like any other stream: to the bit what the C
// reader's vdsh_stream_decode gives (w_j = level_j * step_{c,j}, then from
// the mean a = a + w_j * basis_{c,j}[i] in order, each product and sum
// rounded to f32: a double result of f32 operands rounded once to f32 is
// the f32 operation's). Arguments as cpcaModel's; nv vertices.
// Returns a Float32Array, coefficient i of vertex v at v * order^2 + i;
// throws on a model or record that breaks the layout's rules.
export function vdshCpcaDecode(stream, nv, cluster, levels, model) {
  const m = cpcaModel(stream, cluster, levels, model), { nc, B } = m;
  const out = new Float32Array(nv * nc), w = new Float32Array(B);
  for (let v = 0; v < nv; v++) {
    const k = m.at(v, -1);
    for (let j = 0; j < B; j++) w[j] = m.at(v, j) * m.steps[k * B + j];  // rounded to f32 by the store
    for (let i = 0; i < nc; i++) {
      let a = m.means[k * nc + i];
      for (let j = 0; j < B; j++) a = Math.fround(a + Math.fround(w[j] * m.bases[(k * B + j) * nc + i]));
      out[v * nc + i] = a;
    }
  }
  return out;
}

// A cpca stream kept compressed on the GPU and decoded in the vertex
// stage (vdsh_buffer.glsl's BUF_KIND 4, as vdsh-view draws it): each
// vertex's record as the file stores it (formats/VDSH.md "cpca streams":
// the cluster in bits 0-7 of word 0, then the weight levels of `bits`
// bits each, or with bits 0 of widths[j] bits, two's complement, a field
// that does not fit in what is left of a word starting the next; `unpack`
// is then the shader's BUF_CPCA_UNPACK), `stride` words from vertex v * stride,
// one word per texel of an R32UI texture; and the model as RGBA32F
// texels (runtime/vr_buffer.c's build_model): for cluster c and record
// texel t (four coefficients in bufferSequence's order), B + 1 texels from
// (c * T + t) * (B + 1), the mean and then each basis vector times its
// step. Both textures are `width` texels wide. Arguments as
// vdshCpcaDecode's; maxTexture: the GPU's MAX_TEXTURE_SIZE.
export function vdshCpcaBufferData(stream, nv, cluster, levels, model, maxTexture) {
  const m = cpcaModel(stream, cluster, levels, model), { N, nc, K, B, bits, widths } = m;
  // each field's word and shift (weight j widths[j] bits wide)
  const fields = [];
  let stride = 1;
  for (let j = 0, shift = 8; j < B; shift += widths[j], j++) {
    if (shift + widths[j] > 32) {
      stride++;
      shift = 0;
    }
    fields.push([stride - 1, shift]);
  }
  const width = Math.min(maxTexture, 4096);
  const seq = bufferSequence(N), T = Math.ceil(seq.length / 4), row = B + 1;
  const rows = (texels, what) => {
    const h = Math.max(1, Math.ceil(texels / width));
    if (h > maxTexture) throw new Error('cpca stream of order ' + N + ': its ' + what + ' need ' + texels +
      ' texels, over this GPU\'s texture (' + maxTexture + ' x ' + maxTexture + ')');
    return h;
  };
  const height = rows(nv * stride, 'records'), modelHeight = rows(K * T * row, 'model');
  const words = new Uint32Array(width * height);
  for (let v = 0; v < nv; v++) {
    words[v * stride] = m.at(v, -1);
    for (let j = 0; j < B; j++)
      words[v * stride + fields[j][0]] |= ((m.at(v, j) & ((1 << widths[j]) - 1)) << fields[j][1]) >>> 0;
  }
  const texels = new Float32Array(width * modelHeight * 4);
  for (let c = 0; c < K; c++)
    for (let p = 0; p < seq.length; p++) {
      const t = ((c * T + (p >> 2)) * row) * 4 + (p & 3);
      texels[t] = m.means[c * nc + seq[p]];
      for (let j = 0; j < B; j++)
        texels[t + 4 * (j + 1)] = Math.fround(m.steps[c * B + j] * m.bases[(c * B + j) * nc + seq[p]]);
    }
  // bits 0: buf_begin's unpacking written out, as runtime/vr_buffer.c's
  // cpca_unpack_define writes it (the word fetched once, then per field
  // its shifts as constants)
  let unpack = '';
  if (!bits) {
    unpack = '#define BUF_CPCA_UNPACK(f)';
    for (let j = 0, last = 0; j < B; j++) {
      const [wd, sh] = fields[j];
      if (wd !== last) unpack += ` w = BUF_FETCH((f) + ${wd}).r;`;
      last = wd;
      unpack += ` b_wt[${j}] = float(int(w << ${32 - sh - widths[j]}u) >> ${32 - widths[j]});`;
    }
    unpack += '\n';
  }
  return { stride, words, width, height, model: texels, modelHeight, basis: B, bits, widths, unpack, T };
}

// The vertex stage's VDSH code for a plan (vdshStreamPlan), after
// NUM_LIGHTS and vdsh_common.glsl (`defines` goes before vdsh_common.glsl):
// the caller declares `uniform float vdshScale, vdshMaxDistance;` before
// `decl`, binds the attributes vdshC0.. (the glb's groups, attribute path)
// or a_record, a_order and the texture u_coef (buffer path, width
// texWidth), or, given cpca (vdshCpcaBufferData's result: a cpca stream
// decoded in the vertex stage), the textures u_coef (its words) and
// u_model (its model), and calls
//   void vdsh_vertex(vec3 p, vec3 lights[NUM_LIGHTS], out float val[NUM_LIGHTS])
// p the vertex and lights in the bake's frame; val: per light the
// distance (VDSH_DIST_PATH 1) or the visibility, to interpolate.
export function vdshVertexGlsl(plan, shaders, texWidth, cpca) {
  const defines = `#define QUANTITY ${plan.quantity}\n#define COMPARE 0\n#define VDSH_DIST_PATH ${plan.distPath ? 1 : 0}\n` +
    `#define BUFFER ${plan.buffer ? 1 : 0}\n#define VDSH_ORDER ${plan.order}\n`;
  let decl = '';
  if (plan.buffer) {
    const ks = ksTable(plan.order);
    const kind = cpca ? `#define BUF_KIND 4\n#define BUF_VARIABLE 0\n#define BUF_STRIDE ${cpca.stride}\n` +
      `#define BUF_CPCA_BASIS ${cpca.basis}\n#define BUF_CPCA_BITS ${cpca.bits}\n#define BUF_CPCA_T ${cpca.T}\n` +
      (cpca.unpack || '')
      : '#define BUF_KIND 0\n#define BUF_VARIABLE 1\n#define BUF_STRIDE 0\n';
    decl = `#define BUF_TEXTURE_2D 1\n#define BUF_TEX_WIDTH ${texWidth}\n${kind}#define BUF_ORDER ${plan.order}\n` +
      `#define BUF_RECEIVER vdshP\n#define BUF_LIGHT(i) vdshL[i]\n#define BUF_SCALE vdshScale\n` +
      `vec3 vdshP;\nvec3 vdshL[NUM_LIGHTS];\n` +
      `const float KS[${ks.length}] = float[${ks.length}](${Array.from(ks, flit).join(', ')});\n` + shaders.buffer + '\n';
  } else {
    for (let g = 0; g < plan.groups; g++) decl += `in vec4 vdshC${g};\n`;
    const g7 = Array.from({ length: 7 }, (_, g) => (g < plan.groups ? 'vdshC' + g : 'vec4(0.0)')).join(', ');
    decl += `float vdshSum(vec3 d) {
#if VDSH_ORDER == 2
  return vdshScale * sh_sum4(vdshC0, d);
#elif VDSH_ORDER == 3
  return vdshScale * sh_sum9(vdshC0, vdshC1, vdshC2.x, d);
#else
  vec4 g[7] = vec4[7](${g7});
  return vdshScale * vdsh_sh_sum25(g, d);
#endif
}
`;
  }
  decl += `void vdsh_vertex(vec3 p, vec3 lights[NUM_LIGHTS], out float val[NUM_LIGHTS]) {
#if BUFFER
  vdshP = p;
  for (int i = 0; i < NUM_LIGHTS; i++) vdshL[i] = lights[i];
  float sums[NUM_LIGHTS];
  buffer_sums(sums);
#endif
  for (int i = 0; i < NUM_LIGHTS; i++) {
    vec3 lv = lights[i] - p;
    float dl = length(lv);
    // a light at the vertex has no direction: distance 0, not NaN
#if BUFFER
    float dv = dl > 0.0 ? vdsh_distance(sums[i], vdshMaxDistance) : 0.0;
#else
    float dv = dl > 0.0 ? vdsh_distance(vdshSum(lv / dl), vdshMaxDistance) : 0.0;
#endif
#if VDSH_DIST_PATH
    val[i] = dv;
#else
    val[i] = vdsh_compare(dv, dl);
#endif
  }
}
`;
  return { defines, decl };
}

// ---- free space (formats/vdsh_light.h, formats/vdsh_scene_view.c) ----
// The rule vdsh-view places its default lights by, in double arithmetic
// (the C is float: a decision at a clearance's edge may differ): a point
// is free when none of 14 probes (the axes, the cube diagonals) meets a
// surface nearer than the clearance (1% of the diagonal), and none meets
// the back of a face first, or more meet fronts than backs.

const FREE_DIRS = (() => {
  const d = [];
  for (let a = 0; a < 3; a++)
    for (const s of [-1, 1]) { const v = [0, 0, 0]; v[a] = s; d.push(v); }
  const q = 0.57735026918962576;
  for (let k = 0; k < 8; k++) d.push([k & 1 ? q : -q, k & 2 ? q : -q, k & 4 ? q : -q]);
  return d;
})();

// vdsh_free_diagonal: the bounds' diagonal, the clearance's scale.
function freeDiagonal(lo, hi) {
  return Math.fround(Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])) || 1;
}

// vdsh_free_space: the decision from the probes' first hits.
function freeSpace(hits, clearance) {
  let backs = 0, fronts = 0;
  for (const h of hits) {
    if (!h) continue;
    if (h.t < clearance) return false;
    if (h.back) backs++; else fronts++;
  }
  return backs === 0 || fronts > backs;
}

// A uniform grid of the triangles (about two cells per triangle, at most
// 128 a side) and the first hit along a ray (Moller-Trumbore, edges
// included; back: the winding normal along the ray), as vdsh_view_trace.
export function vdshViewTracer(pos, indices) {
  const nt = Math.floor(indices.length / 3);
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < 3 * nt; i++)
    for (let k = 0; k < 3; k++) {
      const x = pos[3 * indices[i] + k];
      lo[k] = Math.min(lo[k], x);
      hi[k] = Math.max(hi[k], x);
    }
  const diag = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  const ext = [0, 0, 0], n = [1, 1, 1], cell = [0, 0, 0];
  for (let k = 0; k < 3; k++) {
    lo[k] -= 1e-4 * diag;
    ext[k] = Math.max(hi[k] + 1e-4 * diag - lo[k], 1e-3 * diag);
  }
  const h = Math.cbrt(ext[0] * ext[1] * ext[2] / (2 * Math.max(nt, 1)));
  for (let k = 0; k < 3; k++) {
    n[k] = Math.min(128, Math.max(1, Math.ceil(ext[k] / h)));
    cell[k] = ext[k] / n[k];
  }
  const cellOf = (k, x) => Math.min(n[k] - 1, Math.max(0, Math.floor((x - lo[k]) / cell[k])));
  const vert = (t, j) => 3 * indices[3 * t + j];
  const lists = new Map();
  for (let t = 0; t < nt; t++) {
    const c0 = [0, 0, 0], c1 = [0, 0, 0];
    for (let k = 0; k < 3; k++) {
      const xs = [0, 1, 2].map((j) => pos[vert(t, j) + k]);
      const a = Math.min(...xs), b = Math.max(...xs), pad = 1e-3 * diag + 1e-3 * cell[k];
      c0[k] = cellOf(k, a - pad);
      c1[k] = cellOf(k, b + pad);
    }
    for (let z = c0[2]; z <= c1[2]; z++)
      for (let y = c0[1]; y <= c1[1]; y++)
        for (let x = c0[0]; x <= c1[0]; x++) {
          const id = (z * n[1] + y) * n[0] + x;
          if (!lists.has(id)) lists.set(id, []);
          lists.get(id).push(t);
        }
  }
  function hitTri(t, o, d, tmin, best) {
    const a = vert(t, 0), b = vert(t, 1), c = vert(t, 2);
    const e1 = [0, 1, 2].map((k) => pos[b + k] - pos[a + k]), e2 = [0, 1, 2].map((k) => pos[c + k] - pos[a + k]);
    const s = [0, 1, 2].map((k) => o[k] - pos[a + k]);
    const p = [d[1] * e2[2] - d[2] * e2[1], d[2] * e2[0] - d[0] * e2[2], d[0] * e2[1] - d[1] * e2[0]];
    const det = e1[0] * p[0] + e1[1] * p[1] + e1[2] * p[2];
    if (det === 0) return;
    const u = (s[0] * p[0] + s[1] * p[1] + s[2] * p[2]) / det;
    if (!(u >= 0 && u <= 1)) return;
    const q = [s[1] * e1[2] - s[2] * e1[1], s[2] * e1[0] - s[0] * e1[2], s[0] * e1[1] - s[1] * e1[0]];
    const v = (d[0] * q[0] + d[1] * q[1] + d[2] * q[2]) / det;
    if (!(v >= 0 && u + v <= 1)) return;
    const dist = (e2[0] * q[0] + e2[1] * q[1] + e2[2] * q[2]) / det;
    if (!(dist >= tmin) || !(dist < best.t || (dist === best.t && t < best.tri))) return;
    best.t = dist;
    best.tri = t;
    best.back = det < 0;
  }
  function trace(o, d, tmin = 0) {
    let t0 = Math.max(tmin, 0), t1 = Infinity;
    for (let k = 0; k < 3; k++) {
      if (d[k] === 0) {
        if (o[k] < lo[k] || o[k] > lo[k] + ext[k]) return null;
        continue;
      }
      const a = (lo[k] - o[k]) / d[k], b = (lo[k] + ext[k] - o[k]) / d[k];
      t0 = Math.max(t0, Math.min(a, b));
      t1 = Math.min(t1, Math.max(a, b));
    }
    if (!(t0 <= t1)) return null;
    const c = [0, 1, 2].map((k) => cellOf(k, o[k] + t0 * d[k]));
    const step = d.map((x) => (x > 0 ? 1 : x < 0 ? -1 : 0));
    const best = { t: Infinity, tri: -1, back: false };
    for (;;) {
      const list = lists.get((c[2] * n[1] + c[1]) * n[0] + c[0]);
      if (list) for (const t of list) hitTri(t, o, d, tmin, best);
      let axis = 0;
      const next = [0, 1, 2].map((k) => (step[k] ? (lo[k] + (c[k] + (step[k] > 0)) * cell[k] - o[k]) / d[k] : Infinity));
      for (let k = 1; k < 3; k++) if (next[k] < next[axis]) axis = k;
      if (best.t <= next[axis] || next[axis] > t1) break;
      c[axis] += step[axis];
      if (c[axis] < 0 || c[axis] >= n[axis]) break;
    }
    return best.tri < 0 ? null : best;
  }
  const probes = (p) => FREE_DIRS.map((d) => trace(p, d));
  return {
    trace, probes,
    // vdsh_view_free_space at `clearance` (default: 1% of the diagonal given)
    free: (p, diagonal, clearance = 0.01 * diagonal) => freeSpace(probes(p), clearance),
  };
}

// vdsh_light_candidate: candidate k of the seeded sequence, uniform in
// lo..hi (SplitMix64 on seed, k, axis: the C's bits, as BigInt).
export function vdshLightCandidate(lo, hi, seed, k) {
  const M = (x) => BigInt.asUintN(64, x);
  return [0, 1, 2].map((a) => {
    let z = M(BigInt(seed) + 0x9e3779b97f4a7c15n * BigInt(k * 4 + a + 1));
    z = M((z ^ (z >> 30n)) * 0xbf58476d1ce4e5b9n);
    z = M((z ^ (z >> 27n)) * 0x94d049bb133111ebn);
    z ^= z >> 31n;
    const u = Number(z >> 11n) / 9007199254740992;
    return Math.fround(lo[a] + u * (hi[a] - lo[a]));
  });
}

// vdsh_light_region: the bounds, or grown by up to a quarter of their
// diagonal when few of 1024 seeded candidates in them are free (a closed
// object fills its bounds): VDSH_REGION_GROW at 64 or fewer free, 0 at
// 256 or more, linear between.
export function vdshLightRegion(lo, hi, isFree) {
  const seed = 0x6f626a6563747321n;
  let found = 0;
  for (let k = 0; found < 256 && k < 1024; k++) found += isFree(vdshLightCandidate(lo, hi, seed, k)) ? 1 : 0;
  const share = found <= 64 ? 0.25 : found >= 256 ? 0 : 0.25 * (256 - found) / (256 - 64);
  const g = share * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  return share > 0 ? [lo.map((x) => Math.fround(x - g)), hi.map((x) => Math.fround(x + g))] : [lo.slice(), hi.slice()];
}

// find_free (vdsh_scene_view.c): p0 when free; else, inside lo..hi, on
// rings k = 1, 2, ... of 26 directions (faces, edges, corners) at steps
// of half the clearance, the nearest position 8 clearances from every
// surface within 16 clearances (VDSH_VIEW_LIGHT_MARGIN, _MARGIN_REACH),
// else the nearest free one up to half the diagonal; else the seeded
// candidates (seed 1) in lo..hi, nearest first, the first 4096. null
// when none is free.
export function vdshFindFree(tracer, p0, lo, hi, diagonal) {
  const clear = 0.01 * diagonal, h = 0.5 * clear;
  if (tracer.free(p0, diagonal)) return p0.slice();
  const dirs = [];
  for (let ones = 1; ones <= 3; ones++)
    for (let z = -1; z <= 1; z++)
      for (let y = -1; y <= 1; y++)
        for (let x = -1; x <= 1; x++)
          if (Math.abs(x) + Math.abs(y) + Math.abs(z) === ones) {
            const l = Math.sqrt(ones);
            dirs.push([x / l, y / l, z / l]);
          }
  const inside = (p) => p.every((x, k) => x > lo[k] && x < hi[k]);
  const rings = Math.ceil(0.5 * diagonal / h), reach = 32;
  for (let pass = 0; pass < 2; pass++)
    for (let k = 1; k <= (pass ? rings : reach); k++)
      for (const d of dirs) {
        const p = p0.map((x, a) => Math.fround(x + k * h * d[a]));
        if (inside(p) && freeSpace(tracer.probes(p), pass ? clear : 8 * clear)) return p;
      }
  const cand = [];
  for (let k = 0; k < 4096; k++) {
    const p = vdshLightCandidate(lo, hi, 1, k);
    cand.push({ p, d2: (p[0] - p0[0]) ** 2 + (p[1] - p0[1]) ** 2 + (p[2] - p0[2]) ** 2, k });
  }
  cand.sort((a, b) => a.d2 - b.d2 || a.k - b.k);
  for (const c of cand) if (tracer.free(c.p, diagonal)) return c.p;
  return null;
}

// The default view of a file without extras.vdsh.view (an older export),
// formats/vdsh_scene_view.c's for an object: the outside camera
// (vdsh_view_fit_camera) and an object's preferred lights, outside its
// bounding sphere, pulled into its light region (below) and, with the
// mesh, each moved into free space as vdsh-view moves it (find_free):
// pulled into the bounds, a light could stand inside the object. lo, hi:
// the bounds; pos, nrm
// (vertex_count x 3) and indices (triangle_count x 3), when given, decide
// whether the object is flat (every vertex within a hundredth of the
// diagonal of the plane of its largest triangle, VDSH_VIEW_FLAT_SHARE: one
// triangle, a panel);
// a flat object whose front (the side its summed vertex normals face; the
// winding's where they cancel) faces away from the fit direction w is
// seen along w mirrored through its plane (along its normal where that is
// within about 6 degrees of vertical), its lights mirrored through the
// plane through the bounds' centre, then each behind the plane mirrored to
// its front and moved a quarter diagonal off it: vdsh_view_compute's rule
// (flat_front, mirror), so that the camera sees the side the normals face,
// lit.
export function vdshFallbackView(lo, hi, pos, nrm, indices) {
  const f = Math.fround;
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const norm = (a) => { const l = Math.hypot(a[0], a[1], a[2]); return [a[0] / l, a[1] / l, a[2] / l]; };
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const c = [0, 1, 2].map((k) => f(0.5 * (lo[k] + hi[k])));
  const r = Math.sqrt([0, 1, 2].reduce((a, k) => a + 0.25 * (hi[k] - lo[k]) ** 2, 0)) || 1;
  const diag = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) || 1;
  const ax = hi[0] - lo[0] >= hi[2] - lo[2] ? 0 : 2, other = 2 - ax;
  const u = [[0, 0, 0], [0, 1, 0], [0, 0, 0]];
  u[0][ax] = 1;
  u[2][other] = 1;
  const place = (cc, s, a, b, d) => [0, 1, 2].map((k) => cc[k] + s * (a * u[0][k] + b * u[1][k] + d * u[2][k]));
  let w = norm(place([0, 0, 0], 1, 0.8, 0.45, 0.4));
  const fn = pos && indices ? flatFront(pos, nrm, indices, diag) : null;
  const flip = fn !== null && dot(w, fn) < 0;
  // x mirrored through the plane through cc with unit normal fn
  const mirror = (x, cc) => {
    const d = dot([0, 1, 2].map((k) => x[k] - cc[k]), fn);
    return x.map((v, k) => v - 2 * d * fn[k]);
  };
  if (flip) {
    w = mirror(w, [0, 0, 0]);
    if (w[0] * w[0] + w[2] * w[2] < 0.01) w = fn.slice();
  }
  // ... and at most 45 degrees off its normal (VDSH_VIEW_FLAT_ANGLE), turned
  // toward it, its azimuth about the normal kept.
  if (fn !== null) {
    const cw = dot(w, fn), cmax = f(Math.cos(45 * Math.PI / 180));
    if (cw < cmax) {
      const tn = norm(w.map((x, k) => x - cw * fn[k])), smax = Math.sqrt(1 - cmax * cmax);
      w = fn.map((x, k) => cmax * x + smax * tn[k]);
      if (w[0] * w[0] + w[2] * w[2] < 0.01) w = fn.slice();
    }
  }
  const s = norm([w[2], 0, -w[0]]);
  const v = cross(w, s);
  const t = Math.tan(0.5 * 60 * Math.PI / 180);
  let dist = 0;
  for (let corner = 0; corner < 8; corner++) {
    const p = [0, 1, 2].map((k) => ((corner >> k) & 1 ? hi[k] : lo[k]) - c[k]);
    dist = Math.max(dist, dot(p, w) + Math.max(Math.abs(dot(p, s)), Math.abs(dot(p, v))) / t);
  }
  dist = 1.05 * (dist > 0 ? dist : r);
  const around = [[1.5, 1.5, -0.4], [-1.3, 1.2, 1.4], [0.5, 2.1, 1.5], [1.6, 0.5, 1.2]];
  let lights = around.map((a) => place(c, r, a[0], a[1], a[2]));
  if (flip) lights = lights.map((l) => mirror(l, c));
  // A flat object's lights on its front and a quarter of the diagonal off
  // its plane at least, as vdsh_view_compute puts them (light 0 stood
  // behind a panel facing across the longest horizontal axis).
  if (fn !== null) {
    lights = lights.map((l) => {
      let d = dot([0, 1, 2].map((k) => l[k] - c[k]), fn);
      if (d < 0) { l = mirror(l, c); d = -d; }
      const off = f(0.25 * diag);
      return d < off ? l.map((x, k) => x + (off - d) * fn[k]) : l;
    });
  }
  // Pulled into the light region, 5% of each extent inside every face
  // (VDSH_VIEW_REGION_INSET), as vdsh_view_compute pulls them into the
  // light region the bake trained on: with the mesh, vdsh_light_region's
  // (the bounds, or around a closed object the bounds grown; without it,
  // the bounds, which the region holds); along an axis thinner than the
  // clearance (1% of the diagonal) the bounds grown by a quarter of the
  // diagonal there, a flat object's on every axis and along the line to
  // the centre, so each stays on its side of the plane. Then, with the
  // mesh, each into free space (vdshFindFree, vdsh_view_compute's rule).
  const flat = fn !== null;
  const tracer = pos && indices && indices.length >= 3 ? vdshViewTracer(pos, indices) : null;
  let rlo = lo, rhi = hi;
  if (tracer && !flat) [rlo, rhi] = vdshLightRegion(lo, hi, (p) => tracer.free(p, freeDiagonal(lo, hi)));
  const g = 0.25 * freeDiagonal(lo, hi), clear = 0.01 * freeDiagonal(lo, hi);
  const grow = (k) => flat || rhi[k] - rlo[k] < clear;
  const blo = rlo.map((x, k) => (grow(k) ? lo[k] - g : x));
  const bhi = rhi.map((x, k) => (grow(k) ? hi[k] + g : x));
  const inset = (k) => 0.05 * (bhi[k] - blo[k]);
  lights = lights.map((p) => {
    if (!flat) return p.map((x, k) => Math.min(Math.max(x, blo[k] + inset(k)), bhi[k] - inset(k)));
    let sc = 1;
    for (let k = 0; k < 3; k++) {
      const d = p[k] - c[k], room = d > 0 ? bhi[k] - inset(k) - c[k] : c[k] - (blo[k] + inset(k));
      if (Math.abs(d) > room) sc = Math.min(sc, room / Math.abs(d));
    }
    return p.map((x, k) => c[k] + sc * (x - c[k]));
  });
  if (tracer) lights = lights.map((p) => vdshFindFree(tracer, p, blo, bhi, diag) || p);
  return {
    interior: false, eye: c.map((x, k) => x + dist * w[k]), target: c, up: [0, 1, 0], fov_y: 60,
    lights, fallback: true,
  };
}

// formats/vdsh_scene_view.c's flat_front: the unit normal toward a flat
// object's front, or null (not flat, no triangle with an area, or the
// sides cancel).
function flatFront(pos, nrm, indices, diag) {
  let best = 0, pn = null, p0 = null;
  const at = (i) => [pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]];
  const crossOf = (t) => {
    const a = at(indices[3 * t]), b = at(indices[3 * t + 1]), c = at(indices[3 * t + 2]);
    const e1 = [0, 1, 2].map((k) => b[k] - a[k]), e2 = [0, 1, 2].map((k) => c[k] - a[k]);
    return { a, x: [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]] };
  };
  const nt = Math.floor(indices.length / 3), nv = Math.floor(pos.length / 3);
  for (let t = 0; t < nt; t++) {
    const { a, x } = crossOf(t);
    const l = Math.hypot(x[0], x[1], x[2]);
    if (l > best) {
      best = l;
      pn = x.map((e) => e / l);
      p0 = a;
    }
  }
  if (!pn) return null;
  let side = 0, wind = 0;
  for (let i = 0; i < nv; i++) {
    const q = at(i);
    if (Math.abs((q[0] - p0[0]) * pn[0] + (q[1] - p0[1]) * pn[1] + (q[2] - p0[2]) * pn[2]) > 0.01 * diag) return null;
    if (nrm) side += nrm[3 * i] * pn[0] + nrm[3 * i + 1] * pn[1] + nrm[3 * i + 2] * pn[2];
  }
  for (let t = 0; t < nt; t++) {
    const { x } = crossOf(t);
    wind += x[0] * pn[0] + x[1] * pn[1] + x[2] * pn[2];
  }
  const sign = side !== 0 ? side : wind;
  if (sign === 0) return null;
  return pn.map((e) => (sign > 0 ? e : -e));
}
