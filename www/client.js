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

/** The engine's two wasm modules (see engine.js): the viewer, all the first draw needs, and
 * the planner. */
const VIEWER_URL = new URL('./pkg-view/tspath_bg.wasm', import.meta.url);
const PLANNER_URL = new URL('./pkg/tspath_bg.wasm', import.meta.url);

/** Requests only the planner answers: the client sends them once the worker has it. */
const PLANNER_OPS = new Set(['concave', 'plan', 'compare', 'pick', 'post', 'verify', 'csv']);

/** Each module fetched and compiled (streamed, off the page's thread) once per page and
 * handed to every worker: a worker started again after a Cancel neither fetches nor compiles
 * it. Resolves to null where the browser cannot (the worker then loads the wasm itself, and
 * says what failed). */
const compiled = new Map();
function compiledModule(url) {
  if (!compiled.has(url.href)) {
    compiled.set(url.href, typeof WebAssembly.compileStreaming === 'function'
      ? WebAssembly.compileStreaming(fetch(url)).catch(() => null)
      : Promise.resolve(null));
  }
  return compiled.get(url.href);
}

export class EngineClient {
  constructor() {
    this.workerUrl = new URL('./worker.js', import.meta.url);
    this.nextId = 1;
    this.pending = new Map(); // id -> {resolve, reject, onProgress}
    this.source = null; // what the current model was loaded from, to reload after a cancel
    this.info = null;
    this.planner = null; // resolves once the worker runs the planner module
    this.hasPlanner = false; // true from then on (until a cancel restarts the worker)
    this.plannerCompiled = false; // true once the planner module is compiled here
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
    // A worker started again after the planner was compiled starts on it.
    const onPlanner = this.plannerCompiled;
    this.hasPlanner = false;
    const started = compiledModule(onPlanner ? PLANNER_URL : VIEWER_URL)
      .then((module) => this.#send('init', [module, onPlanner]))
      .then((info) => {
        this.info = info;
        return info;
      });
    const ready = this.source
      ? started.then(async (info) => {
        await this.#send('load', [this.source]);
        return info;
      })
      : started;
    this.planner = onPlanner ? ready.then(() => { this.hasPlanner = true; }) : null;
    if (this.planner) this.planner.catch(() => {});
    return ready;
  }

  /** Resolves once the worker runs the planner module: fetched and compiled on the first
   * call, then handed to the worker, which loads the current model into it. Call it when the
   * model is shown, so planning does not wait for the download. */
  loadPlanner() {
    if (!this.planner) {
      const worker = this.worker;
      const planner = this.ready
        .then(() => compiledModule(PLANNER_URL))
        .then((module) => {
          // A Cancel meanwhile started another worker, which has its own way to the planner.
          if (this.worker !== worker) throw new CancelledError();
          if (module) this.plannerCompiled = true;
          return this.#send('upgrade', [module]);
        })
        .then(() => { this.hasPlanner = true; });
      this.planner = planner;
      // A failure (the download, say) is the caller's to show; the next call tries again.
      planner.catch(() => {
        if (this.planner === planner) this.planner = null;
      });
    }
    return this.planner;
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
    await (PLANNER_OPS.has(op) ? this.loadPlanner() : this.ready);
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
