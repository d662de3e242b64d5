// The Web Worker that owns the wasm engine and does every heavy step (load, tessellate,
// plan, post, verify, export), so the page's thread only draws and answers the user.
//
// Protocol: the page posts {id, op, args}; the worker answers {id, ok: true, result} or
// {id, ok: false, error}, and while planning posts {id, progress} (fraction done). Large
// arrays travel as transferred typed arrays. A request cannot be interrupted once running:
// the page cancels by terminating this worker and starting a new one (see client.js).
// Requests are answered one at a time, in the order they came.
//
// The worker starts on the viewer module (or on the planner, when the page has it compiled
// already) and is moved to the planner by `upgrade`, which loads the current model into it;
// the page sends planning requests only after that (see engine.js).
import { engineInfo, loadModel, loadPlanner, loadViewer } from './engine.js';

const KIND_NAMES = ['feed', 'link', 'retract', 'rapid', 'plunge', 'approach'];
/** Least progress interval posted to the page (ms): enough for a smooth bar. */
const PROGRESS_INTERVAL_MS = 40;

let engine = null; // the wasm module's exports in use: the viewer's or the planner's
let planner = false; // whether `engine` is the planner
let source = null; // what `model` was loaded from, to load it again into the planner
let chordal = 0; // the tolerance `mesh` was tessellated with (mm), the same in the planner
let model = null; // wasm Model
let mesh = null; // wasm SurfaceMesh of `model` (the drawn one; the heat map is per vertex of it)
let plan = null; // wasm Plan of `model`
let comparison = null; // wasm Comparison of `model` (its rows' plans not yet picked)

/** Throws unless the planner module is the one in use (the page waits for `upgrade`). */
function needPlanner() {
  if (!planner) throw new Error('the planner module is not loaded yet');
}

function free(x) {
  if (x) x.free();
  return null;
}

/** Makes `nextModel` and its drawn `nextMesh` the current ones; the old model, mesh, plan and
 * comparison are freed. */
function adopt(nextModel, nextMesh) {
  plan = free(plan);
  comparison = free(comparison);
  mesh = free(mesh);
  model = free(model);
  model = nextModel;
  mesh = nextMesh;
}

/** Area of a triangle mesh (mm²): the drawn surface, within its chordal tolerance. */
function meshArea(p, idx) {
  let area = 0;
  for (let t = 0; t < idx.length; t += 3) {
    const a = 3 * idx[t], b = 3 * idx[t + 1], c = 3 * idx[t + 2];
    const ux = p[b] - p[a], uy = p[b + 1] - p[a + 1], uz = p[b + 2] - p[a + 2];
    const vx = p[c] - p[a], vy = p[c + 1] - p[a + 1], vz = p[c + 2] - p[a + 2];
    area += Math.hypot(uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx) / 2;
  }
  return area;
}

/** Tessellation tolerance for drawing: 1/5000 of the diagonal, at least 5 µm (mm). */
function drawChordal(summary) {
  const { min, max } = summary.bbox_mm;
  return Math.max(0.005, Math.hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]) * 2e-4);
}

/** A progress callback posting the fraction done under request `id`, at most every
 * PROGRESS_INTERVAL_MS (and at the end). */
function progressTo(id) {
  let last = 0;
  return (f) => {
    const now = performance.now();
    if (now - last >= PROGRESS_INTERVAL_MS || f >= 1) {
      last = now;
      postMessage({ id, progress: f });
    }
    return true;
  };
}

/** The program of the current plan for a machine, dialect and units: its text, the line of
 * each move in it and the machining time on that machine. */
function program(machine, dialect, units) {
  // The lines first: they post the program once and keep it for gcodeFor.
  const lines = plan.gcodeLines(machine, dialect, units);
  const text = plan.gcodeFor(machine, dialect, units);
  plan.timeOn(machine);
  const { machining_time_min: minutes, time_machine: timeMachine, notes } = plan.report();
  return { text, lines, time: { machining_time_min: minutes, time_machine: timeMachine, notes } };
}

/** The current plan as the page draws it: report, points, kinds, rest area and layers. */
function planResult() {
  const report = plan.report();
  const result = {
    report,
    // What the simulation's first round samples at least (the page shows a preview only
    // before a long one).
    verifyFirstSamples: model.verifyFirstSamples(plan),
    cl: plan.clPoints(),
    cc: plan.ccPoints(),
    axes: plan.axes(),
    kinds: plan.moveKinds(),
    patchIds: plan.patchIds(),
    rest: plan.restPositions(),
    restReasons: plan.restReasons(),
    // A space-filling curve's cells and tree, for the layer (drawn without planning again).
    isfc: report.strategy === 'isfc' ? {
      cells: plan.isfcCells(), tree: plan.isfcTree(), across: plan.isfcTreeAcross(), start: plan.isfcStart(),
    } : null,
    // The watershed strategies' rectangles, for the layer.
    rects: ['watershed', 'multi-rectangle'].includes(report.strategy) ? {
      fills: plan.rectangleFills(), kinds: plan.rectangleKinds(), outlines: plan.rectangleOutlines(), arrows: plan.rectangleArrows(),
    } : null,
  };
  const transfer = ['cl', 'cc', 'axes', 'kinds', 'patchIds', 'rest', 'restReasons'].map((k) => result[k].buffer);
  for (const layer of [result.isfc, result.rects]) {
    if (layer) transfer.push(...Object.values(layer).map((a) => a.buffer));
  }
  return { result, transfer };
}

const ops = {
  /** Starts the engine from `module` (the page's compiled wasm; null: fetch it here): the
   * planner's when `isPlanner`, else the viewer's. */
  async init(module, isPlanner) {
    engine = isPlanner ? await loadPlanner(module) : await loadViewer(module);
    planner = !!isPlanner;
    return { result: engineInfo(engine) };
  },

  /** Moves to the planner module (`module` as for init): the current model is loaded into it
   * again and drawn from there on (the same tessellation: the same code on the same input). */
  async upgrade(module) {
    if (planner) return { result: null };
    const next = await loadPlanner(module);
    let nextModel = null;
    let nextMesh = null;
    if (model) {
      try {
        nextModel = loadModel(next, source);
        nextMesh = nextModel.tessellate(chordal);
      } catch (e) {
        free(nextModel);
        throw e;
      }
    }
    adopt(nextModel, nextMesh);
    engine = next;
    planner = true;
    return { result: null };
  },

  /** Loads a sample ({sample}) or file bytes ({bytes, name}); the old model stays on failure. */
  async load(next) {
    const nextModel = loadModel(engine, next);
    let nextMesh = null;
    try {
      // Without the smallest concave radius, which samples every face: the page asks for
      // it (`concave`) once the model is drawn.
      const summary = nextModel.quickSummary();
      const tolerance = drawChordal(summary);
      nextMesh = nextModel.tessellate(tolerance);
      const result = {
        summary,
        chordal_mm: tolerance,
        area_mm2: meshArea(nextMesh.positions(), nextMesh.indices()),
        positions: nextMesh.positions(),
        normals: nextMesh.normals(),
        indices: nextMesh.indices(),
        patchIds: nextMesh.patchIds(),
        eps: nextModel.extraordinaryPoints(),
        cage: nextModel.controlEdges(),
      };
      adopt(nextModel, nextMesh);
      source = next;
      chordal = tolerance;
      const transfer = ['positions', 'normals', 'indices', 'patchIds', 'eps', 'cage'].map((k) => result[k].buffer);
      return { result, transfer };
    } catch (e) {
      free(nextMesh);
      nextModel.free();
      throw e;
    }
  },

  /** The current model's smallest concave radius: `{radius_mm, at_mm}` (mm) or null. Asked
   * of the planner, whose model keeps it for planning (found in the viewer, it was looked for
   * again by the first plan). */
  async concave() {
    if (!model) throw new Error('no model is loaded');
    needPlanner();
    return { result: model.smallestConcaveRadius() };
  },

  /** Plans with `options` (PlanOptions fields), reporting progress under request `id`; with
   * `post` ({machine, dialect, units}) the answer holds the program too (`program`, as `post`
   * answers, or `programError`), so the page can ask for the simulation as soon as it has the
   * plan. */
  async plan(options, post, id) {
    if (!model) throw new Error('no model is loaded');
    needPlanner();
    plan = free(plan);
    plan = model.plan(options, progressTo(id));
    const answer = planResult();
    if (post) {
      const t0 = performance.now();
      try {
        answer.result.program = program(post.machine, post.dialect, post.units);
        // How long writing it took (ms): not planning, for the page's "re-plan when fast".
        answer.result.program.ms = performance.now() - t0;
        answer.transfer.push(answer.result.program.lines.buffer);
      } catch (e) {
        answer.result.programError = e && e.message ? e.message : String(e);
      }
    }
    return answer;
  },

  /** Compares strategies (`strategies`: comma-separated, all when empty) on the model with
   * `options`, times on `machine`, each cut simulated when `simulate`; the table, its CSV and
   * each row's path for a small view. The rows' plans stay here for `pick`. */
  async compare(options, strategies, machine, simulate, id) {
    if (!model) throw new Error('no model is loaded');
    needPlanner();
    comparison = free(comparison);
    comparison = model.compare(options, strategies, machine, simulate, progressTo(id));
    const report = comparison.report();
    const paths = report.runs.map((_, k) => ({ cl: comparison.clPoints(k), kinds: comparison.moveKinds(k) }));
    const result = { report, csv: comparison.csv(), paths };
    return { result, transfer: paths.flatMap((p) => [p.cl.buffer, p.kinds.buffer]) };
  },

  /** Makes row `k` of the last comparison the current plan (as `plan` returns it). */
  async pick(k) {
    if (!comparison) throw new Error('nothing is compared');
    const next = comparison.take(k);
    plan = free(plan);
    plan = next;
    return planResult();
  },

  /** The program for a machine, dialect and units, and the line of each move in it. */
  async post(machine, dialect, units) {
    if (!plan) throw new Error('nothing is planned');
    const result = program(machine, dialect, units);
    return { result, transfer: [result.lines.buffer] };
  },

  /** Cutting simulation of the plan (`options`: samples, bound_mm, max_samples): summary,
   * the heat map per drawn vertex, and the plan's report with what it found. */
  async verify(options, id) {
    if (!plan) throw new Error('nothing is planned');
    const v = model.verify(plan, mesh, options, progressTo(id));
    try {
      const result = {
        summary: v.summary(), heat: v.heatMap(), verify_ms: v.verifyMs, report: plan.reportWith(v),
      };
      return { result, transfer: [result.heat.buffer] };
    } finally {
      v.free();
    }
  },

  /** The drawn surface as binary STL bytes. */
  async stl() {
    if (!mesh) throw new Error('no model is loaded');
    const bytes = mesh.stl(model.name);
    return { result: bytes, transfer: [bytes.buffer] };
  },

  /** CL data as CSV: one row per move, ball centre, tool axis and contact point (mm). */
  async csv() {
    if (!plan) throw new Error('nothing is planned');
    const cl = plan.clPoints();
    const cc = plan.ccPoints();
    const ax = plan.axes();
    const kinds = plan.moveKinds();
    const patches = plan.patchIds();
    const f = (x) => x.toFixed(6);
    const rows = ['move,kind,patch,cl_x_mm,cl_y_mm,cl_z_mm,axis_i,axis_j,axis_k,cc_x_mm,cc_y_mm,cc_z_mm'];
    for (let i = 0; i < kinds.length; i++) {
      const k = 3 * i;
      rows.push([
        i, KIND_NAMES[kinds[i]] ?? kinds[i], patches[i],
        f(cl[k]), f(cl[k + 1]), f(cl[k + 2]),
        f(ax[k]), f(ax[k + 1]), f(ax[k + 2]),
        f(cc[k]), f(cc[k + 1]), f(cc[k + 2]),
      ].join(','));
    }
    return { result: rows.join('\n') + '\n' };
  },
};

/** Answers one request. */
async function answer({ id, op, args }) {
  try {
    if (!ops[op]) throw new Error(`unknown request ${op}`);
    const { result, transfer = [] } = await ops[op](...(args || []), id);
    postMessage({ id, ok: true, result }, transfer);
  } catch (err) {
    postMessage({ id, ok: false, error: err && err.message ? err.message : String(err) });
  }
}

// One at a time: `upgrade` waits for the planner's instantiation, and a request coming
// meanwhile must find the engine it was sent for.
let queue = Promise.resolve();
self.onmessage = (e) => {
  queue = queue.then(() => answer(e.data));
};
