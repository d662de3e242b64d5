// The page: picks or opens a model, plans, shows the result and offers the G-code.
import { loadBytes, loadSample, sampleNames, version } from './engine.js';
import { View } from './view.js';

const $ = (id) => document.getElementById(id);
const view = new View($('view'));
const PARAMS = ['tool_radius_mm', 'scallop_mm', 'chordal_mm', 'feed_mm_min'];
let model = null;
let plan = null;

function status(text, isError = false) {
  const el = $('status');
  el.textContent = text;
  el.classList.toggle('error', isError);
}

function facts(el, rows) {
  el.replaceChildren();
  for (const [k, v] of rows) {
    const dt = document.createElement('dt');
    dt.textContent = k;
    const dd = document.createElement('dd');
    dd.textContent = v;
    el.append(dt, dd);
  }
}

const mm = (x, d = 3) => `${x.toFixed(d)} mm`;

function showModel(m) {
  if (plan) { plan.free(); plan = null; }
  if (model) model.free();
  model = m;
  const s = model.summary();
  const size = s.bbox_mm.max.map((v, k) => v - s.bbox_mm.min[k]);
  facts($('summary'), [
    ['Name', s.name],
    ['Size', size.map((v) => v.toFixed(2)).join(' × ') + ' mm'],
    ['Faces', s.faces],
    ['Control points', s.control_points],
    ['Patches', s.patches],
    ['T-junctions', s.t_junctions],
    ['Extraordinary points', s.extraordinary_points],
  ]);
  const chordal = Math.max(0.005, Math.hypot(...size) * 2e-4);
  const mesh = model.tessellate(chordal);
  view.setMesh(mesh.positions(), mesh.normals(), mesh.indices(), mesh.patchIds());
  mesh.free();
  view.setPath(null);
  facts($('report'), []);
  $('download').disabled = true;
  document.body.dataset.state = 'model-loaded';
  document.body.dataset.model = s.name;
  status(`Loaded ${s.name}.`);
}

function options() {
  const o = {};
  for (const id of PARAMS) {
    const v = Number($(id).value);
    if (!Number.isFinite(v) || v <= 0) throw new Error(`${$(id).labels[0].textContent} must be a positive number`);
    o[id] = v;
  }
  return o;
}

async function doPlan() {
  if (!model) return;
  $('plan').disabled = true;
  status('Planning…');
  document.body.dataset.state = 'planning';
  await new Promise((r) => setTimeout(r, 0));
  try {
    if (plan) { plan.free(); plan = null; }
    plan = model.plan(options(), null);
    const r = plan.report();
    view.setPath(plan.clPoints(), plan.moveKinds(), plan.patchIds());
    facts($('report'), [
      ['Path length', mm(r.length_mm, 1)],
      ['Cutting length', mm(r.cutting_length_mm, 1)],
      ['CL points', r.cl_points],
      ['Retractions', r.retractions],
      ['Reversals', r.reversals],
      ['Predicted max scallop', mm(r.max_predicted_scallop_mm, 4)],
      ['Machining time', `${r.machining_time_min.toFixed(1)} min`],
      ['Planning time', `${r.plan_ms.toFixed(0)} ms`],
    ]);
    $('download').disabled = false;
    document.body.dataset.state = 'planned';
    status(`Planned ${r.cl_points} points in ${r.plan_ms.toFixed(0)} ms.`);
  } catch (e) {
    document.body.dataset.state = 'model-loaded';
    status(`Could not plan: ${e.message}`, true);
  } finally {
    $('plan').disabled = false;
  }
}

function download() {
  if (!plan) return;
  const blob = new Blob([plan.gcode()], { type: 'text/plain' });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = `${model.name}.nc`;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

async function openFile(file) {
  try {
    const bytes = new Uint8Array(await file.arrayBuffer());
    const stem = file.name.replace(/\.[^.]*$/, '');
    showModel(await loadBytes(bytes, stem));
  } catch (e) {
    status(`Could not open ${file.name}: ${e.message}`, true);
  }
}

async function main() {
  try {
    $('version').textContent = await version();
    const names = await sampleNames();
    for (const n of names) $('sample').append(new Option(n, n));
    $('sample').addEventListener('change', async () => showModel(await loadSample($('sample').value)));
    $('file').addEventListener('change', () => $('file').files[0] && openFile($('file').files[0]));
    $('plan').addEventListener('click', doPlan);
    $('download').addEventListener('click', download);
    showModel(await loadSample(names[0]));
  } catch (e) {
    status(`The engine failed to start: ${e.message}`, true);
    document.body.dataset.state = 'error';
  }
}

main();
