// <tspath-planner>: the whole planner as one custom element. A page includes it with one
// script tag and writes, for example,
//
//   <script type="module" src="tspath-planner.js"></script>
//   <tspath-planner model="keycap-convex" scallop="0.01" plan></tspath-planner>
//
// Attributes: `model` (a built-in sample), every parameter of params.js by its key
// (`tool-radius`, `scallop`, `machine`, `dialect`, ...), `plan` (plan once the model is
// loaded) and `sync-url` (read the parameters from the page's URL and keep it up to date, so a
// link reproduces the plan). The engine runs in a Web Worker (worker.js, through client.js);
// this thread only draws and answers the user. The host's `data-state` says where it is:
// starting, loading, model-loaded, planning, planned or error; `data-verify` says whether
// the cutting simulation is running, done or failed.
import { CancelledError, EngineClient } from './client.js';
import { KINDS, PATCH_COLOURS, heatColour, hexCss, pathColour } from './colours.js';
import { bytes, deg, int, minutes, mm, ms, pct } from './format.js';
import { GROUPS, PARAMS, byKey, planOptions, validate } from './params.js';

/** Plans faster than this (ms, planning and posting) are redone on every change. */
const AUTO_REPLAN_MS = 1500;
/** Pause after the last change before an automatic re-plan (ms). */
const REPLAN_DELAY_MS = 300;
/** G-code lines shown around the current one. */
const LISTING_LINES = 13;
/** Largest model file accepted (bytes). */
const MAX_FILE_BYTES = 64 * 1048576;
const FILE_TYPES = ['.json', '.tsm', '.obj'];
const GCODE_EXT = { heidenhain: 'h', siemens: 'mpf' };

const TEMPLATE = `
<div class="app" part="app">
  <aside class="controls" aria-label="Model and parameters">
    <section class="model">
      <h2>Model</h2>
      <label for="sample">Built-in sample</label>
      <select id="sample"></select>
      <label for="file">Open a model file (.tsm, .obj, .json) — or drop it on the view</label>
      <input id="file" type="file" accept=".json,.tsm,.obj">
      <dl id="summary" class="facts" aria-label="Model summary"></dl>
      <div id="patch-legend" class="legend" aria-label="Patch colours"></div>
    </section>
    <form id="params" novalidate></form>
  </aside>
  <div class="stage">
    <div class="toolbar">
      <button id="plan" type="button" class="primary">Plan tool path</button>
      <button id="cancel" type="button" disabled>Cancel</button>
      <label class="inline" title="Re-plan after each change when planning takes under ${AUTO_REPLAN_MS / 1000} s">
        <input id="auto" type="checkbox" checked> Re-plan on change when fast</label>
      <progress id="progress" max="1" value="0" aria-label="Planning progress" hidden></progress>
      <p id="status" role="status" aria-live="polite">Starting the engine…</p>
    </div>
    <div class="viewport" id="viewport">
      <canvas id="view" tabindex="0"
        aria-label="3D view of the model and the tool path. Drag to orbit, right-drag or shift-drag to pan, wheel to zoom; arrow keys orbit, shift+arrows pan, + and - zoom, F fits"></canvas>
      <div id="drop-hint" class="drop-hint" hidden>Drop a .tsm, .obj or .json model to open it</div>
      <div id="heat-legend" class="heat-legend" hidden aria-label="Heat map colours"></div>
    </div>
    <div class="layers" role="group" aria-label="What the view shows">
      <span class="radio" role="radiogroup" aria-label="Surface colours">
        <label class="inline"><input type="radio" name="colour" id="colour-patches" value="patches" checked> Patches</label>
        <label class="inline"><input type="radio" name="colour" id="colour-heat" value="heat" disabled> Scallop heat map</label>
      </span>
      <label class="inline"><input type="checkbox" id="layer-path" checked> Path</label>
      <label class="inline"><input type="checkbox" id="layer-tool" checked> Tool</label>
      <label class="inline"><input type="checkbox" id="layer-cage"> Control mesh</label>
      <label class="inline"><input type="checkbox" id="layer-eps" checked> Extraordinary points</label>
      <button id="fit" type="button">Fit view</button>
    </div>
    <div class="scrub">
      <button id="play" type="button" disabled aria-pressed="false">Play</button>
      <label for="scrub">Tool position</label>
      <input id="scrub" type="range" min="0" max="0" value="0" step="1" disabled>
      <output id="tool-readout" for="scrub">no path yet</output>
    </div>
    <div id="path-legend" class="legend path-legend" aria-label="Path colours"></div>
  </div>
  <aside class="results" aria-label="Results">
    <section class="stats-section">
      <h2>Statistics</h2>
      <dl id="stats" class="facts"></dl>
      <ul id="notes" class="notes"></ul>
    </section>
    <section class="listing-section">
      <h2 id="listing-title">G-code</h2>
      <ol id="listing" class="listing" aria-labelledby="listing-title"></ol>
      <h2>Downloads</h2>
      <div class="downloads">
        <button id="download-gcode" type="button" disabled>G-code</button>
        <button id="download-csv" type="button" disabled>CL data (CSV)</button>
        <button id="download-stl" type="button" disabled>Surface (STL)</button>
      </div>
    </section>
  </aside>
</div>`;

/** Statistics rows: id, label, value from (report, verification, context). */
const STATS = [
  ['length_mm', 'Path length', (r) => mm(r.length_mm, 1)],
  ['cutting_length_mm', 'Cutting length', (r) => mm(r.cutting_length_mm, 1)],
  ['link_length_mm', 'Links on the surface', (r) => mm(r.link_length_mm, 1)],
  ['retractions', 'Retractions', (r) => int(r.retractions)],
  ['reversals', 'Reversals', (r) => int(r.reversals)],
  ['cl_points', 'CL points', (r) => int(r.cl_points)],
  ['patches', 'Patches cut', (r) => int(r.patches)],
  ['max_predicted_scallop_mm', 'Predicted max scallop', (r) => mm(r.max_predicted_scallop_mm, 4)],
  ['max_scallop_mm', 'Simulated max scallop', (r, v) => (v ? mm(v.max_scallop_mm, 4) : '…')],
  ['mean_scallop_mm', 'Simulated mean scallop', (r, v) => (v ? mm(v.mean_scallop_mm, 4) : '…')],
  ['uncut_fraction', 'Area above the scallop asked', (r, v) => (v ? pct(v.uncut_fraction) : '…')],
  ['unreached_fraction', 'Area the tool never reached', (r, v) => (v ? pct(v.unreached_fraction) : '…')],
  ['max_gouge_mm', 'Deepest gouge', (r, v) => (v ? mm(v.max_gouge_mm, 4) : '…')],
  ['gouge_count', 'Gouges beyond the chordal tolerance', (r, v) => (v ? `${int(v.gouge_count)} samples` : '…')],
  ['error_bound_mm', 'Simulation error bound', (r, v) => {
    if (!v) return '…';
    return Number.isFinite(v.error_bound_mm) ? mm(v.error_bound_mm, 4) : 'not bounded';
  }],
  ['max_axis_step_deg', 'Largest tool-axis step', (r) => deg(r.max_axis_step_deg)],
  ['machining_time_min', 'Machining time', (r) => minutes(r.machining_time_min)],
  ['plan_ms', 'Planning time', (r) => ms(r.plan_ms)],
  ['verify_ms', 'Simulation time', (r, v, x) => (v ? ms(x.verify_ms) : '…')],
  ['samples', 'Simulation samples', (r, v) => (v ? int(v.samples) : '…')],
];
/** Raw value of a statistic (for data-value), where it has one. */
function rawStat(id, r, v) {
  if (id in r) return r[id];
  if (v && id in v) return v[id];
  return '';
}

function download(name, data, type) {
  const blob = data instanceof Blob ? data : new Blob([data], { type });
  const a = document.createElement('a');
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.style.display = 'none';
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}

export class TspathPlanner extends HTMLElement {
  static get observedAttributes() {
    return ['model', ...PARAMS.map((p) => p.key)];
  }

  constructor() {
    super();
    this.root = this.attachShadow({ mode: 'open' });
    const css = document.createElement('link');
    css.rel = 'stylesheet';
    css.href = new URL('./planner.css', import.meta.url).href;
    this.root.append(css);
    const box = document.createElement('div');
    box.innerHTML = TEMPLATE;
    this.root.append(...box.childNodes);
    this.$ = (id) => this.root.getElementById(id);
    this.started = false;
  }

  connectedCallback() {
    if (this.started) return;
    this.started = true;
    this.t0 = performance.now();
    this.#start();
  }

  attributeChangedCallback(name, old, value) {
    if (!this.ready || old === value) return;
    if (name === 'model') {
      if (value && value !== this.$('sample').value) this.#loadSample(value);
      return;
    }
    const el = this.$(`p-${name}`);
    if (!el) return;
    el.value = value ?? '';
    this.#onParamChange(name);
  }

  set state(s) {
    this.dataset.state = s;
  }

  get state() {
    return this.dataset.state;
  }

  #status(text, isError = false) {
    const el = this.$('status');
    el.textContent = text;
    el.classList.toggle('error', isError);
  }

  // ---------------------------------------------------------------- start

  async #start() {
    this.state = 'starting';
    this.client = new EngineClient();
    const viewReady = this.#createView();
    this.#buildParams();
    this.#bindUi();
    let info;
    try {
      [info] = await Promise.all([this.client.ready, viewReady]);
    } catch (e) {
      this.state = 'error';
      this.#status(`The engine failed to start: ${e.message}`, true);
      return;
    }
    this.info = info;
    this.machineRotaries = Object.fromEntries(info.machines.map((m) => {
      const j = JSON.parse(m.json);
      return [m.name, { rotaries: j.rotaries.length, description: j.description || '' }];
    }));
    this.#fillChoice('machine', info.machines.map((m) => [m.name, `${m.name}${this.machineRotaries[m.name].rotaries ? ' (five-axis)' : ''}`]));
    this.#fillChoice('dialect', info.dialects.map((d) => [d, d]));
    for (const n of info.samples) this.$('sample').append(new Option(n, n));

    // Initial values: attributes, then the URL if synced.
    const initial = {};
    for (const a of this.getAttributeNames()) initial[a] = this.getAttribute(a);
    if (this.hasAttribute('sync-url')) {
      for (const [k, v] of new URLSearchParams(location.search)) initial[k] = v;
    }
    for (const p of PARAMS) {
      if (initial[p.key] !== undefined && initial[p.key] !== null) this.$(`p-${p.key}`).value = initial[p.key];
    }
    // Patch choices exist once the model is loaded.
    this.pendingPatches = { 'start-patch': initial['start-patch'], 'finish-patch': initial['finish-patch'] };
    this.#updateMachineControls();
    this.ready = true;
    this.#validateAll();
    const model = initial.model || info.samples[0];
    const loaded = await this.#loadSample(model);
    const planFlag = initial.plan;
    if (loaded && planFlag !== undefined && planFlag !== null && planFlag !== '0' && planFlag !== 'false') {
      this.#plan();
    }
  }

  async #createView() {
    const canvas = this.$('view');
    const probe = document.createElement('canvas');
    let webgl = false;
    try {
      webgl = !!(probe.getContext('webgl2') || probe.getContext('webgl'));
    } catch {
      webgl = false;
    }
    if (webgl) {
      try {
        const { View3D } = await import('./view3d.js');
        this.view = new View3D(canvas);
      } catch (e) {
        console.warn('WebGL view failed, using the 2D view:', e);
        this.view = null;
      }
    }
    if (!this.view) {
      const { View2D } = await import('./view2d.js');
      this.view = new View2D(canvas);
    }
    this.dataset.renderer = this.view.kind;
  }

  #buildParams() {
    const form = this.$('params');
    for (const [group, title] of GROUPS) {
      const details = document.createElement('details');
      details.id = `group-${group}`;
      if (group === 'accuracy' || group === 'tool' || group === 'output') details.open = true;
      const summary = document.createElement('summary');
      summary.textContent = title;
      details.append(summary);
      for (const p of PARAMS.filter((q) => q.group === group)) {
        const id = `p-${p.key}`;
        const row = document.createElement('div');
        row.className = 'param';
        const label = document.createElement('label');
        label.htmlFor = id;
        label.textContent = p.unit ? `${p.label} (${p.unit})` : p.label;
        let control;
        if (p.kind === 'number') {
          control = document.createElement('input');
          control.type = 'number';
          control.min = p.min;
          control.max = p.max;
          control.step = 'any';
          control.inputMode = 'decimal';
          if (p.default === null) {
            control.placeholder = `auto: ${p.auto}`;
          } else {
            control.value = p.default;
          }
        } else {
          control = document.createElement('select');
          if (p.kind === 'patch') control.append(new Option(`auto (${p.auto})`, ''));
          for (const [v, text] of p.choices || []) control.append(new Option(text, v));
          control.value = p.default ?? '';
        }
        control.id = id;
        control.name = p.key;
        const err = document.createElement('span');
        err.className = 'field-error';
        err.id = `${id}-error`;
        err.setAttribute('aria-live', 'polite');
        control.setAttribute('aria-describedby', err.id);
        row.append(label, control, err);
        details.append(row);
      }
      form.append(details);
    }
  }

  #fillChoice(key, choices) {
    const el = this.$(`p-${key}`);
    const current = el.value || byKey[key].default;
    el.replaceChildren(...choices.map(([v, t]) => new Option(t, v)));
    el.value = choices.some(([v]) => v === current) ? current : byKey[key].default;
  }

  #bindUi() {
    const $ = this.$;
    $('plan').addEventListener('click', () => this.#plan());
    $('cancel').addEventListener('click', () => this.#cancel());
    $('sample').addEventListener('change', () => this.#loadSample($('sample').value));
    $('file').addEventListener('change', () => {
      const f = $('file').files[0];
      if (f) this.#openFile(f);
      $('file').value = '';
    });
    $('params').addEventListener('change', (e) => this.#onParamChange(e.target.name));
    $('params').addEventListener('submit', (e) => e.preventDefault());
    $('fit').addEventListener('click', () => this.view && this.view.fit());
    for (const k of ['path', 'tool', 'cage', 'eps']) {
      $(`layer-${k}`).addEventListener('change', () => this.view.setLayers({ [k]: $(`layer-${k}`).checked }));
    }
    for (const id of ['colour-patches', 'colour-heat']) $(id).addEventListener('change', () => this.#showColours());
    $('scrub').addEventListener('input', () => this.#scrubTo(Number($('scrub').value)));
    $('play').addEventListener('click', () => this.#togglePlay());
    $('download-gcode').addEventListener('click', () => this.#downloadGcode());
    $('download-csv').addEventListener('click', () => this.#downloadCsv());
    $('download-stl').addEventListener('click', () => this.#downloadStl());
    // Drag and drop anywhere on the element.
    let depth = 0;
    this.addEventListener('dragenter', (e) => {
      if (![...(e.dataTransfer?.types || [])].includes('Files')) return;
      depth++;
      $('drop-hint').hidden = false;
    });
    this.addEventListener('dragleave', () => {
      depth = Math.max(0, depth - 1);
      if (!depth) $('drop-hint').hidden = true;
    });
    this.addEventListener('dragover', (e) => e.preventDefault());
    this.addEventListener('drop', (e) => {
      e.preventDefault();
      depth = 0;
      $('drop-hint').hidden = true;
      const f = e.dataTransfer?.files?.[0];
      if (f) this.#openFile(f);
    });
    this.#pathLegend();
  }

  // ---------------------------------------------------------------- models

  async #loadSample(name) {
    if (this.info && !this.info.samples.includes(name)) {
      this.#status(`There is no sample “${name}”; the samples are ${this.info.samples.join(', ')}.`, true);
      if (!this.model) this.state = 'error';
      return false;
    }
    return this.#load({ sample: name }, name);
  }

  async #openFile(file) {
    const ext = (file.name.match(/\.[^.]*$/) || [''])[0].toLowerCase();
    if (file.size > MAX_FILE_BYTES) {
      this.#status(`Could not open ${file.name}: it is ${bytes(file.size)}, more than the ${bytes(MAX_FILE_BYTES)} this page reads.`, true);
      return false;
    }
    if (!FILE_TYPES.includes(ext)) {
      this.#status(`Could not open ${file.name}: the page reads ${FILE_TYPES.join(', ')} files.`, true);
      return false;
    }
    const buf = await file.arrayBuffer();
    const stem = file.name.replace(/\.[^.]*$/, '');
    return this.#load({ bytes: buf, name: stem }, file.name);
  }

  async #load(source, label) {
    if (this.planning || this.dataset.verify === 'running') this.#cancel(true);
    this.state = 'loading';
    this.#status(`Loading ${label}…`);
    let m;
    try {
      m = await this.client.load(source);
    } catch (e) {
      this.state = this.model ? (this.plan ? 'planned' : 'model-loaded') : 'error';
      this.#status(`Could not open ${label}: ${e.message}`, true);
      if (this.model) this.$('sample').value = this.model.sample ?? '';
      return false;
    }
    this.model = { ...m, sample: source.sample ?? null, file: source.sample ? null : label };
    this.#clearPlan();
    this.$('colour-patches').checked = true;
    this.$('sample').value = source.sample ?? '';
    this.#showSummary(m.summary);
    this.#fillPatchChoices(m.summary.patches);
    this.view.setModel(m);
    this.#showColours();
    this.view.renderNow();
    if (this.dataset.firstDrawMs === undefined) {
      this.dataset.firstDrawMs = String(Math.round(performance.now() - this.t0));
    }
    this.$('download-stl').disabled = false;
    this.state = 'model-loaded';
    this.dataset.model = m.summary.name;
    this.dataset.meshChordalMm = String(m.chordal_mm);
    this.#status(`Loaded ${m.summary.name}: ${m.summary.patches} patches. Choose parameters and plan.`);
    this.#validateAll();
    this.#syncUrl();
    return true;
  }

  #showSummary(s) {
    const size = s.bbox_mm.max.map((v, k) => v - s.bbox_mm.min[k]);
    const rows = [
      ['Name', s.name],
      ['Format', s.format + (s.units_read && s.units_read !== 'mm' ? ` (${s.units_read})` : '')],
      ['Size (mm)', size.map((v) => v.toFixed(v < 10 ? 2 : 1)).join(' × ')],
      ['Faces', int(s.faces)],
      ['Control points', int(s.control_points)],
      ['Patches', int(s.patches)],
      ['Extraordinary points', int(s.extraordinary_points)],
      ['T-junctions', int(s.t_junctions)],
      ['Holes', int(s.holes)],
    ];
    this.#facts(this.$('summary'), rows.map(([k, v]) => [k.toLowerCase().replace(/\W+/g, '-'), k, v]));
    const legend = this.$('patch-legend');
    legend.replaceChildren();
    if (s.patches <= 40) {
      for (let i = 0; i < s.patches; i++) {
        const sw = document.createElement('span');
        sw.className = 'swatch';
        sw.style.setProperty('--c', hexCss(PATCH_COLOURS[i % PATCH_COLOURS.length]));
        sw.textContent = `patch ${i}`;
        legend.append(sw);
      }
    }
  }

  #facts(dl, rows) {
    dl.replaceChildren();
    for (const [id, label, text, raw] of rows) {
      const dt = document.createElement('dt');
      dt.textContent = label;
      const dd = document.createElement('dd');
      dd.id = `${dl.id}-${id}`;
      dd.textContent = text;
      if (raw !== undefined && raw !== '') dd.dataset.value = String(raw);
      dl.append(dt, dd);
    }
  }

  #fillPatchChoices(n) {
    for (const key of ['start-patch', 'finish-patch']) {
      const el = this.$(`p-${key}`);
      const wanted = this.pendingPatches?.[key] ?? ''; // a new model's patches are not the old one's
      el.replaceChildren(new Option(`auto (${byKey[key].auto})`, ''));
      for (let i = 0; i < n; i++) el.append(new Option(`patch ${i}`, String(i)));
      el.value = wanted !== '' && Number(wanted) < n ? String(wanted) : '';
    }
    this.pendingPatches = null;
  }

  // ---------------------------------------------------------------- parameters

  #raw() {
    const raw = {};
    for (const p of PARAMS) raw[p.key] = this.$(`p-${p.key}`).value;
    return raw;
  }

  get #fiveAxis() {
    const m = this.$('p-machine').value;
    return !!(this.machineRotaries && this.machineRotaries[m] && this.machineRotaries[m].rotaries);
  }

  #updateMachineControls() {
    const five = this.#fiveAxis;
    for (const p of PARAMS.filter((q) => q.fiveAxis)) {
      const el = this.$(`p-${p.key}`);
      el.disabled = !five;
      el.title = five ? '' : 'Needs a five-axis machine: a three-axis machine keeps the tool axis at +Z';
    }
    const m = this.machineRotaries?.[this.$('p-machine').value];
    this.$('p-machine').title = m ? m.description : '';
  }

  /** Validates every field; marks the wrong ones and returns the values (null if wrong). */
  #validateAll() {
    const { values, errors } = validate(this.#raw(), {
      patches: this.model ? this.model.summary.patches : 1,
      fiveAxis: this.#fiveAxis,
    });
    for (const p of PARAMS) {
      const el = this.$(`p-${p.key}`);
      const msg = errors[p.key] || '';
      el.setAttribute('aria-invalid', msg ? 'true' : 'false');
      this.$(`p-${p.key}-error`).textContent = msg;
      if (msg) el.closest('details').open = true;
    }
    const list = Object.values(errors);
    this.$('plan').disabled = list.length > 0 || !this.model || this.planning;
    return list.length ? { errors: list } : { values };
  }

  #onParamChange(key) {
    if (key === 'machine') this.#updateMachineControls();
    const v = this.#validateAll();
    this.#syncUrl();
    if (v.errors) {
      this.#status(v.errors[0], true);
      return;
    }
    if (!this.plan && !this.planning) {
      this.#status('Ready to plan.');
      return;
    }
    const opts = this.#planOptions(v.values);
    const samePlan = this.plan && JSON.stringify(opts) === JSON.stringify(this.plan.options);
    if (samePlan && (key === 'dialect' || key === 'units' || key === 'machine')) {
      this.#post();
      return;
    }
    if (samePlan && key === 'samples') {
      this.#verify();
      return;
    }
    if (samePlan) return;
    if (this.planning) {
      this.replanAfter = true;
      return;
    }
    this.#markStale(true);
    const fast = this.lastPlanMs !== undefined && this.lastPlanMs < AUTO_REPLAN_MS;
    if (this.$('auto').checked && fast) {
      clearTimeout(this.replanTimer);
      this.replanTimer = setTimeout(() => this.#plan(), REPLAN_DELAY_MS);
      this.#status('Parameters changed: re-planning…');
    } else {
      this.#status('Parameters changed: press “Plan tool path” to plan again.');
    }
  }

  #planOptions(values) {
    return planOptions(values, { fiveAxis: this.#fiveAxis });
  }

  #markStale(stale) {
    this.$('stats').classList.toggle('stale', stale);
    this.toggleAttribute('data-stale', stale);
  }

  // ---------------------------------------------------------------- planning

  async #plan() {
    clearTimeout(this.replanTimer);
    if (!this.model) return;
    const v = this.#validateAll();
    if (v.errors) {
      this.#status(v.errors[0], true);
      return;
    }
    if (this.planning) {
      this.replanAfter = true;
      return;
    }
    const options = this.#planOptions(v.values);
    const post = { machine: v.values.machine, dialect: v.values.dialect, units: v.values.units };
    const token = (this.planToken = (this.planToken || 0) + 1);
    this.planning = true;
    this.replanAfter = false;
    this.#stopPlay();
    this.state = 'planning';
    this.$('plan').disabled = true;
    this.$('cancel').disabled = false;
    const bar = this.$('progress');
    bar.hidden = false;
    bar.value = 0;
    this.#status('Planning… 0 %');
    const t0 = performance.now();
    let result;
    try {
      result = await this.client.call('plan', [options], (f) => {
        if (token !== this.planToken) return;
        bar.value = f;
        this.#status(`Planning… ${Math.round(100 * f)} %`);
      });
    } catch (e) {
      if (token !== this.planToken) return;
      this.#endPlanning();
      if (e instanceof CancelledError) return;
      this.state = this.plan ? 'planned' : 'model-loaded';
      this.#status(`Could not plan: ${e.message}`, true);
      this.#markField(e.message);
      return;
    }
    if (token !== this.planToken) return;
    this.#clearPlan();
    this.plan = { ...result, options, values: v.values, workerHasPlan: true };
    this.view.setPath(result);
    this.#showTool(v.values);
    const n = result.kinds.length;
    const scrub = this.$('scrub');
    scrub.max = String(Math.max(0, n - 1));
    scrub.value = '0';
    scrub.disabled = n === 0;
    this.$('play').disabled = n === 0;
    this.$('download-csv').disabled = false;
    this.#showStats();
    this.#markStale(false);
    this.#endPlanning();
    this.state = 'planned';
    this.dataset.verify = 'pending';
    const r = result.report;
    this.#status(`Planned ${int(r.cl_points)} CL points in ${ms(r.plan_ms)}.`);
    await this.#post();
    this.lastPlanMs = performance.now() - t0;
    this.dataset.plans = String(Number(this.dataset.plans || 0) + 1);
    this.#scrubTo(0);
    this.#syncUrl();
    if (this.replanAfter) {
      this.replanAfter = false;
      this.#plan();
      return;
    }
    this.#verify();
  }

  #endPlanning() {
    this.planning = false;
    this.$('cancel').disabled = true;
    this.$('progress').hidden = true;
    this.#validateAll();
  }

  /** Marks the field an engine error names (`scallop_mm`, ...). */
  #markField(message) {
    const p = PARAMS.find((q) => q.field && message.includes(q.field));
    if (!p) return;
    const el = this.$(`p-${p.key}`);
    el.setAttribute('aria-invalid', 'true');
    this.$(`p-${p.key}-error`).textContent = message;
    el.closest('details').open = true;
  }

  /** Stops planning (or the simulation) now. `quiet`: no status message. */
  #cancel(quiet = false) {
    const t0 = performance.now();
    const wasPlanning = this.planning;
    this.planToken = (this.planToken || 0) + 1;
    this.verifyToken = (this.verifyToken || 0) + 1;
    this.client.cancel();
    if (this.plan) this.plan.workerHasPlan = false;
    if (wasPlanning) {
      this.#endPlanning();
      this.state = this.plan ? 'planned' : 'model-loaded';
      if (!quiet) this.#status('Planning cancelled.');
    } else if (this.dataset.verify === 'running') {
      this.dataset.verify = 'cancelled';
      this.$('cancel').disabled = true;
      if (!quiet) this.#status('Simulation cancelled.');
    }
    this.dataset.cancelMs = String(Math.round(performance.now() - t0));
  }

  /** Makes sure the worker holds the shown plan (a cancel restarts it without), by planning
   * the same options again (deterministic: the same path). */
  async #ensureWorkerPlan() {
    if (!this.plan || this.plan.workerHasPlan) return true;
    this.#status('Restoring the plan in the engine…');
    try {
      await this.client.call('plan', [this.plan.options]);
      this.plan.workerHasPlan = true;
      return true;
    } catch (e) {
      this.#status(`Could not restore the plan: ${e.message}`, true);
      return false;
    }
  }

  async #post() {
    if (!this.plan) return;
    const plan = this.plan;
    const values = this.#validateAll().values;
    if (!values) return;
    const { machine, dialect, units } = values;
    this.$('download-gcode').disabled = true;
    this.$('download-gcode').textContent = 'G-code';
    if (!(await this.#ensureWorkerPlan())) return;
    try {
      const g = await this.client.call('post', [machine, dialect, units]);
      if (plan !== this.plan) return;
      plan.gcode = { ...g, machine, dialect, units, lineStarts: null, lineCount: 0 };
      this.#indexLines(plan.gcode);
      this.$('download-gcode').disabled = false;
      this.$('download-gcode').textContent = `G-code (${dialect}, ${units})`;
      this.$('listing-title').textContent = `G-code: ${machine}, ${dialect}, ${units}`;
      this.$('p-machine').removeAttribute('aria-invalid');
      this.$('p-dialect').removeAttribute('aria-invalid');
      this.#scrubTo(Number(this.$('scrub').value));
      if (this.$('status').classList.contains('error')) this.#status('Program written.');
    } catch (e) {
      if (e instanceof CancelledError || plan !== this.plan) return;
      plan.gcode = null;
      this.$('listing').replaceChildren();
      this.$('listing-title').textContent = 'G-code';
      this.#status(`Could not write the program for ${machine} in ${dialect}: ${e.message}`, true);
    }
  }

  /** Where each line of the program starts, for showing a window of it. */
  #indexLines(g) {
    const starts = [0];
    const t = g.text;
    for (let i = t.indexOf('\n'); i >= 0 && i < t.length - 1; i = t.indexOf('\n', i + 1)) starts.push(i + 1);
    g.lineStarts = starts;
    g.lineCount = starts.length;
  }

  #lineText(g, line) {
    const a = g.lineStarts[line - 1];
    const b = line < g.lineCount ? g.lineStarts[line] - 1 : g.text.length;
    return g.text.slice(a, b).replace(/\n$/, '');
  }

  async #verify() {
    if (!this.plan) return;
    const plan = this.plan;
    const values = this.#validateAll().values;
    if (!values) return;
    const token = (this.verifyToken = (this.verifyToken || 0) + 1);
    this.dataset.verify = 'running';
    this.$('cancel').disabled = false;
    this.$('colour-heat').disabled = true;
    plan.verification = null;
    this.#showStats();
    if (!(await this.#ensureWorkerPlan())) return;
    const base = this.$('status').textContent;
    this.#status(`${base} Simulating the cut…`);
    try {
      const v = await this.client.call('verify', [{ samples: values.samples }]);
      if (token !== this.verifyToken || plan !== this.plan) return;
      plan.verification = v;
      this.dataset.verify = 'done';
      this.$('colour-heat').disabled = false;
      this.#showStats();
      this.#showColours();
      this.#status(`${base} Simulated max scallop ${mm(v.summary.max_scallop_mm, 4)}.`);
    } catch (e) {
      if (token !== this.verifyToken || e instanceof CancelledError) return;
      this.dataset.verify = 'error';
      this.#status(`The cutting simulation failed: ${e.message}`, true);
    } finally {
      if (token === this.verifyToken && !this.planning) this.$('cancel').disabled = true;
    }
  }

  #clearPlan() {
    this.plan = null;
    this.#stopPlay();
    if (this.view) {
      this.view.setPath(null);
      this.view.setTool(null);
      this.view.setHeat(null);
    }
    this.$('colour-heat').disabled = true;
    this.$('scrub').disabled = true;
    this.$('scrub').max = '0';
    this.$('play').disabled = true;
    this.$('tool-readout').textContent = 'no path yet';
    this.$('listing').replaceChildren();
    this.$('listing-title').textContent = 'G-code';
    this.$('download-gcode').disabled = true;
    this.$('download-gcode').textContent = 'G-code';
    this.$('download-csv').disabled = true;
    this.$('stats').replaceChildren();
    this.$('notes').replaceChildren();
    this.$('heat-legend').hidden = true;
    delete this.dataset.verify;
    this.#markStale(false);
  }

  #showStats() {
    const p = this.plan;
    if (!p) return;
    const r = p.report;
    const v = p.verification ? p.verification.summary : null;
    const rows = STATS.map(([id, label, f]) => [id, label, f(r, v, p.verification || {}), rawStat(id, r, v)]);
    const time = rows.find((x) => x[0] === 'machining_time_min');
    time[1] = `Machining time at ${int(p.options.feed_mm_min ?? 1000)} mm/min`;
    this.#facts(this.$('stats'), rows);
    const notes = this.$('notes');
    notes.replaceChildren(...(r.notes || []).map((t) => {
      const li = document.createElement('li');
      li.textContent = t;
      return li;
    }));
  }

  // ---------------------------------------------------------------- view

  #showColours() {
    const heat = this.$('colour-heat').checked && this.plan && this.plan.verification;
    if (heat) {
      this.view.setHeat(this.plan.verification.heat, this.plan.verification.summary.requested_scallop_mm);
      this.#heatLegend(this.plan.verification.summary.requested_scallop_mm);
    } else {
      this.view.setHeat(null);
      this.$('heat-legend').hidden = true;
    }
  }

  #heatLegend(h) {
    const el = this.$('heat-legend');
    const stops = [0, 0.25, 0.5, 0.75, 1].map((t) => hexCss(heatColour(t * h, h)));
    el.innerHTML = '';
    const bar = document.createElement('div');
    bar.className = 'bar';
    bar.style.background = `linear-gradient(to right, ${stops.join(', ')})`;
    const scale = document.createElement('div');
    scale.className = 'scale';
    scale.innerHTML = `<span>0</span><span>${(h / 2).toPrecision(2)}</span><span>${h} mm left</span>`;
    const keys = document.createElement('div');
    keys.className = 'keys';
    for (const [c, t] of [[heatColour(2 * h, h), `more than ${h} mm`], [heatColour(-1, h), 'gouge'], [heatColour(Infinity, h), 'not reached']]) {
      const s = document.createElement('span');
      s.className = 'swatch';
      s.style.setProperty('--c', hexCss(c));
      s.textContent = t;
      keys.append(s);
    }
    el.append(bar, scale, keys);
    el.hidden = false;
  }

  #pathLegend() {
    const el = this.$('path-legend');
    el.replaceChildren();
    for (const k of KINDS) {
      if (k.name === 'rapid') continue;
      const s = document.createElement('span');
      s.className = `swatch line${k.dashed ? ' dashed' : ''}`;
      s.style.setProperty('--c', hexCss(k.colour ?? pathColour(0)));
      s.textContent = k.name === 'retract' ? 'retraction and rapid' : k.label;
      el.append(s);
    }
  }

  #showTool(values) {
    const r = values['tool-radius'];
    this.toolSizes = {
      radius: r,
      shankRadius: values['shank-radius'] ?? r,
      fluteLength: values['flute-length'] ?? 4 * r,
      shankLength: values['shank-length'],
      holderRadius: values['holder-radius'],
      holderLength: values['holder-length'],
    };
  }

  #scrubTo(i) {
    const p = this.plan;
    if (!p || !p.kinds.length) return;
    i = Math.max(0, Math.min(p.kinds.length - 1, i | 0));
    const k = 3 * i;
    const centre = [p.cl[k], p.cl[k + 1], p.cl[k + 2]];
    const axis = [p.axes[k], p.axes[k + 1], p.axes[k + 2]];
    this.view.setTool({ ...this.toolSizes, centre, axis });
    const kind = KINDS[p.kinds[i]]?.name ?? p.kinds[i];
    this.$('tool-readout').textContent =
      `move ${int(i)} of ${int(p.kinds.length - 1)} · ${kind} · patch ${p.patchIds[i]} · ball centre ${centre.map((x) => x.toFixed(3)).join(', ')} mm`;
    this.dataset.move = String(i);
    this.#showListing(i);
  }

  #showListing(i) {
    const g = this.plan && this.plan.gcode;
    const ol = this.$('listing');
    if (!g) {
      ol.replaceChildren();
      return;
    }
    const line = g.lines[i] || 1;
    const first = Math.max(1, Math.min(line - Math.floor(LISTING_LINES / 2), g.lineCount - LISTING_LINES + 1));
    const last = Math.min(g.lineCount, first + LISTING_LINES - 1);
    ol.start = first;
    const items = [];
    for (let l = first; l <= last; l++) {
      const li = document.createElement('li');
      li.textContent = this.#lineText(g, l);
      li.value = l;
      if (l === line) {
        li.className = 'current';
        li.setAttribute('aria-current', 'true');
      }
      items.push(li);
    }
    ol.replaceChildren(...items);
    ol.dataset.line = String(line);
  }

  #togglePlay() {
    if (this.playing) {
      this.#stopPlay();
      return;
    }
    const p = this.plan;
    if (!p) return;
    this.playing = true;
    this.$('play').textContent = 'Pause';
    this.$('play').setAttribute('aria-pressed', 'true');
    const n = p.kinds.length;
    const perFrame = Math.max(1, Math.round(n / 900)); // about 15 s for the whole path
    const step = () => {
      if (!this.playing || p !== this.plan) return;
      let i = Number(this.$('scrub').value) + perFrame;
      if (i >= n - 1) {
        i = n - 1;
        this.#stopPlay();
      }
      this.$('scrub').value = String(i);
      this.#scrubTo(i);
      if (this.playing) this.playFrame = requestAnimationFrame(step);
    };
    if (Number(this.$('scrub').value) >= n - 1) this.$('scrub').value = '0';
    this.playFrame = requestAnimationFrame(step);
  }

  #stopPlay() {
    this.playing = false;
    cancelAnimationFrame(this.playFrame);
    this.$('play').textContent = 'Play';
    this.$('play').setAttribute('aria-pressed', 'false');
  }

  // ---------------------------------------------------------------- downloads and URL

  #baseName() {
    return (this.model?.summary.name || 'model').replace(/[^\w.-]+/g, '_');
  }

  #downloadGcode() {
    const g = this.plan && this.plan.gcode;
    if (!g) return;
    const ext = GCODE_EXT[g.dialect] || 'nc';
    download(`${this.#baseName()}-${g.dialect}.${ext}`, g.text, 'text/plain');
  }

  async #downloadCsv() {
    if (!this.plan || !(await this.#ensureWorkerPlan())) return;
    try {
      const csv = await this.client.call('csv');
      download(`${this.#baseName()}-cl.csv`, csv, 'text/csv');
    } catch (e) {
      if (!(e instanceof CancelledError)) this.#status(`Could not write the CL data: ${e.message}`, true);
    }
  }

  async #downloadStl() {
    try {
      const stl = await this.client.call('stl');
      download(`${this.#baseName()}.stl`, new Blob([stl], { type: 'model/stl' }));
    } catch (e) {
      if (!(e instanceof CancelledError)) this.#status(`Could not write the STL: ${e.message}`, true);
    }
  }

  /** With `sync-url`: the sample and every parameter not at its default, and `plan=1` once
   * planned, so the link opens the same plan. */
  #syncUrl() {
    if (!this.hasAttribute('sync-url') || !this.ready) return;
    const q = new URLSearchParams();
    if (this.model && this.model.sample) q.set('model', this.model.sample);
    const raw = this.#raw();
    for (const p of PARAMS) {
      const v = raw[p.key];
      const d = p.default === null ? '' : String(p.default);
      if (v !== '' && v !== d && !(p.kind === 'number' && Number(v) === Number(d) && d !== '')) q.set(p.key, v);
    }
    if (this.plan) q.set('plan', '1');
    const url = `${location.pathname}${q.toString() ? `?${q}` : ''}${location.hash}`;
    if (url !== `${location.pathname}${location.search}${location.hash}`) history.replaceState(null, '', url);
  }

  // ---------------------------------------------------------------- for tests

  /** Counts the view's pixels that are not background (renders first). */
  countPixels() {
    return this.view ? this.view.countPixels() : { drawn: 0, total: 0 };
  }

  /** Pixels of the view that differ by more than a little (sum of RGB differences over 24)
   * between now and after `change()` (a function that changes what is shown). */
  pixelsChangedBy(change) {
    const a = this.view.snapshot();
    change();
    const b = this.view.snapshot();
    let n = 0;
    for (let i = 0; i < a.length; i += 4) {
      if (Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]) > 24) n++;
    }
    return n;
  }

  /** Pixels a layer (`path`, `tool`, `cage`, `eps`) changes when shown (it is left as it was). */
  layerPixels(layer) {
    const on = this.view.layers[layer];
    const n = this.pixelsChangedBy(() => this.view.setLayers({ [layer]: !on }));
    this.view.setLayers({ [layer]: on });
    this.view.renderNow();
    return n;
  }
}

customElements.define('tspath-planner', TspathPlanner);
