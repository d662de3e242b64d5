// The page's side of the engine worker: requests as promises, progress callbacks, and cancel.
//
// A worker busy inside wasm cannot read messages, so cancel terminates it at once (the
// request's promise rejects with a CancelledError) and starts a fresh worker in the
// background, which loads the current model again; later requests wait for it.

export class CancelledError extends Error {
  constructor() {
    super('cancelled');
    this.name = 'CancelledError';
  }
}

/** The engine's wasm, fetched and compiled (streamed, off the page's thread) once per page
 * while the first worker starts, and handed to every worker: a worker started again after a
 * Cancel neither fetches nor compiles it. Resolves to null where the browser cannot (the
 * worker then loads the wasm itself, and says what failed). */
let compiled = null;
function compiledEngine() {
  if (!compiled) {
    const url = new URL('./pkg/tspath_bg.wasm', import.meta.url);
    compiled = typeof WebAssembly.compileStreaming === 'function'
      ? WebAssembly.compileStreaming(fetch(url)).catch(() => null)
      : Promise.resolve(null);
  }
  return compiled;
}

export class EngineClient {
  constructor() {
    this.workerUrl = new URL('./worker.js', import.meta.url);
    this.nextId = 1;
    this.pending = new Map(); // id -> {resolve, reject, onProgress}
    this.source = null; // what the current model was loaded from, to reload after a cancel
    this.info = null;
    this.ready = this.#start();
  }

  #start() {
    this.worker = new Worker(this.workerUrl, { type: 'module', name: 'tspath-engine' });
    this.worker.onmessage = (e) => this.#onMessage(e.data);
    this.worker.onerror = (e) => {
      const err = new Error(`the engine worker failed: ${e.message || 'could not start'}`);
      for (const p of this.pending.values()) p.reject(err);
      this.pending.clear();
    };
    const started = compiledEngine().then((module) => this.#send('init', [module])).then((info) => {
      this.info = info;
      return info;
    });
    return this.source
      ? started.then(async (info) => {
        await this.#send('load', [this.source]);
        return info;
      })
      : started;
  }

  #onMessage(msg) {
    const p = this.pending.get(msg.id);
    if (!p) return;
    if (msg.progress !== undefined) {
      if (p.onProgress) p.onProgress(msg.progress);
      return;
    }
    this.pending.delete(msg.id);
    if (msg.ok) p.resolve(msg.result);
    else p.reject(new Error(msg.error));
  }

  #send(op, args, onProgress, transfer = []) {
    const id = this.nextId++;
    return new Promise((resolve, reject) => {
      this.pending.set(id, { resolve, reject, onProgress });
      this.worker.postMessage({ id, op, args }, transfer);
    });
  }

  /** Runs `op` on the engine once it is ready. */
  async call(op, args = [], onProgress = null) {
    await this.ready;
    return this.#send(op, args, onProgress);
  }

  /** True while a request is running or queued. */
  get busy() {
    return this.pending.size > 0;
  }

  /** Loads a model; on success it becomes the one a restarted worker loads again. */
  async load(source) {
    const result = await this.call('load', [source]);
    this.source = source.bytes ? { bytes: source.bytes.slice(0), name: source.name } : source;
    return result;
  }

  /** Stops whatever the engine is doing now: terminates the worker, rejects what is
   * pending with CancelledError and starts a new worker with the current model. */
  cancel() {
    this.worker.terminate();
    const err = new CancelledError();
    for (const p of this.pending.values()) p.reject(err);
    this.pending.clear();
    this.ready = this.#start();
    this.ready.catch(() => {});
  }
}
