// The only importer of the generated wasm package. Everything else talks to the engine
// through these functions (in practice only worker.js, which owns the engine), so the package
// can be rebuilt or moved without touching the page.
import init, * as wasm from './pkg/tspath.js';

let ready = null;

/** Loads and instantiates the wasm module once: from `module` (a compiled
 * WebAssembly.Module) when given, else fetched and compiled here. */
export function loadEngine(module = null) {
  if (!ready) ready = init(module ? { module_or_path: module } : undefined).then(() => wasm);
  return ready;
}

/** What the engine offers: version, samples, machines (with their JSON), dialects. */
export async function engineInfo() {
  const w = await loadEngine();
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

/** A built-in sample model (a handle in wasm memory; call free() when done), placed by
 * `setup` if given (see Model.fromBytesPlaced). */
export async function loadSample(name, setup = null) {
  const w = await loadEngine();
  return setup ? w.Model.samplePlaced(name, setup) : w.Model.sample(name);
}

/** A model from file bytes, placed by `setup` if given; throws an Error whose message says
 * what is wrong with the file. */
export async function loadBytes(bytes, name, setup = null) {
  const w = await loadEngine();
  return setup ? w.Model.fromBytesPlaced(bytes, name, setup) : w.Model.fromBytes(bytes, name);
}
