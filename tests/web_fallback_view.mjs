// web_fallback_view.mjs CORE [BAKE EXPORT DIR] - runtime/web/vdsh_core.js's
// vdshFallbackView, the web viewer's default view of a glb without
// extras.vdsh.view, on flat objects (formats/vdsh_scene_view.c's rule):
// a triangle facing each axis both ways, a tilted one, a quad wound both
// ways: the eye and every light on the side the normals face, every corner
// of the bounds in view; a solid (a tetrahedron): the bounds-only camera,
// its lights in its bounds without the mesh; solids with the mesh (a box,
// a flatter one, a cube on a floor): every light in free space (vdsh-view's
// find_free; pulled into the bounds alone a light stood inside the box).
// With BAKE and EXPORT: each triangle baked and exported, and the page's
// view against the one vdsh-export wrote (vdsh-view's, in C): eye and
// target to 1e-4 of the diagonal, each light on the same side; the solids'
// lights within 1e-3 of the diagonal of vdsh-view's. Exit 0 or 1 with the failures.
import { importCore } from './web_core.mjs';
import { execFileSync } from 'node:child_process';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';

const [core, bake, exporter, dir] = process.argv.slice(2);
const { vdshFallbackView } = await importCore(core);
const fail = [];
const check = (ok, msg) => { if (!ok) fail.push(msg); };
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];

function bounds(pos) {
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < pos.length; i += 3)
    for (let k = 0; k < 3; k++) {
      lo[k] = Math.min(lo[k], pos[i + k]);
      hi[k] = Math.max(hi[k], pos[i + k]);
    }
  return [lo, hi];
}

// A mesh with winding normals (each vertex the normal of its triangles).
function mesh(verts, tris) {
  const pos = Float32Array.from(verts.flat()), nrm = new Float32Array(pos.length);
  for (const t of tris) {
    const [a, b, c] = t.map((i) => verts[i]);
    const n = cross(sub(b, a), sub(c, a));
    for (const i of t) for (let k = 0; k < 3; k++) nrm[3 * i + k] += n[k];
  }
  return { verts, tris, pos, nrm, indices: Uint32Array.from(tris.flat()) };
}

// Flat cases: triangles with their front normal.
const cases = [];
const axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
for (let a = 0; a < 3; a++) {
  const e1 = axes[(a + 1) % 3], e2 = axes[(a + 2) % 3], o = [0.5, -0.25, 2];
  const v = [o, o.map((x, k) => x + 2 * e1[k]), o.map((x, k) => x + 1.5 * e2[k])];
  cases.push({ name: 'axis ' + a + ' +', m: mesh(v, [[0, 1, 2]]) });
  cases.push({ name: 'axis ' + a + ' -', m: mesh(v, [[0, 2, 1]]) });
}
cases.push({ name: 'tilted', m: mesh([[0, 0, 0], [1, 0.3, -0.2], [0.2, -0.4, -1]], [[0, 1, 2]]) });
cases.push({ name: 'tilted back', m: mesh([[0, 0, 0], [1, 0.3, -0.2], [0.2, -0.4, -1]], [[0, 2, 1]]) });
const quad = [[0, 0, 0], [2, 0, 0], [2, 1, 0.5], [0, 1, 0.5]];
cases.push({ name: 'quad', m: mesh(quad, [[0, 1, 2], [0, 2, 3]]) });
cases.push({ name: 'quad back', m: mesh(quad, [[0, 2, 1], [0, 3, 2]]) });

let away = 0;
for (const { name, m } of cases) {
  const [lo, hi] = bounds(m.pos);
  const [a, b, c] = m.tris[0].map((i) => m.verts[i]);
  const n = cross(sub(b, a), sub(c, a));
  const v = vdshFallbackView(lo, hi, m.pos, m.nrm, m.indices);
  const plain = vdshFallbackView(lo, hi);
  away += dot(sub(plain.eye, a), n) < 0;
  check(dot(sub(v.eye, a), n) > 0, name + ': the eye ' + v.eye + ' sees the back');
  v.lights.forEach((l, i) => check(dot(sub(l, a), n) > 0, name + ': light ' + i + ' behind the front'));
  // every corner of the bounds in the view (fov_y 60, a square image)
  const f = sub(v.target, v.eye), s = cross(f, v.up), u = cross(s, f), t = Math.tan(Math.PI / 6);
  for (let k = 0; k < 8; k++) {
    const p = [0, 1, 2].map((j) => ((k >> j) & 1 ? hi[j] : lo[j]));
    const d = sub(p, v.eye), z = dot(d, f) / Math.hypot(...f);
    check(Math.abs(dot(d, s) / Math.hypot(...s)) <= t * z * (1 + 1e-6) &&
      Math.abs(dot(d, u) / Math.hypot(...u)) <= t * z * (1 + 1e-6), name + ': corner ' + k + ' out of view');
  }
  m.view = v;
}
check(away >= 4, 'only ' + away + ' cases face away from the bounds-only view: the test tests nothing');
// A solid: the view from the bounds alone.
{
  const t = mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]);
  const [lo, hi] = bounds(t.pos);
  const withMesh = vdshFallbackView(lo, hi, t.pos, t.nrm, t.indices), plain = vdshFallbackView(lo, hi);
  check(JSON.stringify([withMesh.eye, withMesh.target]) === JSON.stringify([plain.eye, plain.target]),
    'a tetrahedron is not framed from the bounds alone');
  // without the mesh its lights in its bounds, which the bake's light
  // region holds (they stood outside the bounding sphere, where the fit
  // was never trained)
  for (const l of plain.lights)
    check(l.every((x, k) => x >= lo[k] && x <= hi[k]), 'a tetrahedron\'s light ' + l + ' outside its bounds');
}

// Solids with the mesh: every light in free space (checked here against
// every triangle, the rule of formats/vdsh_light.h), as vdsh-view moves
// them (find_free); pulled into the bounds without the test, a light stood
// inside a closed box that fills them.
function freeHere(m, p, diag) {
  const q = 0.57735026918962576, dirs = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];
  for (let k = 0; k < 8; k++) dirs.push([k & 1 ? q : -q, k & 2 ? q : -q, k & 4 ? q : -q]);
  let backs = 0, fronts = 0;
  for (const d of dirs) {
    let best = Infinity, back = false;
    for (const t of m.tris) {
      const [a, b, c] = t.map((i) => m.verts[i]);
      const e1 = sub(b, a), e2 = sub(c, a), pv = cross(d, e2), det = dot(e1, pv);
      if (det === 0) continue;
      const s = sub(p, a), u = dot(s, pv) / det, qv = cross(s, e1), v = dot(d, qv) / det, tt = dot(e2, qv) / det;
      if (u >= 0 && u <= 1 && v >= 0 && u + v <= 1 && tt >= 0 && tt < best) { best = tt; back = det < 0; }
    }
    if (best < 0.01 * diag) return false;
    if (best < Infinity) { if (back) backs++; else fronts++; }
  }
  return backs === 0 || fronts > backs;
}
const boxOf = (l, h) => {
  const v = [];
  for (let k = 0; k < 8; k++) v.push([k & 1 ? h[0] : l[0], k & 2 ? h[1] : l[1], k & 4 ? h[2] : l[2]]);
  // outward faces (winding normal out)
  const f = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
  return { v, t: f.flatMap(([a, b, c, d]) => [[a, b, c], [a, c, d]]) };
};
const solids = [];
{
  const b = boxOf([-1, 0, -1], [1, 2, 1]);
  solids.push({ name: 'box', m: mesh(b.v, b.t) });
  const tilted = boxOf([-1, -0.5, -0.7], [1.2, 0.6, 0.9]);
  solids.push({ name: 'flat box', m: mesh(tilted.v, tilted.t) });
  const c = boxOf([-0.5, 0, -0.5], [0.5, 1, 0.5]);
  const floor = [[-2, 0, -2], [-2, 0, 2], [2, 0, 2], [2, 0, -2]];
  solids.push({ name: 'cube on a floor', m: mesh(floor.concat(c.v), [[0, 1, 2], [0, 2, 3]].concat(c.t.map((t) => t.map((i) => i + 4)))) });
}
let wereInside = 0;
for (const { name, m } of solids) {
  const [lo, hi] = bounds(m.pos);
  const diag = Math.hypot(...sub(hi, lo));
  const v = vdshFallbackView(lo, hi, m.pos, m.nrm, m.indices);
  v.lights.forEach((l, i) => check(freeHere(m, l, diag), name + ': light ' + i + ' ' + l + ' is not in free space'));
  wereInside += vdshFallbackView(lo, hi).lights.filter((l) => !freeHere(m, l, diag)).length;
  m.view = v;
}
check(wereInside > 0, 'no bounds-only light of the solids is outside free space: the test tests nothing');

// Against vdsh-view's own default view (vdsh-export's extras.vdsh.view).
if (bake && exporter && dir) {
  mkdirSync(dir, { recursive: true });
  cases.forEach(({ name, m }, i) => {
    const obj = dir + '/flat' + i + '.obj';
    writeFileSync(obj, m.verts.map((p) => 'v ' + p.join(' ')).join('\n') + '\n' +
      m.tris.map((t) => 'f ' + t.map((x) => x + 1).join(' ')).join('\n') + '\n');
    execFileSync(bake, [obj, '--rays', '16', '--cube-size', '0', '-q', '-o', dir + '/flat' + i + '.vdsh']);
    execFileSync(exporter, ['-q', dir + '/flat' + i + '.vdsh', '-o', dir + '/flat' + i + '.glb']);
    const g = readFileSync(dir + '/flat' + i + '.glb');
    const json = JSON.parse(g.subarray(20, 20 + g.readUInt32LE(12)).toString());
    const cv = json.meshes[0].extras.vdsh.view;
    const [lo, hi] = bounds(m.pos);
    const diag = Math.hypot(...sub(hi, lo));
    const near = (p, q) => Math.hypot(...sub(p, q)) <= 1e-4 * diag;
    check(near(m.view.eye, cv.eye), name + ': eye ' + m.view.eye + ', vdsh-view ' + cv.eye);
    check(near(m.view.target, cv.target), name + ': target ' + m.view.target + ', vdsh-view ' + cv.target);
    // Lights: vdsh-view moves one that is not in free space (behind a
    // lone triangle its probes meet the face's back); the page has no
    // tracer and keeps the preferred positions. Each on the same side.
    const [a, b, c] = m.tris[0].map((x) => m.verts[x]), nf = cross(sub(b, a), sub(c, a));
    for (let l = 0; l < cv.lights.length; l++)
      check(Math.sign(dot(sub(m.view.lights[l], a), nf)) === Math.sign(dot(sub(cv.lights[l], a), nf)),
        name + ': light ' + l + ' ' + m.view.lights[l] + ' on the other side from vdsh-view\'s ' + cv.lights[l]);
  });
}
// The solids' lights against vdsh-view's: the same rule (in double
// arithmetic, the C's float; the C's frame rule for an object's lights,
// which these keep as they are, is not the page's): each within 1e-3 of
// the diagonal of the C's.
if (bake && exporter && dir) {
  solids.forEach(({ name, m }, i) => {
    const obj = dir + '/solid' + i + '.obj';
    writeFileSync(obj, m.verts.map((p) => 'v ' + p.join(' ')).join('\n') + '\n' +
      m.tris.map((t) => 'f ' + t.map((x) => x + 1).join(' ')).join('\n') + '\n');
    execFileSync(bake, [obj, '--rays', '16', '--cube-size', '0', '-q', '-o', dir + '/solid' + i + '.vdsh']);
    execFileSync(exporter, ['-q', dir + '/solid' + i + '.vdsh', '-o', dir + '/solid' + i + '.glb']);
    const g = readFileSync(dir + '/solid' + i + '.glb');
    const cv = JSON.parse(g.subarray(20, 20 + g.readUInt32LE(12)).toString()).meshes[0].extras.vdsh.view;
    const [lo, hi] = bounds(m.pos);
    const diag = Math.hypot(...sub(hi, lo));
    const far = cv.lights.map((l, k) => Math.hypot(...sub(l, m.view.lights[k])) / diag);
    console.log(name + ': page lights ' + JSON.stringify(m.view.lights.map((l) => l.map((x) => +x.toFixed(3)))) +
      ', vdsh-view ' + JSON.stringify(cv.lights.map((l) => l.map((x) => +x.toFixed(3)))) + ', apart ' +
      far.map((x) => x.toFixed(4)).join(' ') + ' diagonals');
    check(far.every((x) => x <= 1e-3), name + ': lights apart from vdsh-view\'s by ' + far.join(', ') + ' diagonals');
  });
}
if (fail.length) {
  console.log(fail.join('\n'));
  process.exit(1);
}
console.log('fallback view: ' + cases.length + ' flat objects seen from the front (' + away + ' facing away from the bounds-only view)' +
  (bake ? ', each as vdsh-view sees it' : ''));
