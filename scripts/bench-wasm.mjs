// Timing of the wasm build in Node: evaluation throughput (point + first and second
// derivatives) on the keycap and the T-junction sample, planning time per sample, and each
// public .tsm file loaded and planned three-axis (r 1 mm, h 0.05 mm; target ≤ 2 s).
// Usage: scripts/build-wasm && node scripts/bench-wasm.mjs
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';

const pkg = fileURLToPath(new URL('../www/pkg/', import.meta.url));
const wasm = await import(pkg + 'tspath.js');
const exports = await wasm.default({ module_or_path: readFileSync(pkg + 'tspath_bg.wasm') });
const wasmMemory = () => exports.memory;

function best(fn, runs = 7) {
  let t = Infinity;
  for (let i = 0; i < runs; i++) {
    const t0 = performance.now();
    fn();
    t = Math.min(t, performance.now() - t0);
  }
  return t;
}

// The closed head planned five-axis (issue 19: target ≤ 2 s and ≤ 40 MB of wasm memory),
// first, so that the memory read after it is what this plan needed.
{
  const m = wasm.Model.sample('head');
  const before = wasmMemory().buffer.byteLength;
  const t0 = performance.now();
  const p = m.plan({ tool_radius_mm: 0.5, scallop_mm: 0.01, max_tilt_deg: 120 }, null);
  const ms = performance.now() - t0;
  const r = p.report();
  console.log(`plan head five-axis (r 0.5 mm, h 0.01 mm, tilt ≤ 120°): ${r.cl_points} CL points, largest axis step ${r.max_axis_step_deg.toFixed(2)}°, ${r.status} in ${ms.toFixed(0)} ms (target ≤ 2000 ms); wasm memory ${(before / 1048576).toFixed(1)} → ${(wasmMemory().buffer.byteLength / 1048576).toFixed(1)} MB (target ≤ 40 MB)`);
  p.free();
  m.free();
}

for (const name of ['keycap-convex', 'tjunction']) {
  const m = wasm.Model.sample(name);
  let count = 0;
  const ms = best(() => { count = m.benchDerivs(16); });
  console.log(`eval ${name}: ${count} points+derivatives in ${ms.toFixed(2)} ms = ${(count / ms / 1000).toFixed(2)} M/s`);
  m.free();
}

// Best time of `runs` whole plans of model `m` with `opts`, and the last plan's report.
function timePlan(m, opts, runs) {
  let report = null;
  const ms = best(() => {
    const p = m.plan(opts, null);
    report = p.report();
    p.free();
  }, runs);
  return { ms, report };
}

// Planning at the paper's settings, and the wasm memory it needed.
const paper = { tool_radius_mm: 0.5, scallop_mm: 0.005, chordal_mm: 0.001 };
for (const name of ['keycap-convex', 'keycap-concave']) {
  const m = wasm.Model.sample(name);
  const { ms, report } = timePlan(m, paper, 5);
  console.log(`plan ${name}: ${report.cl_points} CL points in ${ms.toFixed(1)} ms`);
  m.free();
}
// The space-filling curve (issue 14): the convex keycap at the paper's settings (target
// 400 ms) and mouse.tsm at r 1 mm, h 0.01 mm, three-axis (target 1 s), whole plans.
{
  const m = wasm.Model.sample('keycap-convex');
  const { ms, report } = timePlan(m, { ...paper, strategy: 'isfc' }, 5);
  console.log(`plan keycap-convex isfc: ${report.cl_points} CL points in ${ms.toFixed(1)} ms (target ≤ 400 ms)`);
  m.free();
  const bytes = readFileSync(fileURLToPath(new URL('../www/models/grapetec/mouse.tsm', import.meta.url)));
  const mouse = wasm.Model.fromBytes(bytes, 'mouse.tsm');
  const t = timePlan(mouse, { tool_radius_mm: 1, scallop_mm: 0.01, max_tilt_deg: 0, strategy: 'isfc' }, 3);
  console.log(`plan mouse.tsm isfc (three-axis, r 1 mm, h 0.01 mm): ${t.report.cl_points} CL points, ${t.report.retractions} retractions, ${t.report.length_mm.toFixed(0)} mm in ${t.ms.toFixed(0)} ms (target ≤ 1000 ms)`);
  mouse.free();
}
// The watershed strategy (issue 15): bumps-hole at r 1 mm, h 0.01 mm (target 800 ms), and
// its multi-rectangle baseline.
for (const strategy of ['watershed', 'multi-rectangle']) {
  const m = wasm.Model.sample('bumps-hole');
  const { ms, report } = timePlan(m, { tool_radius_mm: 1, scallop_mm: 0.01, strategy }, 3);
  console.log(`plan bumps-hole ${strategy} (r 1 mm, h 0.01 mm): ${report.cl_points} CL points, ${report.rectangles.length} rectangles, ${report.reversals} reversals in ${ms.toFixed(0)} ms${strategy === 'watershed' ? ' (target ≤ 800 ms)' : ''}`);
  m.free();
}
// Iso-planar slicing (issue 16): the convex keycap at the paper's settings, three-axis
// (target 500 ms).
{
  const m = wasm.Model.sample('keycap-convex');
  const { ms, report } = timePlan(m, { ...paper, strategy: 'isoplanar', max_tilt_deg: 0 }, 5);
  console.log(`plan keycap-convex isoplanar: ${report.cl_points} CL points, ${report.planes} planes in ${ms.toFixed(1)} ms (target ≤ 500 ms)`);
  m.free();
}
// The comparison (issue 17): every strategy on the convex keycap at the paper's settings,
// three-axis, with and without simulating each cut (target ≤ 3 s, progress at least every
// 250 ms).
{
  const m = wasm.Model.sample('keycap-convex');
  for (const simulate of [false, true]) {
    const ticks = [];
    const t0 = performance.now();
    const c = m.compare({ ...paper, max_tilt_deg: 0 }, '', '3-axis', simulate, () => {
      ticks.push(performance.now() - t0);
      return true;
    });
    const ms = performance.now() - t0;
    const runs = c.report().runs;
    const gaps = [ticks[0], ...ticks.slice(1).map((t, i) => t - ticks[i]), ms - ticks[ticks.length - 1]];
    console.log(`compare keycap-convex (${simulate ? 'each cut simulated' : 'plans only'}): ${runs.length} rows (${runs.filter((r) => r.error).length} could not plan) in ${ms.toFixed(0)} ms (target ≤ 3000 ms); ${ticks.length} progress calls, longest gap ${Math.max(...gaps).toFixed(0)} ms (target ≤ 250 ms)`);
    c.free();
  }
  m.free();
}
// The public .tsm files as a user opens them in the page: load, then plan three-axis.
const models = fileURLToPath(new URL('../www/models/grapetec/', import.meta.url));
for (const file of ['simple.tsm', 'mouse.tsm', 'face.tsm', 'fan.tsm', 'Bike.tsm', 'gearbox2-9.tsm']) {
  const bytes = readFileSync(models + file);
  let loadMs = Infinity;
  let planMs = Infinity;
  let points = 0;
  let status = '';
  for (let run = 0; run < 3; run++) {
    const t0 = performance.now();
    const m = wasm.Model.fromBytes(bytes, file);
    const t1 = performance.now();
    const p = m.plan({ tool_radius_mm: 1, scallop_mm: 0.05, max_tilt_deg: 0 }, null);
    const t2 = performance.now();
    const r = p.report();
    points = r.cl_points;
    status = r.status;
    loadMs = Math.min(loadMs, t1 - t0);
    planMs = Math.min(planMs, t2 - t1);
    p.free();
    m.free();
  }
  console.log(`${file}: load ${loadMs.toFixed(0)} ms + plan ${planMs.toFixed(0)} ms = ${(loadMs + planMs).toFixed(0)} ms (three-axis, r 1 mm, h 0.05 mm; ${points} CL points, ${status}; target ≤ 2000 ms)`);
}
console.log(`wasm memory: ${(wasmMemory().buffer.byteLength / 1048576).toFixed(1)} MB`);
