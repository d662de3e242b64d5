// The only importer of the generated wasm package. Everything else talks to the engine
// through these functions, so the package can be rebuilt or moved without touching the page.
import init, * as wasm from './pkg/tspath.js';

let ready = null;

/** Loads and instantiates the wasm module once. */
export function loadEngine() {
  if (!ready) ready = init().then(() => wasm);
  return ready;
}

/** Names of the built-in sample models. */
export async function sampleNames() {
  return (await loadEngine()).sampleNames();
}

/** The engine's version string. */
export async function version() {
  return (await loadEngine()).version();
}

/** A built-in sample model (a handle in wasm memory; call free() when done). */
export async function loadSample(name) {
  return (await loadEngine()).Model.sample(name);
}

/** A model from file bytes; throws an Error whose message says what is wrong with the file. */
export async function loadBytes(bytes, name) {
  return (await loadEngine()).Model.fromBytes(bytes, name);
}
