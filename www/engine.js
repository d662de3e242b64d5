// The only importer of the generated wasm packages. Everything else talks to the engine
// through these functions (in practice only worker.js, which owns the engine), so the packages
// can be rebuilt or moved without touching the page.
//
// The engine comes in two modules built from the same crate (scripts/build-wasm): the viewer
// (www/pkg-view: load, place, tessellate, export; the machines and dialects by name), which is
// all the first draw waits for, and the planner (www/pkg: the viewer's API and planning,
// posting and the cutting simulation), fetched once a model is shown or planning is asked
// for. Handles of one module cannot be passed to the other: a model is loaded again into the
// planner (worker.js).
import initViewer, * as viewer from './pkg-view/tspath.js';

let viewerReady = null;
let plannerReady = null;

/** Instantiates the viewer module once: from `module` (a compiled WebAssembly.Module) when
 * given, else fetched and compiled here. */
export function loadViewer(module = null) {
  if (!viewerReady) viewerReady = initViewer(module ? { module_or_path: module } : undefined).then(() => viewer);
  return viewerReady;
}

/** Instantiates the planner module once (its glue imported on first use), as loadViewer. */
export function loadPlanner(module = null) {
  if (!plannerReady) {
    plannerReady = import('./pkg/tspath.js').then(async (planner) => {
      await planner.default(module ? { module_or_path: module } : undefined);
      return planner;
    });
  }
  return plannerReady;
}

/** What engine `w` offers: version, samples, machines (with their JSON), dialects. */
export function engineInfo(w) {
  return {
    version: w.version(),
    samples: w.sampleNames(),
    machines: w.machineNames().map((name) => ({ name, json: w.machineJson(name), reachTiltDeg: w.machineReachableTiltDeg(name) })),
    dialects: w.dialectNames(),
    verifySamples: w.planVerifySamples(),
    verifyMaxSamples: w.planVerifyMaxSamples(),
    paperLeadDeg: w.paperLeadDeg(),
  };
}

/** A model of engine `w` (a handle in its wasm memory; call free() when done) from `source`:
 * a built-in sample ({sample}) or file bytes ({bytes, name}), placed by `source.setup` if
 * given (see Model.fromBytesPlaced); throws an Error whose message says what is wrong with the
 * file. */
export function loadModel(w, source) {
  const { setup } = source;
  if (source.sample !== undefined) {
    return setup ? w.Model.samplePlaced(source.sample, setup) : w.Model.sample(source.sample);
  }
  const bytes = new Uint8Array(source.bytes);
  return setup ? w.Model.fromBytesPlaced(bytes, source.name, setup) : w.Model.fromBytes(bytes, source.name);
}
