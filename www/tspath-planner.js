// <tspath-planner>: the whole planner as one custom element. A page includes it with one
// script tag and writes, for example,
//
//   <script type="module" src="tspath-planner.js"></script>
//   <tspath-planner model="keycap-convex" scallop="0.01" plan></tspath-planner>
//
// Attributes: `model` (a built-in sample), every parameter of params.js by its key
// (`tool-radius`, `scallop`, `strategy`, `machine`, `dialect`, ...), `plan` (plan once the model is
// loaded) and `sync-url` (read the parameters from the page's URL and keep it up to date, so a
// link reproduces the plan). The engine runs in a Web Worker (worker.js, through client.js);
// this thread only draws and answers the user. The host's `data-state` says where it is:
// starting, loading, model-loaded, planning, planned or error; `data-status` what the shown
// plan's report says (`planned`, or `planned_with_problems` when it leaves something undone);
// `data-verify` whether the cutting simulation is running, done or failed; `data-stale`
// that the parameters no longer match the plan shown (its downloads are off);
// `data-plan-to-final-ms` the time from Plan to the final heat map of the last plan simulated.
import { GLOSSARY, markTerms } from './glossary.js';
import { JOB_SUFFIX, isJob, readJob, writeJob } from './job.js';
import { CancelledError, EngineClient } from './client.js';
import { loadLastFile, saveLastFile } from './storage.js';
import {
  BACKGROUND_LIGHT, ISFC_LAYER, KINDS, PATCH_COLOURS, RECT_LAYER, REST_REASONS, heatColour, hexCss, pathColour, tableGrid,
} from './colours.js';
import { area, bytes, deg, int, minutes, mm, mmSig, ms, pct, share } from './format.js';
import { GROUPS, PARAMS, byKey, flagOn, placement, planOptions, validate } from './params.js';

/** Plans faster than this (ms, from Plan to the path shown) are redone on every change. */
const AUTO_REPLAN_MS = 1500;
/** Pause after the last change before an automatic re-plan (ms). */
const REPLAN_DELAY_MS = 300;
/** Samples of the preview heat map shown while the simulation runs (at most a quarter of
 * what the simulation's first round samples). */
const PREVIEW_SAMPLES = 100000;
/** A simulation whose first round samples fewer than this shows no preview: its final heat
 * map comes about as soon as a preview would (the convex keycap at the defaults, 153 476
 * samples: 0.5 s in wasm on the test machine, of which a preview took 0.2 s more). */
const PREVIEW_WORTH_SAMPLES = 400000;
/** G-code lines shown around the current one. */
const LISTING_LINES = 13;
/** Patches listed one row each in the patch legend; beyond, one swatch per colour. */
const PATCH_LEGEND_ROWS = 40;
/** Values longer than this (characters) go on their own line under their label, per list
 * (the model panel is the narrower). */
const WIDE_VALUE_CHARS = { summary: 16, stats: 22 };
/** Largest model file accepted (bytes). */
const MAX_FILE_BYTES = 64 * 1048576;
const FILE_TYPES = ['.json', '.tsm', '.obj'];
const GCODE_EXT = { heidenhain: 'h', siemens: 'mpf' };
/** The simulation's error bound aimed for, as a share of the scallop: a quarter, as
 * `tspath plan --verify` (its VERIFY_BOUND_SHARE). */
const VERIFY_BOUND_SHARE = 0.25;

/** The public T-Splines files served beside the page (www/models/grapetec/, see SOURCE.md
 * there), offered next to the built-in samples; `?model=grapetec/Bike.tsm` opens one. */
const PUBLIC_SOURCE = {
  dir: 'grapetec',
  group: 'Public T-spline files (GrapeTec/T-SPLINE, LGPL-3.0)',
  repository: 'GrapeTec/T-SPLINE',
  url: 'https://github.com/GrapeTec/T-SPLINE',
  licence: 'LGPL-3.0',
  licenceFile: 'LICENSE.LGPL-3.0',
};
const PUBLIC_MODELS = [
  ['simple.tsm', 'a few faces'],
  ['mouse.tsm', 'computer-mouse shell'],
  ['face.tsm', 'face, creases'],
  ['Bike.tsm', 'bicycle seat'],
  ['fan.tsm', 'fan blade'],
  ['gearbox2-9.tsm', 'gearbox cover'],
].map(([file, what]) => ({ id: `${PUBLIC_SOURCE.dir}/${file}`, file, what }));
const publicModel = (name) => PUBLIC_MODELS.find((m) => m.id === name || m.file === name) || null;

/** Problem kinds of the report, as a short heading. */
const PROBLEM_KINDS = {
  rest_faces_away: 'Not machined: faces away',
  rest_tool_hits: 'Not machined: shank or holder would hit',
  rest_no_way_out: 'Not machined: no way in or out',
  rest_too_tight: 'Rest material: tighter than the ball',
  turn_margin: 'Turn within the safety margin',
  scallop: 'Scallop above the request',
  scallop_predicted: 'Scallop above the request (predicted)',
  gouge: 'Gouge',
  unproven: 'Not proven by the simulation',
  model_not_as_modelled: 'Surface not as modelled',
};

/** The comparison's rows as `tspath compare` names them, with the strategy control's value
 * each stands for and whether it is the iso-planar baseline (no deformation). */
const COMPARE_ROWS = {
  isoparametric: { strategy: 'isoparametric', label: 'Patch by patch (isoparametric)' },
  isfc: { strategy: 'isfc', label: 'One continuous pass (space-filling curve)' },
  watershed: { strategy: 'watershed', label: 'Feature regions in rectangles (watershed)' },
  'multi-rectangle': { strategy: 'multi-rectangle', label: 'Rectangles, one direction (multi-rectangle)' },
  isoplanar: { strategy: 'isoplanar', label: 'Parallel planes, deformed (iso-planar)' },
  'isoplanar-baseline': { strategy: 'isoplanar', baseline: true, label: 'Parallel planes, constant spacing (iso-planar baseline)' },
};

/** The comparison table's columns: the run's key (from its simulated cut where `sim`),
 * heading with unit, and the cell's text from the raw value. */
const COMPARE_COLUMNS = [
  ['cutting_length_mm', 'Cutting (mm)', (x) => x.toFixed(1)],
  ['link_length_mm', 'Links (mm)', (x) => x.toFixed(1)],
  ['air_length_mm', 'Air (mm)', (x) => x.toFixed(1)],
  ['retractions', 'Retractions', int],
  ['reversals', 'Reversals', int],
  ['cl_points', 'CL points', int],
  ['max_scallop_mm', 'Max scallop (mm)', (x) => x.toFixed(4), 'sim'],
  ['mean_scallop_mm', 'Mean scallop (mm)', (x) => x.toFixed(4), 'sim'],
  ['p95_scallop_mm', 'p95 scallop (mm)', (x) => x.toFixed(4), 'sim'],
  ['error_bound_mm', 'Simulation bound (mm)', (x) => x.toFixed(4), 'sim'],
  ['uncut_fraction', 'Uncut (%)', (x) => (100 * x).toFixed(2), 'sim'],
  ['gouges', 'Gouges', int, 'sim'],
  ['max_axis_step_deg', 'Largest axis step (°)', (x) => x.toFixed(2)],
  ['plan_ms', 'Plan (ms)', (x) => x.toFixed(0)],
  ['machining_time_min', 'Machining (min)', (x) => x.toFixed(2)],
  ['feed_time_min', 'Length ÷ feed (min)', (x) => x.toFixed(2)],
  ['efficiency', 'Cutting ÷ L_min', (x) => x.toFixed(3)],
  ['efficiency_flat', 'Cutting ÷ flat L_min', (x) => x.toFixed(3)],
];

/** The bar charts under the table: key, title with unit, decimals. */
const COMPARE_CHARTS = [
  ['machining_time_min', 'Machining time (min)', 2],
  ['cutting_length_mm', 'Cutting length (mm)', 0],
  ['reversals', 'Reversals', 0],
  ['max_scallop_mm', 'Max simulated scallop (mm)', 4],
];

/** A run's value for a column key (from its simulated cut where the column says so). */
const runValue = (run, key, fromSim) => (fromSim ? run.simulated?.[key] : run[key]);

/** How the URL names a file of the user's kept in the browser (`model=file:NAME`). */
const FILE_PREFIX = 'file:';

/** URL keys that are not parameters: the model, and whether to plan or compare. */
const URL_KEYS = ['model', 'plan', 'compare'];

/** The layers a plan of some strategies brings along (drawn without planning again), each
 * with its view setter, legend heading, box titles and legend rows (`[colour, text, filled]`). */
const OVERLAYS = {
  isfc: {
    setter: 'setIsfc',
    heading: 'Space-filling curve',
    title: 'The 2 × 2 cells of grid points and the tree that joins them into one pass',
    none: 'Only a space-filling-curve plan (strategy: one continuous pass) has cells and a tree',
    rows: (c) => {
      const nAcross = c.across.reduce((a, x) => a + x, 0);
      return [
        [ISFC_LAYER.cell, `${int(c.cells.length / 24)} cell outlines (grid lines between contact points)`],
        [ISFC_LAYER.tree, `${int(c.tree.length / 6 - nAcross)} tree links between cell centres`],
        [ISFC_LAYER.across, `${int(nAcross)} tree links across patch sides`],
      ];
    },
  },
  rects: {
    setter: 'setRects',
    heading: 'Regions and rectangles',
    title: 'The rectangles the surface was cut into, coloured by feature region, each with an arrow along its passes',
    none: 'Only the rectangle strategies (watershed, multi-rectangle) cut the surface into rectangles',
    rows: (r) => {
      const count = r.arrows.length / 18;
      const perRect = count ? r.kinds.length / count : 1;
      const byKind = RECT_LAYER.kinds.map(() => 0);
      for (const k of r.kinds) byKind[k]++;
      return [
        ...RECT_LAYER.kinds.map((k, i) => [k.colour, `${int(byKind[i] / perRect)} ${byKind[i] === perRect ? 'rectangle' : 'rectangles'} ${k.label}`, true]).filter((_, i) => byKind[i]),
        [RECT_LAYER.outline, `${int(count)} rectangle outlines`],
        [RECT_LAYER.arrow, 'arrows: the way the passes run in each'],
      ];
    },
  },
};

const TEMPLATE = `
<div class="app" part="app">
  <aside class="controls" aria-label="Model and parameters">
    <section class="model">
      <h2>Model</h2>
      <label for="sample">Built-in sample or public model</label>
      <select id="sample"></select>
      <label for="file">Open a model file (.tsm, .obj, .json) or a saved job — or drop it on the view</label>
      <input id="file" type="file" accept=".json,.tsm,.obj">
      <div class="job-buttons">
        <button id="save-job" type="button" disabled title="One file with the model and every parameter: open it again here, on any machine, for the same plan">Save job</button>
      </div>
      <dl id="summary" class="facts" aria-label="Model summary"></dl>
      <p id="concave-hint" class="hint"></p>
      <div id="patch-legend" class="legend" aria-label="Patch colours"></div>
    </section>
    <form id="params" novalidate></form>
  </aside>
  <div class="stage">
    <div class="toolbar">
      <button id="plan" type="button" class="primary" title="Plan (Ctrl+Enter); Escape cancels" aria-keyshortcuts="Control+Enter">Plan tool path</button>
      <button id="compare" type="button" title="Plan every strategy on this model with these settings, simulate each cut and put them side by side">Compare strategies</button>
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
    </div>
    <div class="view-legends">
      <div id="heat-legend" class="heat-legend" hidden aria-label="Heat map colours"></div>
      <div id="rest-legend" class="rest-legend" hidden aria-label="Rest area colours"></div>
      <div id="isfc-legend" class="overlay-legend" hidden aria-label="Cells and tree colours"></div>
      <div id="rects-legend" class="overlay-legend" hidden aria-label="Regions and rectangles colours"></div>
    </div>
    <div class="layers" role="group" aria-label="What the view shows">
      <span class="radio" role="radiogroup" aria-label="Surface colours">
        <label class="inline"><input type="radio" name="colour" id="colour-patches" value="patches" checked> Patches</label>
        <label class="inline"><input type="radio" name="colour" id="colour-heat" value="heat" disabled> Scallop heat map</label>
      </span>
      <label class="inline" title="What the plan leaves unmachined, coloured by why"><input type="checkbox" id="layer-rest" checked disabled> Rest area</label>
      <label class="inline" id="layer-isfc-label" title="${OVERLAYS.isfc.none}"><input type="checkbox" id="layer-isfc" disabled> Cells and tree</label>
      <label class="inline" id="layer-rects-label" title="${OVERLAYS.rects.none}"><input type="checkbox" id="layer-rects" disabled> Regions and rectangles</label>
      <label class="inline"><input type="checkbox" id="layer-path" checked> Path</label>
      <label class="inline"><input type="checkbox" id="layer-tool" checked> Tool</label>
      <label class="inline"><input type="checkbox" id="layer-cage"> Control mesh</label>
      <label class="inline"><input type="checkbox" id="layer-eps" checked> Extraordinary points</label>
      <label class="inline" title="The program's X0 Y0 Z0 in the work offset chosen (X red, Y green, Z blue), and the stock block (brown)"><input type="checkbox" id="layer-zero" checked> Program zero and stock</label>
      <label class="inline" id="layer-grid-label" title="A grid on the table (the stock's bottom), its spacing in the label"><input type="checkbox" id="layer-grid" checked> <span id="grid-text">Grid</span></label>
    </div>
    <div class="views" role="group" aria-label="Camera">
      <button id="fit" type="button">Fit view</button>
      <button type="button" data-view="top" title="Looking down -Z, X to the right">Top</button>
      <button type="button" data-view="front" title="Looking along +Y, X to the right, Z up">Front</button>
      <button type="button" data-view="side" title="Looking along -X, Y to the right, Z up">Side</button>
      <button type="button" data-view="iso" title="From the front left, above">Iso</button>
      <label class="inline" title="Parallel projection: true proportions, no perspective"><input type="checkbox" id="ortho"> Orthographic</label>
    </div>
    <div class="scrub">
      <button id="play" type="button" disabled aria-pressed="false">Play</button>
      <label for="scrub">Tool position</label>
      <input id="scrub" type="range" min="0" max="0" value="0" step="1" disabled>
      <output id="tool-readout" for="scrub">no path yet</output>
    </div>
    <div id="path-legend" class="legend path-legend" aria-label="Path colours"></div>
    <section id="compare-panel" class="compare-panel" hidden aria-labelledby="compare-title">
      <div class="compare-head">
        <h2 id="compare-title">Strategies compared</h2>
        <label class="inline" title="Simulate each strategy's cut until the error bound is a quarter of the scallop (as tspath compare does); off: plans only, much faster"><input type="checkbox" id="compare-simulate" checked> Simulate each cut</label>
        <button id="compare-csv" type="button" disabled>Download CSV</button>
        <button id="compare-close" type="button">Close</button>
      </div>
      <p id="compare-summary" class="hint"></p>
      <div class="compare-table-wrap"><table id="compare-table" aria-describedby="compare-summary"></table></div>
      <div id="compare-charts" class="compare-charts" aria-label="Bar charts of the comparison"></div>
      <div id="compare-thumbs" class="compare-thumbs" aria-label="Each strategy's path, seen from above"></div>
    </section>
  </div>
  <aside class="results" aria-label="Results">
    <section class="stats-section" id="stats-section">
      <h2>Statistics</h2>
      <p id="stale-note" class="stale-note" hidden>The parameters changed: these results are for the plan drawn, made with the previous ones. Plan again to download.</p>
      <div id="problems-box" class="problems-box" hidden>
        <h3 id="problems-title">Problems</h3>
        <ul id="problems" class="problems" aria-labelledby="problems-title"></ul>
      </div>
      <p id="stats-empty" class="placeholder">Plan a tool path: its lengths, retractions, scallop, machining time and any problems appear here.</p>
      <dl id="stats" class="facts"></dl>
      <ul id="notes" class="notes" aria-label="Notes"></ul>
    </section>
    <section class="listing-section">
      <h2 id="listing-title">G-code</h2>
      <p id="listing-empty" class="placeholder">The program appears here once planned, the block of the tool's position highlighted.</p>
      <ol id="listing" class="listing" aria-labelledby="listing-title" tabindex="0"></ol>
      <h2>Downloads</h2>
      <div class="downloads">
        <button id="download-gcode" type="button" disabled>G-code</button>
        <button id="download-csv" type="button" disabled>CL data (CSV)</button>
        <button id="download-stl" type="button" disabled>Surface (STL)</button>
      </div>
    </section>
    <details class="glossary-section">
      <summary>Glossary</summary>
      <dl id="glossary" class="glossary"></dl>
    </details>
  </aside>
</div>`;

/** The strategies as the statistics name them. */
const STRATEGY_NAMES = {
  isoparametric: 'patch by patch (isoparametric)',
  isfc: 'one continuous pass (space-filling curve)',
  watershed: 'feature regions in rectangles (watershed)',
  'multi-rectangle': 'rectangles, one direction (multi-rectangle)',
  isoplanar: 'parallel planes (iso-planar)',
};

/** Statistics rows: id, label, value from (report, verification summary, context); the
 * context has `verify_ms`, `area_mm2` (the model's) and `samples` (the simulation's start). */
const STATS = [
  ['strategy', 'Strategy', (r, v, x) => `${STRATEGY_NAMES[r.strategy] ?? r.strategy}${x.plain ? ', plain curve (no repairs)' : ''}`],
  ['length_mm', 'Path length', (r) => mm(r.length_mm, 1)],
  ['cutting_length_mm', 'Cutting length', (r) => mm(r.cutting_length_mm, 1)],
  ['link_length_mm', 'Links on the surface', (r) => mm(r.link_length_mm, 1)],
  ['retractions', 'Retractions', (r) => int(r.retractions)],
  ['reversals', 'Reversals', (r) => int(r.reversals)],
  ['cl_points', 'CL points', (r) => int(r.cl_points)],
  ['patches', 'Patches cut', (r) => int(r.patches)],
  ['unreachable_area_mm2', 'Area not machined', (r, v, x) => {
    const a = r.unreachable_area_mm2;
    if (!(a > 0)) return '0 mm²';
    return `${area(a)} (${share(a, x.area_mm2)} of ${area(x.area_mm2)})`;
  }],
  ['max_predicted_scallop_mm', 'Predicted max scallop', (r) => mm(r.max_predicted_scallop_mm, 4)],
  ['max_scallop_mm', 'Simulated max scallop', (r, v) => (v ? mm(v.max_scallop_mm, 4) : '…')],
  ['mean_scallop_mm', 'Simulated mean scallop', (r, v) => (v ? mm(v.mean_scallop_mm, 4) : '…')],
  ['uncut_fraction', 'Area above the scallop asked', (r, v) => (v ? pct(v.uncut_fraction) : '…')],
  ['unreached_fraction', 'Area the tool never reached', (r, v) => (v ? pct(v.unreached_fraction) : '…')],
  ['max_gouge_mm', 'Deepest gouge', (r, v) => (v ? mm(v.max_gouge_mm, 4) : '…')],
  ['gouge_count', 'Gouges beyond the gouge tolerance', (r, v) => (v ? `${int(v.gouge_count)} samples (${mm(v.gouge_tolerance_mm, 4)})` : '…')],
  ['error_bound_mm', 'Simulation error bound', (r, v) => {
    if (!v) return '…';
    return Number.isFinite(v.error_bound_mm) ? mm(v.error_bound_mm, 4) : 'not bounded';
  }],
  ['error_bound_target_mm', 'Bound aimed for (¼ of the scallop)', (r, v) => {
    if (!v) return '…';
    const t = v.error_bound_target_mm;
    return v.error_bound_mm <= t ? `${mm(t, 4)}: reached` : `${mm(t, 4)}: not reached`;
  }],
  ['samples', 'Simulation samples', (r, v, x) => {
    if (!v) return '…';
    return v.samples === x.samples ? int(v.samples) : `${int(v.samples)} (grown from ${int(x.samples)})`;
  }],
  ['max_axis_step_deg', 'Largest tool-axis turn between cut points', (r) => deg(r.max_axis_step_deg)],
  ['max_axis_acceleration_deg_s2', 'Largest tool-axis acceleration at the feed', (r) => `${int(r.max_axis_acceleration_deg_s2)} °/s²`],
  ['machining_time_min', 'Machining time', (r) => minutes(r.machining_time_min)],
  ['feed_time_min', 'Length ÷ feed (no acceleration)', (r) => minutes(r.feed_time_min)],
  ['plan_ms', 'Planning time', (r) => ms(r.plan_ms)],
  ['verify_ms', 'Simulation time', (r, v, x) => (v ? ms(x.verify_ms) : '…')],
];
/** Rows of a space-filling-curve plan (`isfc`): what its curve is made of. Id, label, text
 * and raw value (data-value) from (report, context); the context has `start` (the curve's
 * first point, mm). */
const ISFC_STATS = [
  ['grid', 'Grid lines, s × t (all patches)', (r) => `${int(r.grid.s_lines)} × ${int(r.grid.t_lines)} lines`, (r) => `${r.grid.s_lines}x${r.grid.t_lines}`],
  ['vertices', 'Grid points (cutter contacts)', (r) => int(r.grid.vertices), (r) => r.grid.vertices],
  ['cells', 'Cells (2 × 2 grid points each)', (r) => int(r.cells), (r) => r.cells],
  ['tree_links', 'Tree links joining the cells', (r) => `${int(r.tree_links)}${r.tree_links === r.cells - 1 ? ' (one pass)' : ''}`, (r) => r.tree_links],
  ['repaired_cells', 'Cells repaired for parity', (r) => int(r.repaired_cells), (r) => r.repaired_cells],
  ['compensated_corners', 'Corners with a scallop detour', (r) => int(r.compensated_corners), (r) => r.compensated_corners],
  ['start_mm', 'Curve starts at', (r, x) => (x.start && x.start.length === 3 ? `${[...x.start].map((c) => c.toFixed(3)).join(', ')} mm` : '—'),
    (r, x) => (x.start ? [...x.start].join(',') : '')],
];

/** Raw value of a statistic (for data-value), where it has one. */
function rawStat(id, r, v) {
  if (id in r) return r[id];
  if (v && id in v) return v[id];
  return '';
}

/** A parameter's default as its control shows it. */
function defaultText(p) {
  if (p.kind === 'flag') return p.default ? '1' : '0';
  return p.default === null || p.default === undefined ? '' : String(p.default);
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
    return ['model', 'compare', ...PARAMS.map((p) => p.key)];
  }

  constructor() {
    super();
    /** Plan layers (OVERLAYS) the user turned on, kept for the next plans. */
    this.overlayShown = {};
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
      if (value && value !== this.$('sample').value) this.#loadNamed(value);
      return;
    }
    if (name === 'compare') {
      if (flagOn(value ?? '0')) this.#compare();
      return;
    }
    if (!this.$(`p-${name}`)) return;
    this.#setControl(byKey[name], value ?? '');
    this.#onParamChange(name);
  }

  set state(s) {
    this.dataset.state = s;
  }

  get state() {
    return this.dataset.state;
  }

  /** The status line; `tone` is `error` (also `true`), `warning` or nothing. */
  #status(text, tone = '') {
    const el = this.$('status');
    el.textContent = text;
    const t = tone === true ? 'error' : tone || '';
    el.classList.toggle('error', t === 'error');
    el.classList.toggle('warning', t === 'warning');
  }

  /** The status line for the plan shown: what its report (with the simulation's findings,
   * once simulated) says, loud when it leaves something undone. `extra` is appended. */
  #planStatus(extra = '') {
    const p = this.plan;
    if (!p) return;
    const r = p.report;
    const v = p.verification?.summary;
    const sim = v ? ` Simulated max scallop ${mm(v.max_scallop_mm, 4)}.` : '';
    if (r.status === 'planned_with_problems') {
      const n = r.problems.length;
      this.#status(`Planned with problems: ${int(r.cl_points)} CL points in ${ms(r.plan_ms)}; ${n} problem${n === 1 ? '' : 's'} (listed with the statistics).${sim}${extra}`, 'warning');
    } else {
      this.#status(`Planned ${int(r.cl_points)} CL points in ${ms(r.plan_ms)}.${sim}${extra}`);
    }
  }

  // ---------------------------------------------------------------- start

  async #start() {
    this.state = 'starting';
    this.client = new EngineClient();
    // The view (three.js) and the engine (the worker's wasm) start side by side, and the
    // first model is loaded as soon as the engine is up: #load waits for the view only to
    // draw (on the test machine the view was ready last, and the model waited for it).
    this.viewReady = this.#createView();
    this.viewReady.catch(() => {}); // said by #load, which awaits it
    this.#buildParams();
    this.#bindUi();
    this.#buildGlossary();
    let info;
    try {
      info = await this.client.ready;
    } catch (e) {
      this.state = 'error';
      this.#status(`The engine failed to start: ${e.message}`, true);
      return;
    }
    this.info = info;
    this.machineRotaries = Object.fromEntries(info.machines.map((m) => {
      const j = JSON.parse(m.json);
      return [m.name, { rotaries: j.rotaries.length, description: j.description || '', reachTiltDeg: m.reachTiltDeg }];
    }));
    this.#fillChoice('machine', info.machines.map((m) => [m.name, `${m.name}${this.machineRotaries[m.name].rotaries ? ' (five-axis)' : ''}`]));
    this.#fillChoice('dialect', info.dialects.map((d) => [d, d]));
    const builtIn = document.createElement('optgroup');
    builtIn.label = 'Built-in samples';
    for (const n of info.samples) builtIn.append(new Option(n, n));
    const files = document.createElement('optgroup');
    files.label = PUBLIC_SOURCE.group;
    for (const m of PUBLIC_MODELS) files.append(new Option(`${m.file} (${m.what})`, m.id));
    this.$('sample').append(builtIn, files);
    if (info.verifySamples !== byKey.samples.default) {
      console.warn(`The engine's simulation starts from ${info.verifySamples} samples, the page's default ${byKey.samples.default}`);
    }
    if (info.verifyMaxSamples !== byKey['max-samples'].default) {
      console.warn(`The engine's simulation cap is ${info.verifyMaxSamples} samples, the page's default ${byKey['max-samples'].default}`);
    }

    // Initial values: attributes, then the URL if synced; parameters this page does not
    // know are named in the status once the model is loaded.
    const initial = {};
    for (const a of this.getAttributeNames()) initial[a] = this.getAttribute(a);
    const unknown = [];
    if (this.hasAttribute('sync-url')) {
      for (const [k, v] of new URLSearchParams(location.search)) {
        initial[k] = v;
        if (!byKey[k] && !URL_KEYS.includes(k)) unknown.push(k);
      }
    }
    for (const p of PARAMS) {
      if (initial[p.key] !== undefined && initial[p.key] !== null) this.#setControl(p, initial[p.key]);
    }
    // Patch choices exist once the model is loaded.
    this.pendingPatches = { 'start-patch': initial['start-patch'], 'finish-patch': initial['finish-patch'] };
    this.#updateDependentControls();
    this.ready = true;
    this.#validateAll();
    const model = initial.model || info.samples[0];
    const loaded = model.startsWith(FILE_PREFIX) ? await this.#loadStored(model.slice(FILE_PREFIX.length)) : await this.#loadNamed(model);
    if (loaded && unknown.length) {
      this.#status(`The link's ${unknown.map((k) => `“${k}”`).join(', ')} ${unknown.length === 1 ? 'is not a parameter' : 'are not parameters'} of this page (left out); the parameters are ${PARAMS.map((p) => p.key).join(', ')}.`, 'warning');
    }
    const flag = (x) => x !== undefined && x !== null && x !== '0' && x !== 'false';
    if (loaded && flag(initial.plan)) await this.#plan();
    if (loaded && flag(initial.compare)) this.#compare();
  }

  async #createView() {
    const canvas = this.$('view');
    // No probe canvas first: three.js throws when the canvas gives no WebGL 2 context, and
    // the 2D view takes the canvas then (a failed getContext binds no context to it).
    if (typeof WebGL2RenderingContext !== 'undefined') {
      try {
        const { View3D } = await import('./view3d.js');
        this.view = new View3D(canvas);
        try {
          this.view.warmUp();
        } catch (e) {
          console.warn('could not compile the shaders ahead:', e); // the first draw does
        }
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
      if (group === 'accuracy' || group === 'strategy' || group === 'tool' || group === 'output') details.open = true;
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
        if (p.kind === 'flag') {
          // A checkbox with its label beside it.
          control = document.createElement('input');
          control.type = 'checkbox';
          control.checked = !!p.default;
          control.value = '1';
          label.className = 'inline check';
          label.textContent = ` ${p.label}`;
          label.prepend(control);
        } else if (p.kind === 'number') {
          // Text, not type=number: the browser would turn “0,02” or “1e” into an empty
          // value before the checks could say what was read.
          control = document.createElement('input');
          control.type = 'text';
          control.inputMode = 'decimal';
          control.autocomplete = 'off';
          control.spellcheck = false;
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
        row.append(label);
        if (control.parentNode !== label) row.append(control);
        row.append(err);
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
    $('compare').addEventListener('click', () => this.#compare());
    // Keys: Escape cancels what is running (wherever the focus is), Ctrl+Enter (⌘+Enter)
    // plans from anywhere in the element.
    document.addEventListener('keydown', (e) => {
      if (e.key === 'Escape' && (this.planning || this.dataset.verify === 'running')) {
        e.preventDefault();
        this.#cancel();
      }
    });
    this.addEventListener('keydown', (e) => {
      if (e.key === 'Enter' && (e.ctrlKey || e.metaKey) && !this.$('plan').disabled) {
        e.preventDefault();
        this.#plan();
      }
    });
    $('compare-close').addEventListener('click', () => {
      $('compare-panel').hidden = true;
      this.comparison = null;
      this.#syncUrl();
    });
    $('compare-csv').addEventListener('click', () => {
      if (this.comparison) download(`${this.#baseName()}-compare.csv`, new Blob([this.comparison.csv], { type: 'text/csv' }));
    });
    // A row's strategy button or its path picks it.
    $('compare-panel').addEventListener('click', (e) => {
      const b = e.target.closest('button[data-row]');
      if (b) this.#pickCompared(Number(b.dataset.row));
    });
    $('sample').addEventListener('change', () => this.#loadNamed($('sample').value));
    $('file').addEventListener('change', () => {
      const f = $('file').files[0];
      if (f) this.#openFile(f);
      $('file').value = '';
    });
    $('params').addEventListener('change', (e) => this.#onParamChange(e.target.name));
    $('params').addEventListener('submit', (e) => e.preventDefault());
    $('fit').addEventListener('click', () => this.view && this.view.fit());
    for (const b of this.root.querySelectorAll('[data-view]')) {
      b.addEventListener('click', () => {
        if (!this.view) return;
        this.view.fit(b.dataset.view);
        this.dataset.view = b.dataset.view;
      });
    }
    $('ortho').addEventListener('change', () => this.view && this.view.setOrtho($('ortho').checked));
    for (const k of ['path', 'tool', 'cage', 'eps', 'zero', 'grid']) {
      $(`layer-${k}`).addEventListener('change', () => this.view.setLayers({ [k]: $(`layer-${k}`).checked }));
    }
    $('layer-rest').addEventListener('change', () => {
      this.restHidden = !$('layer-rest').checked; // kept for the next plans
      this.#showRestLayer();
    });
    // Drawn from what the plan brought along: showing it does not plan again.
    for (const key of Object.keys(OVERLAYS)) {
      $(`layer-${key}`).addEventListener('change', () => {
        this.overlayShown[key] = $(`layer-${key}`).checked; // kept for the next plans
        this.#showOverlayLayer(key);
      });
    }
    $('problems').addEventListener('click', (e) => {
      const b = e.target.closest('button[data-move]');
      if (b) this.#showMove(Number(b.dataset.move), b.dataset.at ? JSON.parse(b.dataset.at) : null);
    });
    for (const id of ['colour-patches', 'colour-heat']) $(id).addEventListener('change', () => this.#showColours());
    $('scrub').addEventListener('input', () => this.#scrubTo(Number($('scrub').value)));
    $('play').addEventListener('click', () => this.#togglePlay());
    $('download-gcode').addEventListener('click', () => this.#downloadGcode());
    $('download-csv').addEventListener('click', () => this.#downloadCsv());
    $('download-stl').addEventListener('click', () => this.#downloadStl());
    $('save-job').addEventListener('click', () => this.#saveJob());
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

  /** Opens the file kept from the last visit (a reload, or a link naming `file:NAME`);
   * says so, and opens the first sample, when this browser does not have it. */
  async #loadStored(name) {
    const kept = await loadLastFile();
    if (kept && kept.name === name) {
      return this.#load({ bytes: kept.bytes, name: name.replace(/\.[^.]*$/, '') }, name);
    }
    const ok = await this.#loadNamed(this.info.samples[0]);
    this.#status(`The file “${name}” is not kept in this browser (files stay on the machine they were opened on): open it again.`, 'warning');
    return ok;
  }

  /** Reads the model shown again (after a change of its placement). */
  async #reload() {
    const m = this.model;
    if (!m) return false;
    if (m.pub) return this.#loadPublic(m.pub);
    if (m.sample) return this.#loadNamed(m.sample);
    const src = this.client.source;
    if (!src?.bytes) return false;
    return this.#load({ bytes: src.bytes.slice(0), name: src.name }, m.file);
  }

  /** Loads a built-in sample or one of the public files by its picker name. */
  async #loadNamed(name) {
    const pub = publicModel(name);
    if (pub) return this.#loadPublic(pub);
    if (this.info && !this.info.samples.includes(name)) {
      const files = PUBLIC_MODELS.map((m) => m.id).join(', ');
      this.#status(`There is no model “${name}”: the samples are ${this.info.samples.join(', ')}; the public files ${files}.`, true);
      if (!this.model) this.state = 'error';
      if (this.model) this.$('sample').value = this.model.sample ?? '';
      return false;
    }
    return this.#load({ sample: name }, name);
  }

  /** Fetches a public .tsm file from beside this module and loads it as an opened file. */
  async #loadPublic(m) {
    if (this.planning || this.dataset.verify === 'running') this.#cancel(true);
    const url = new URL(`./models/${m.id}`, import.meta.url);
    this.state = 'loading';
    this.#status(`Fetching ${m.file}…`);
    let buf;
    try {
      const res = await fetch(url);
      if (!res.ok) throw new Error(`the server answered ${res.status} ${res.statusText} for ${url.pathname}`);
      buf = await res.arrayBuffer();
    } catch (e) {
      this.state = this.model ? (this.plan ? 'planned' : 'model-loaded') : 'error';
      this.#status(`Could not fetch ${m.file}: ${e.message}`, true);
      if (this.model) this.$('sample').value = this.model.sample ?? '';
      return false;
    }
    return this.#load({ bytes: buf, name: m.file.replace(/\.[^.]*$/, '') }, m.file, m);
  }

  /** Opens a job file (see job.js): its parameters set, its model loaded, and planned when
   * it was saved planned. */
  async #openJob(text, name) {
    let job;
    try {
      job = readJob(text);
    } catch (e) {
      this.#status(`Could not open the job ${name}: ${e.message}.`, true);
      return false;
    }
    const unknown = Object.keys(job.parameters).filter((k) => !byKey[k]);
    const before = this.#raw();
    const setAll = (values) => {
      for (const p of PARAMS) this.#setControl(p, values[p.key] ?? defaultText(p));
      this.#updateDependentControls();
      this.#validateAll();
    };
    setAll(job.parameters);
    this.pendingPatches = { 'start-patch': job.parameters['start-patch'], 'finish-patch': job.parameters['finish-patch'] };
    const m = job.model;
    const loaded = m.sample
      ? await this.#loadNamed(m.sample)
      : await this.#load({ bytes: m.bytes, name: m.file.replace(/\.[^.]*$/, '') }, m.file);
    if (!loaded) {
      // The model shown stays, with the parameters it was shown with: the job's would not
      // describe it (its placement, its zero), and the plan shown stays that plan's.
      const said = this.$('status').textContent;
      setAll(before);
      this.pendingPatches = null;
      this.#markStale(!!this.plan && !this.#planMatches());
      this.#status(`Could not open the job ${name}: ${said}`, true);
      return false;
    }
    if (unknown.length) {
      this.#status(`Opened the job ${name}, but its ${unknown.map((k) => `“${k}”`).join(', ')} ${unknown.length === 1 ? 'is not a parameter' : 'are not parameters'} of this page (left out): check the parameters, then plan.`, 'warning');
      return true;
    }
    if (job.planned && !this.#validateAll().errors) await this.#plan();
    else if (!this.#validateAll().errors) this.#status(`Opened the job ${name}: ${this.model.summary.name} with the parameters saved. Press “Plan tool path” to plan it.`);
    return true;
  }

  /** Saves the job: the model (a file's bytes with it) and every parameter, planned or not. */
  #saveJob() {
    const m = this.model;
    if (!m) return;
    let model;
    if (m.sample) model = { sample: m.sample };
    else if (this.client.source?.bytes) model = { file: m.file, bytes: this.client.source.bytes };
    else {
      this.#status('Could not save the job: the model file is no longer held by the page; open it again, then save.', true);
      return;
    }
    const planned = !!this.plan && this.#planMatches();
    const text = writeJob({ model, parameters: this.#raw(), planned, savedBy: `tspath ${this.info?.version ?? ''}`.trim() });
    download(`${this.#baseName()}${JOB_SUFFIX}`, text, 'application/json');
  }

  async #openFile(file) {
    const ext = (file.name.match(/\.[^.]*$/) || [''])[0].toLowerCase();
    // A job holds its model in base64 (4/3 of its bytes) beside the parameters.
    const jobRoom = /\.json$/i.test(file.name) ? (MAX_FILE_BYTES * 4) / 3 + 1048576 : MAX_FILE_BYTES;
    if (file.size > jobRoom) {
      this.#status(`Could not open ${file.name}: it is ${bytes(file.size)}, more than the ${bytes(MAX_FILE_BYTES)} this page reads.`, true);
      return false;
    }
    if (!FILE_TYPES.includes(ext)) {
      this.#status(`Could not open ${file.name}: the page reads ${FILE_TYPES.join(', ')} files.`, true);
      return false;
    }
    const buf = await file.arrayBuffer();
    if (ext === '.json') {
      const text = new TextDecoder().decode(buf);
      if (isJob(text)) return this.#openJob(text, file.name);
    }
    const stem = file.name.replace(/\.[^.]*$/, '');
    return this.#load({ bytes: buf, name: stem }, file.name);
  }

  /** Loads a sample ({sample}) or file bytes ({bytes, name}); `pub` is the public model
   * the bytes are, if one. */
  async #load(source, label, pub = null) {
    if (this.planning || this.dataset.verify === 'running') this.#cancel(true);
    // Placed as the placement controls say (when valid; else as modelled, and the field says
    // what is wrong).
    const placed = validate(this.#raw(), { patches: 1, fiveAxis: this.#fiveAxis, reachTiltDeg: this.#reachTilt });
    const bad = PARAMS.filter((p) => p.placement && placed.errors[p.key]);
    source = { ...source, setup: bad.length ? null : placement(placed.values) };
    this.state = 'loading';
    this.#status(`Loading ${label}…`);
    let m;
    try {
      m = await this.client.load(source);
      await this.viewReady;
    } catch (e) {
      this.state = this.model ? (this.plan ? 'planned' : 'model-loaded') : 'error';
      this.#status(`Could not open ${label}: ${e.message}`, true);
      if (this.model) this.$('sample').value = this.model.sample ?? '';
      return false;
    }
    // `sample`: the picker's (and the URL's) name for it, null for a file of the user's.
    const sample = source.sample ?? pub?.id ?? null;
    this.model = { ...m, sample, file: source.sample ? null : label, pub };
    // A file of the user's is kept for the next visit (the URL names it).
    if (!source.sample && !pub && source.bytes) {
      // `data-kept` names it once stored (a reload before then opens the first sample).
      saveLastFile(label, source.bytes)
        .then(() => { this.dataset.kept = label; })
        .catch((e) => console.warn('could not keep the file:', e));
    }
    this.#clearPlan();
    // A comparison is of the model it was made on.
    this.comparison = null;
    this.#showComparison();
    this.$('colour-patches').checked = true;
    this.$('sample').value = sample ?? '';
    this.#showSummary(m.summary, pub);
    const patchNote = this.#fillPatchChoices(m.summary.patches);
    this.view.setModel(m);
    const grid = tableGrid(m.summary.stock_mm);
    this.$('grid-text').textContent = grid ? `Grid (${grid.spacing} mm)` : 'Grid';
    this.#showColours();
    this.view.renderNow();
    if (this.dataset.firstDrawMs === undefined) {
      this.dataset.firstDrawMs = String(Math.round(performance.now() - this.t0));
      // From the navigation's start (the page's clock), what a visitor waits.
      this.dataset.firstDrawAtMs = String(Math.round(performance.now()));
    }
    // The planner's module while the model is looked at (planning waits for it), and the
    // smallest concave radius from it.
    this.#findConcave(this.model);
    this.$('download-stl').disabled = false;
    this.$('save-job').disabled = false;
    this.state = 'model-loaded';
    this.dataset.model = m.summary.name;
    this.dataset.meshChordalMm = String(m.chordal_mm);
    const { errors } = this.#validateAll();
    // A wrong value from the URL or an attribute is said at once, not only at its field.
    const patches = `${int(m.summary.patches)} ${m.summary.patches === 1 ? 'patch' : 'patches'}`;
    // What the reader could not apply (OBJ subdivision tags) is said as loudly as a problem.
    const readerNote = (m.summary.warnings || []).map((w) => ` Warning: ${w}.`).join('');
    if (errors) this.#status(`Loaded ${m.summary.name}: ${patches}. Before planning: ${errors[0]}${patchNote}${readerNote}`, true);
    else if (patchNote || readerNote) this.#status(`Loaded ${m.summary.name}: ${patches}.${patchNote}${readerNote}`, 'warning');
    else this.#status(`Loaded ${m.summary.name}: ${patches}. Choose parameters and plan.`);
    this.#syncUrl();
    return true;
  }

  #showSummary(s, pub) {
    const size = s.bbox_mm.max.map((v, k) => v - s.bbox_mm.min[k]);
    const concave = s.smallest_concave_radius;
    const rows = [
      ['Name', s.name],
      ['Format', s.format + (s.units_read && s.units_read !== 'mm' ? ` (${s.units_read})` : '')],
      ['Size (mm)', size.map((v) => v.toFixed(v < 10 ? 2 : 1)).join(' × ')],
      ['Placement', s.placement],
      ['Stock', `${s.stock_mm.max.map((v, k) => (v - s.stock_mm.min[k]).toFixed(2)).join(' × ')} mm`],
      ['Program zero', s.program_zero],
      ['Faces', int(s.faces)],
      ['Control points', int(s.control_points)],
      ['Patches', int(s.patches)],
      ['Extraordinary points', int(s.extraordinary_points)],
      ['T-junctions', int(s.t_junctions)],
      ['Holes', int(s.holes)],
      ...(s.subdivision_tags ? [['Subdivision tags', s.subdivision_tags]] : []),
      ['Smallest concave radius', concave === undefined ? 'looking…' : concave ? mmSig(concave.radius_mm) : 'none (nothing concave)', concave ? concave.radius_mm : ''],
    ];
    this.#facts(this.$('summary'), rows.map(([k, v, raw]) => [k.toLowerCase().replace(/\W+/g, '-'), k, v, raw]));
    markTerms(this.$('summary'), 'dt');
    if (pub) {
      // Where the file comes from and under which licence, linked (the licence is served
      // beside the file).
      const dt = document.createElement('dt');
      dt.textContent = 'Source';
      const dd = document.createElement('dd');
      dd.id = 'summary-source';
      const repo = document.createElement('a');
      repo.href = PUBLIC_SOURCE.url;
      repo.target = '_blank';
      repo.rel = 'noopener';
      repo.textContent = PUBLIC_SOURCE.repository;
      const licence = document.createElement('a');
      licence.href = new URL(`./models/${PUBLIC_SOURCE.dir}/${PUBLIC_SOURCE.licenceFile}`, import.meta.url).href;
      licence.target = '_blank';
      licence.textContent = PUBLIC_SOURCE.licence;
      const about = document.createElement('a');
      about.href = new URL(`./models/${PUBLIC_SOURCE.dir}/SOURCE.md`, import.meta.url).href;
      about.target = '_blank';
      about.textContent = 'about';
      dd.append(repo, `, rhino/${pub.file}; licence `, licence, ' (', about, ')');
      dd.classList.add('wide');
      this.$('summary').append(dt, dd);
    }
    this.#concaveHint();
    const legend = this.$('patch-legend');
    legend.replaceChildren();
    const swatch = (i, text) => {
      const sw = document.createElement('span');
      sw.className = 'swatch';
      sw.style.setProperty('--c', hexCss(PATCH_COLOURS[i % PATCH_COLOURS.length]));
      sw.textContent = text;
      legend.append(sw);
    };
    if (s.patches <= PATCH_LEGEND_ROWS) {
      for (let i = 0; i < s.patches; i++) swatch(i, `patch ${i}`);
    } else {
      // Many patches (a big cage): one swatch per colour, naming the patches that take it.
      const n = PATCH_COLOURS.length;
      const note = document.createElement('span');
      note.className = 'legend-note';
      note.textContent = `${s.patches} patches, coloured in turn:`;
      legend.append(note);
      for (let i = 0; i < n; i++) swatch(i, `${i}, ${i + n}, ${i + 2 * n}, …`);
    }
  }

  /** Looks for `model`'s smallest concave radius (it samples every face, so the model is
   * drawn first; asked of the planner's module, which loads the model then and keeps the
   * radius for planning): the summary's row and hint say "looking" until it comes;
   * `data-concave` is `looking`, then `found`. */
  async #findConcave(model) {
    this.dataset.concave = 'looking';
    let c;
    try {
      c = await this.client.call('concave');
    } catch (e) {
      // A Cancel meanwhile: the restarted worker has the model again; ask it.
      if (e instanceof CancelledError && this.model === model) this.#findConcave(model);
      else if (this.model === model) this.#status(`Could not find the smallest concave radius: ${e.message}`, true);
      return;
    }
    if (this.model !== model) return;
    model.summary.smallest_concave_radius = c;
    this.#showSummary(model.summary, model.pub);
    this.dataset.concave = 'found';
  }

  /** Under the summary: what the smallest concave radius means for the ball chosen. */
  #concaveHint() {
    const el = this.$('concave-hint');
    const c = this.model?.summary.smallest_concave_radius;
    if (!this.model) {
      el.textContent = '';
      return;
    }
    if (c === undefined) {
      el.textContent = 'Looking for the smallest concave radius (the largest ball that reaches everywhere)…';
      el.classList.remove('warn');
      return;
    }
    if (!c) {
      el.textContent = 'Nothing is concave: a ball of any radius reaches everywhere the surface is smooth.';
      el.classList.remove('warn');
      return;
    }
    const r = Number(this.$('p-tool-radius').value);
    const at = c.at_mm.map((x) => x.toFixed(2)).join(', ');
    const big = Number.isFinite(r) && r > c.radius_mm;
    el.textContent = `A ball of radius above ${mmSig(c.radius_mm)} cannot reach the bottom of the tightest concave spot (at ${at} mm): `
      + 'it leaves material there, rest material where that is more than the scallop height'
      + (big ? ` (the ${r} mm ball chosen is larger).` : '. The ball chosen fits.');
    el.classList.toggle('warn', big);
  }

  #facts(dl, rows) {
    dl.replaceChildren();
    for (const [id, label, text, raw] of rows) {
      const dt = document.createElement('dt');
      dt.textContent = label;
      const dd = document.createElement('dd');
      dd.id = `${dl.id}-${id}`;
      dd.textContent = text;
      // A long value takes the whole width, on the line under its label.
      if (String(text).length > (WIDE_VALUE_CHARS[dl.id] ?? 22)) dd.classList.add('wide');
      if (raw !== undefined && raw !== '') dd.dataset.value = String(raw);
      dl.append(dt, dd);
    }
  }

  /** Offers the patches of a model of `n`; a patch asked for (URL, attribute, job) that the
   * model does not have is left at auto, and the returned text says so. */
  /** The glossary list, and its terms marked where the controls name them. */
  #buildGlossary() {
    const dl = this.$('glossary');
    for (const [term, def] of GLOSSARY) {
      const dt = document.createElement('dt');
      dt.textContent = term;
      const dd = document.createElement('dd');
      dd.textContent = def;
      dl.append(dt, dd);
    }
    markTerms(this.$('params'));
    markTerms(this.root.querySelector('.layers'));
  }

  #fillPatchChoices(n) {
    const dropped = [];
    for (const key of ['start-patch', 'finish-patch']) {
      const el = this.$(`p-${key}`);
      const wanted = this.pendingPatches?.[key] ?? ''; // a new model's patches are not the old one's
      el.replaceChildren(new Option(`auto (${byKey[key].auto})`, ''));
      for (let i = 0; i < n; i++) el.append(new Option(`patch ${i}`, String(i)));
      const ok = wanted !== '' && /^\d+$/.test(String(wanted)) && Number(wanted) < n;
      el.value = ok ? String(wanted) : '';
      if (wanted !== '' && !ok) dropped.push(`${byKey[key].label.toLowerCase()} “${wanted}”`);
    }
    this.pendingPatches = null;
    if (!dropped.length) return '';
    return ` The ${dropped.join(' and ')} ${dropped.length === 1 ? 'is' : 'are'} not a patch of this model (patches 0 to ${n - 1}): left at auto.`;
  }

  // ---------------------------------------------------------------- parameters

  #raw() {
    const raw = {};
    for (const p of PARAMS) {
      const el = this.$(`p-${p.key}`);
      raw[p.key] = p.kind === 'flag' ? (el.checked ? '1' : '0') : el.value;
    }
    return raw;
  }

  /** Sets a parameter's control from text (URL, attribute): a flag is on unless `0`, `false`,
   * `no` or `off` (a bare attribute is on); a choice that is not offered is kept as an extra
   * option, so that validation names it instead of the select dropping it silently. */
  #setControl(p, value) {
    const el = this.$(`p-${p.key}`);
    if (p.kind === 'flag') {
      el.checked = flagOn(value);
      return;
    }
    const v = String(value);
    if (el.tagName === 'SELECT' && p.choices?.length) {
      for (const o of [...el.options]) if (o.dataset.unknown) o.remove();
      if (v !== '' && ![...el.options].some((o) => o.value === v)) {
        const o = new Option(`${v} (not a choice)`, v);
        o.dataset.unknown = '1';
        el.append(o);
      }
    }
    el.value = v;
  }

  /** How far the chosen machine tilts the tool (degrees). */
  get #reachTilt() {
    const m = this.$('p-machine').value;
    return this.machineRotaries?.[m]?.reachTiltDeg ?? 180;
  }

  get #fiveAxis() {
    const m = this.$('p-machine').value;
    return !!(this.machineRotaries && this.machineRotaries[m] && this.machineRotaries[m].rotaries);
  }

  /** Enables the controls that apply: tool-axis settings on five-axis machines only, lead and
   * tilt unless the axis preset sets them, the plain curve with the space-filling curve only. */
  #updateDependentControls() {
    const five = this.#fiveAxis;
    const preset = this.$('p-axis-preset').value;
    for (const p of PARAMS.filter((q) => q.fiveAxis)) {
      const el = this.$(`p-${p.key}`);
      const byPreset = five && preset === 'gan2014' && (p.key === 'lead' || p.key === 'tilt');
      // A preset left on when the machine became three-axis stays changeable, to be undone.
      const stuck = !five && p.key === 'axis-preset' && !!preset;
      el.disabled = (!five && !stuck) || !!byPreset;
      el.title = !five ? 'Needs a five-axis machine: a three-axis machine keeps the tool axis at +Z'
        : byPreset ? `Set by the tool axis preset (${this.info?.paperLeadDeg ?? 10}° lead, 0° tilt)` : '';
    }
    const strategy = this.$('p-strategy').value;
    for (const [only, name, what] of [['isfcOnly', 'isfc', 'the space-filling curve (one continuous pass)'], ['isoplanarOnly', 'isoplanar', 'iso-planar slicing (parallel planes)']]) {
      for (const p of PARAMS.filter((q) => q[only])) {
        const el = this.$(`p-${p.key}`);
        el.disabled = strategy !== name;
        el.title = strategy === name ? '' : `Only for ${what}`;
      }
    }
    const typed = this.$('p-zero').value === 'point';
    for (const p of PARAMS.filter((q) => q.zeroPoint)) {
      this.$(`p-${p.key}`).disabled = !typed;
      this.$(`p-${p.key}`).title = typed ? '' : 'Choose “a point typed below” as the program zero';
    }
    const m = this.machineRotaries?.[this.$('p-machine').value];
    this.$('p-machine').title = m ? m.description : '';
  }

  /** Validates every field; marks the wrong ones and returns the values (null if wrong). */
  #validateAll() {
    const { values, errors } = validate(this.#raw(), {
      patches: this.model ? this.model.summary.patches : 1,
      fiveAxis: this.#fiveAxis, reachTiltDeg: this.#reachTilt,
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
    this.$('compare').disabled = list.length > 0 || !this.model || this.planning;
    return list.length ? { errors: list } : { values };
  }

  #onParamChange(key) {
    // A choice made in the select replaces a value that was not a choice.
    const sel = this.$(`p-${key}`);
    if (sel && sel.tagName === 'SELECT') {
      for (const o of [...sel.options]) if (o.dataset.unknown && o.value !== sel.value) o.remove();
    }
    if (byKey[key]?.placement) {
      // The model is read again, placed anew (the plan, made on the old placement, goes).
      if (key === 'zero') this.#updateDependentControls();
      this.#validateAll();
      this.#syncUrl();
      const { errors } = validate(this.#raw(), { patches: 1, fiveAxis: this.#fiveAxis, reachTiltDeg: this.#reachTilt });
      const bad = PARAMS.find((p) => p.placement && errors[p.key]);
      if (bad) {
        this.#status(errors[bad.key], true);
        return;
      }
      this.#reload();
      return;
    }
    if (key === 'machine' || key === 'strategy' || key === 'axis-preset') this.#updateDependentControls();
    if (key === 'tool-radius') this.#concaveHint();
    const v = this.#validateAll();
    this.#syncUrl();
    // Whatever the change, the plan shown stays downloadable only while it is the plan of
    // the parameters shown (an invalid value is not that plan's either).
    const matches = this.#planMatches();
    this.#markStale(!!this.plan && !matches);
    if (matches && (key === 'dialect' || key === 'units' || key === 'machine')) {
      this.#post();
      if (!v.errors) return;
    }
    if (v.errors) {
      this.#status(v.errors[0], true);
      return;
    }
    if (!this.plan && !this.planning) {
      this.#status('Ready to plan.');
      return;
    }
    if (this.planning) {
      this.replanAfter = true;
      return;
    }
    if (matches) {
      clearTimeout(this.replanTimer);
      if (key === 'samples' || key === 'max-samples') this.#verify();
      else this.#planStatus();
      return;
    }
    const fast = this.lastPlanMs !== undefined && this.lastPlanMs < AUTO_REPLAN_MS;
    if (this.$('auto').checked && fast) {
      clearTimeout(this.replanTimer);
      this.replanTimer = setTimeout(() => this.#plan(), REPLAN_DELAY_MS);
      this.#status('Parameters changed: re-planning…');
    } else {
      this.#status('Parameters changed: press “Plan tool path” to plan again (the downloads wait for it).');
    }
  }

  #planOptions(values) {
    return planOptions(values, { fiveAxis: this.#fiveAxis, reachTiltDeg: this.#reachTilt, paperLeadDeg: this.info?.paperLeadDeg });
  }

  /** Whether the plan shown is the plan of the parameters as they are now: every plan
   * parameter valid and giving the same options. */
  #planMatches() {
    if (!this.plan) return false;
    const { values, errors } = validate(this.#raw(), {
      patches: this.model ? this.model.summary.patches : 1,
      fiveAxis: this.#fiveAxis, reachTiltDeg: this.#reachTilt,
    });
    if (PARAMS.some((p) => p.field && errors[p.key])) return false;
    return JSON.stringify(this.#planOptions(values)) === JSON.stringify(this.plan.options);
  }

  /** Greys the results and turns the plan's downloads off while they are not the plan of
   * the parameters shown. */
  #markStale(stale) {
    this.$('stats-section').classList.toggle('stale', stale);
    this.$('stats').classList.toggle('stale', stale);
    this.$('stale-note').hidden = !stale;
    this.toggleAttribute('data-stale', stale);
    this.#updateDownloads();
  }

  /** The G-code and CL downloads are on only for the plan shown, while it matches the
   * parameters, and the G-code only once written for the machine, dialect and units shown;
   * their titles say why not. */
  #updateDownloads() {
    const p = this.plan;
    const stale = this.hasAttribute('data-stale');
    const gcode = this.$('download-gcode');
    const csv = this.$('download-csv');
    const [machine, dialect, units] = ['machine', 'dialect', 'units'].map((k) => this.$(`p-${k}`).value);
    let why = '';
    if (!p) why = 'Nothing is planned yet: plan first';
    else if (stale) why = 'The parameters changed since this plan was made: plan again to download';
    csv.disabled = !!why;
    csv.title = why || 'The CL data of the plan shown (CSV, mm)';
    const g = p && p.gcode;
    const written = g && g.machine === machine && g.dialect === dialect && g.units === units;
    if (!why && !written) {
      why = this.posting ? `Writing the program for ${machine} in ${dialect}…`
        : `No program for ${machine} in ${dialect} (${units}): see the status line`;
    }
    gcode.disabled = !!why;
    gcode.title = why || `The program of the plan shown for ${machine} in ${dialect}, ${units}`;
    gcode.textContent = written ? `G-code (${dialect}, ${units})` : 'G-code';
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
    // The program comes with the plan, for the machine, dialect and units asked for now.
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
    // (The planner's module may still be on its way: planning starts once it is in.)
    this.#status(this.client.hasPlanner ? 'Planning… 0 %' : 'Loading the planner…');
    const t0 = performance.now();
    let result;
    try {
      result = await this.client.call('plan', [options, post], (f) => {
        if (token !== this.planToken) return;
        bar.value = f;
        this.#status(`Planning… ${Math.round(100 * f)} % (${((performance.now() - t0) / 1000).toFixed(1)} s)`);
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
    await this.#adopt(result, options, v.values, t0);
  }

  /** Makes a planned result (from `plan`, or a compared row from `pick`) the plan shown:
   * path, layers, statistics, program, URL, then its simulation. */
  async #adopt(answer, options, values, t0) {
    this.#clearPlan();
    const { program, programError, ...result } = answer;
    // `report` is what the page shows: the plan's own (`planReport`), and once simulated
    // the same with the simulation's findings added.
    this.plan = { ...result, planReport: result.report, options, values, workerHasPlan: true, startedAt: t0 };
    this.view.setPath(result);
    this.#showRest();
    for (const key of Object.keys(OVERLAYS)) this.#showOverlay(key);
    this.#showTool(values);
    const n = result.kinds.length;
    const scrub = this.$('scrub');
    scrub.max = String(Math.max(0, n - 1));
    scrub.value = '0';
    scrub.disabled = n === 0;
    this.$('play').disabled = n === 0;
    this.#showStats();
    this.#markStale(!this.#planMatches());
    this.#endPlanning();
    this.state = 'planned';
    this.dataset.status = result.report.status;
    this.dataset.verify = 'pending';
    this.#planStatus();
    // From Plan to the plan shown: what "re-plan when fast" goes by (not the program, though
    // written with it).
    this.lastPlanMs = performance.now() - t0 - (program?.ms || 0);
    const again = this.replanAfter && !this.#planMatches();
    this.replanAfter = false;
    // The program first, then the simulation (not both asked for at once: a Cancel of the
    // simulation would lose the program with the worker). A plan from Plan brings its program
    // for the machine, dialect and units asked for with it, and the simulation is asked for
    // at once (waiting for a separate answer, the worker waited 120–200 ms for the page,
    // busy drawing the path); one picked from a comparison asks for its program, and the
    // simulation as soon as the worker answers, before the page takes the program in.
    const plan = this.plan;
    const choice = this.#programChoice();
    const asked = choice.every((x, i) => x === [values.machine, values.dialect, values.units][i]);
    if (asked && (program || programError)) {
      if (program) this.#takeProgram(plan, program, ...choice);
      else this.#programFailed(plan, choice[0], choice[1], programError);
      this.#updateDownloads();
      if (!again) this.#verify();
    } else {
      await this.#post(() => {
        if (!again && plan === this.plan && !this.planning) this.#verify();
      });
    }
    this.dataset.plans = String(Number(this.dataset.plans || 0) + 1);
    // Where the slider is: 0 for a new plan, unless it was moved while the program was
    // being written.
    this.#scrubTo(Number(this.$('scrub').value));
    this.#syncUrl();
    if (again) this.#plan();
  }

  // ---------------------------------------------------------------- comparison

  /** Plans every strategy with the settings shown, in the worker (progress, Cancel), each
   * cut simulated unless asked not to, and shows them side by side. */
  async #compare() {
    clearTimeout(this.replanTimer);
    if (!this.model || !this.ready) return;
    const v = this.#validateAll();
    if (v.errors) {
      this.#status(v.errors[0], true);
      return;
    }
    if (this.planning) {
      this.#status('Wait for the plan to finish (or cancel it), then compare.', 'warning');
      return;
    }
    const options = this.#planOptions(v.values);
    const simulate = this.$('compare-simulate').checked;
    const token = (this.planToken = (this.planToken || 0) + 1);
    this.planning = true;
    this.#stopPlay();
    this.state = 'comparing';
    this.$('plan').disabled = true;
    this.$('compare').disabled = true;
    this.$('cancel').disabled = false;
    const bar = this.$('progress');
    bar.hidden = false;
    bar.value = 0;
    const t0 = performance.now();
    // When progress arrived (ms from the start), for the benchmark's "every 250 ms".
    this.compareTicks = [];
    this.#status('Comparing strategies… 0 %');
    let result;
    try {
      result = await this.client.call('compare', [options, '', v.values.machine, simulate], (f) => {
        if (token !== this.planToken) return;
        this.compareTicks.push(performance.now() - t0);
        bar.value = f;
        this.#status(`Comparing strategies… ${Math.round(100 * f)} % (${((performance.now() - t0) / 1000).toFixed(1)} s)`);
      });
    } catch (e) {
      if (token !== this.planToken) return;
      this.#endPlanning();
      if (e instanceof CancelledError) return;
      this.state = this.plan ? 'planned' : 'model-loaded';
      this.#status(`Could not compare: ${e.message}`, true);
      this.#markField(e.message);
      return;
    }
    if (token !== this.planToken) return;
    this.#endPlanning();
    this.state = this.plan ? 'planned' : 'model-loaded';
    const elapsed = performance.now() - t0;
    this.comparison = { ...result, options, values: v.values, simulate, ms: elapsed, current: null };
    this.#showComparison();
    const runs = result.report.runs;
    const failed = runs.filter((r) => r.error).length;
    const problems = runs.filter((r) => !r.error && r.status === 'planned_with_problems').length;
    const tail = [failed && `${failed} could not plan`, problems && `${problems} planned with problems`].filter(Boolean).join(', ');
    this.#status(`Compared ${runs.length} strategies in ${(elapsed / 1000).toFixed(1)} s${tail ? `: ${tail} (see the table)` : ''}. Pick a row to make it the plan shown.`, tail ? 'warning' : '');
    this.dataset.compared = String(Number(this.dataset.compared || 0) + 1);
    this.#syncUrl();
  }

  /** The comparison panel: summary, table, bar charts and each path from above. */
  #showComparison() {
    const c = this.comparison;
    const panel = this.$('compare-panel');
    panel.hidden = !c;
    if (!c) return;
    const r = c.report;
    this.$('compare-csv').disabled = false;
    this.$('compare-summary').textContent = `${r.model}: ball radius ${mmSig(r.tool_radius_mm)}, scallop ${mmSig(r.scallop_mm)}, times on ${c.values.machine}; surface ${area(r.area_mm2)}, L_min ${mm(r.l_min_mm, 1)} (∫ dA / g, the side step of the better principal direction at each point) and ${mm(r.l_min_flat_mm, 1)} flat (area / √(8 r h)). ${c.simulate ? 'Each cut simulated until its error bound is a quarter of the scallop.' : 'Not simulated.'} Planned in ${(c.ms / 1000).toFixed(1)} s. Pick a strategy (its name or its path) to make it the plan shown.`;
    // The table.
    const table = this.$('compare-table');
    table.replaceChildren();
    const head = table.createTHead().insertRow();
    for (const h of ['Strategy', ...COMPARE_COLUMNS.map((x) => x[1]), 'Status']) {
      const th = document.createElement('th');
      th.scope = 'col';
      th.textContent = h;
      head.append(th);
    }
    const body = table.createTBody();
    r.runs.forEach((run, k) => {
      const tr = body.insertRow();
      tr.dataset.strategy = run.strategy;
      tr.classList.toggle('current', c.current === k);
      const th = document.createElement('th');
      th.scope = 'row';
      const b = document.createElement('button');
      b.type = 'button';
      b.textContent = run.strategy;
      b.title = run.error ? `${COMPARE_ROWS[run.strategy]?.label}: could not plan this model` : `${COMPARE_ROWS[run.strategy]?.label}: make it the plan shown`;
      b.dataset.row = String(k);
      b.disabled = !!run.error;
      th.append(b);
      tr.append(th);
      if (run.error) {
        const td = tr.insertCell();
        td.colSpan = COMPARE_COLUMNS.length;
        td.className = 'reason';
        td.textContent = `Could not plan: ${run.error}`;
      } else {
        for (const [key, , f, sim] of COMPARE_COLUMNS) {
          const td = tr.insertCell();
          const x = runValue(run, key, sim);
          td.dataset.key = key;
          if (x === undefined || x === null) {
            td.textContent = '–';
          } else {
            td.dataset.value = String(x);
            td.textContent = f(x);
          }
        }
      }
      const st = tr.insertCell();
      st.className = run.error || run.status === 'planned_with_problems' ? 'warning' : '';
      st.textContent = run.error ? 'could not plan' : run.status === 'planned' ? 'planned' : `planned with problems: ${run.problems.join(', ')}`;
    });
    this.#drawCompareCharts();
    this.#drawCompareThumbs();
  }

  /** Horizontal bar charts of the planned rows (SVG): time, length, reversals, scallop (with
   * the requested scallop marked). */
  #drawCompareCharts() {
    const c = this.comparison;
    const box = this.$('compare-charts');
    box.replaceChildren();
    const runs = c.report.runs.filter((r) => !r.error);
    const NS = 'http://www.w3.org/2000/svg';
    const el = (name, attrs, text) => {
      const e = document.createElementNS(NS, name);
      for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
      if (text !== undefined) e.textContent = text;
      return e;
    };
    const [W, LABEL, ROW] = [300, 118, 16];
    for (const [key, title, digits] of COMPARE_CHARTS) {
      const sim = key === 'max_scallop_mm';
      const vals = runs.map((r) => runValue(r, key, sim));
      if (vals.some((x) => x === undefined || x === null)) continue;
      const mark = sim ? c.report.scallop_mm : null;
      const top = Math.max(...vals, mark || 0) || 1;
      const figure = document.createElement('figure');
      figure.dataset.chart = key;
      const cap = document.createElement('figcaption');
      cap.textContent = title;
      const h = ROW * runs.length + 4;
      const svg = el('svg', { viewBox: `0 0 ${W} ${h}`, width: W, height: h, role: 'img', 'aria-label': `${title}: ${runs.map((r, i) => `${r.strategy} ${vals[i].toFixed(digits)}`).join(', ')}` });
      const span = W - LABEL - 52;
      runs.forEach((r, i) => {
        const y = i * ROW + 2;
        svg.append(el('text', { x: LABEL - 4, y: y + 11, 'text-anchor': 'end', class: 'label' }, r.strategy));
        const w = Math.max(1, (span * vals[i]) / top);
        const over = mark !== null && vals[i] > mark;
        svg.append(el('rect', { x: LABEL, y, width: w, height: ROW - 4, class: over ? 'bar over' : 'bar', 'data-value': vals[i] }));
        svg.append(el('text', { x: LABEL + w + 3, y: y + 11, class: 'value' }, vals[i].toFixed(digits)));
      });
      if (mark !== null) {
        const x = LABEL + (span * mark) / top;
        svg.append(el('line', { x1: x, x2: x, y1: 0, y2: h, class: 'mark' }));
        svg.append(el('title', {}, `requested scallop ${mark} mm`));
      }
      figure.append(cap, svg);
      box.append(figure);
    }
  }

  /** Each row's path from above on one scale, in a button that picks it. */
  #drawCompareThumbs() {
    const c = this.comparison;
    const box = this.$('compare-thumbs');
    box.replaceChildren();
    const lo = [Infinity, Infinity];
    const hi = [-Infinity, -Infinity];
    for (const p of c.paths) {
      for (let i = 0; i < p.cl.length; i += 3) {
        for (let k = 0; k < 2; k++) {
          lo[k] = Math.min(lo[k], p.cl[i + k]);
          hi[k] = Math.max(hi[k], p.cl[i + k]);
        }
      }
    }
    const [W, H, PAD] = [190, 140, 6];
    const scale = Math.min((W - 2 * PAD) / Math.max(hi[0] - lo[0], 1e-9), (H - 2 * PAD) / Math.max(hi[1] - lo[1], 1e-9));
    c.report.runs.forEach((run, k) => {
      const b = document.createElement('button');
      b.type = 'button';
      b.className = 'thumb';
      b.dataset.row = String(k);
      b.disabled = !!run.error;
      b.classList.toggle('current', c.current === k);
      b.setAttribute('aria-label', run.error ? `${run.strategy}: could not plan` : `${run.strategy}: make it the plan shown`);
      const canvas = document.createElement('canvas');
      canvas.width = W;
      canvas.height = H;
      const ctx = canvas.getContext('2d');
      ctx.fillStyle = hexCss(BACKGROUND_LIGHT);
      ctx.fillRect(0, 0, W, H);
      const { cl, kinds } = c.paths[k];
      const x = (i) => PAD + (cl[3 * i] - lo[0]) * scale;
      const y = (i) => H - PAD - (cl[3 * i + 1] - lo[1]) * scale;
      // Cuts and links dark, air moves red: one path per colour.
      for (const [which, colour, width] of [[(kk) => kk <= 1 || kk === 4, 0x1f3b73, 0.6], [(kk) => kk === 2 || kk === 3 || kk === 5, 0xd62728, 0.8]]) {
        ctx.strokeStyle = hexCss(colour);
        ctx.lineWidth = width;
        ctx.beginPath();
        for (let i = 1; i < kinds.length; i++) {
          if (!which(kinds[i])) continue;
          ctx.moveTo(x(i - 1), y(i - 1));
          ctx.lineTo(x(i), y(i));
        }
        ctx.stroke();
      }
      const cap = document.createElement('span');
      cap.textContent = run.error ? `${run.strategy}: could not plan` : `${run.strategy}: ${minutes(run.machining_time_min)}, ${int(run.retractions)} retractions`;
      b.append(canvas, cap);
      box.append(b);
    });
  }

  /** Makes compared row `k` the plan shown: the controls take its strategy, and the worker
   * its plan (planned again where the worker no longer holds it, after a cancel). */
  async #pickCompared(k) {
    const c = this.comparison;
    const run = c?.report.runs[k];
    if (!run || run.error || this.planning) return;
    const row = COMPARE_ROWS[run.strategy];
    this.#setControl(byKey.strategy, row.strategy);
    this.#setControl(byKey['no-deform'], row.baseline ? '1' : '0');
    this.#updateDependentControls();
    const v = this.#validateAll();
    if (v.errors) {
      this.#status(v.errors[0], true);
      return;
    }
    const options = this.#planOptions(v.values);
    const token = (this.planToken = (this.planToken || 0) + 1);
    this.planning = true;
    this.#stopPlay();
    let result;
    try {
      result = await this.client.call('pick', [k]);
    } catch (e) {
      if (token !== this.planToken) return;
      this.#endPlanning();
      if (e instanceof CancelledError) return;
      // Taken already or lost with a restarted worker: the same options plan the same path.
      this.#plan();
      c.current = k;
      this.#markCurrentRow();
      return;
    }
    if (token !== this.planToken) return;
    c.current = k;
    this.#markCurrentRow();
    await this.#adopt(result, options, v.values, performance.now() - run.plan_ms);
  }

  #markCurrentRow() {
    const c = this.comparison;
    for (const el of this.$('compare-panel').querySelectorAll('tbody tr, button.thumb')) {
      const k = el.matches('tr') ? [...el.parentNode.children].indexOf(el) : Number(el.dataset.row);
      el.classList.toggle('current', c?.current === k);
    }
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
      if (!quiet) this.#status(this.state === 'comparing' ? 'Comparison cancelled.' : 'Planning cancelled.');
    } else if (this.dataset.verify === 'running') {
      this.dataset.verify = 'cancelled';
      this.$('cancel').disabled = true;
      if (this.plan && this.plan.preview) {
        // The preview stood for a simulation that no longer runs.
        this.plan.preview = null;
        delete this.dataset.preview;
        this.$('colour-heat').disabled = true;
        this.#showColours();
      }
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
      await this.client.call('plan', [this.plan.options, null]);
      this.plan.workerHasPlan = true;
      return true;
    } catch (e) {
      this.#status(`Could not restore the plan: ${e.message}`, true);
      return false;
    }
  }

  /** Writes the program of the plan for the machine, dialect and units shown (choices
   * that are always valid, so a wrong number elsewhere does not hold the program back).
   * `answered`: called when the worker has answered (or failed, not when cancelled), before
   * the page takes the program in. */
  async #post(answered = null) {
    if (!this.plan) return;
    const plan = this.plan;
    const [machine, dialect, units] = this.#programChoice();
    this.posting = (this.posting || 0) + 1;
    this.#updateDownloads();
    try {
      if (!(await this.#ensureWorkerPlan())) return;
      const g = await this.client.call('post', [machine, dialect, units]).then(
        (r) => { answered?.(); return r; },
        (e) => { if (!(e instanceof CancelledError)) answered?.(); throw e; },
      );
      if (plan !== this.plan) return;
      this.#takeProgram(plan, g, machine, dialect, units);
    } catch (e) {
      if (e instanceof CancelledError || plan !== this.plan) return;
      this.#programFailed(plan, machine, dialect, e.message);
    } finally {
      this.posting--;
      this.#updateDownloads();
    }
  }

  /** The machine, dialect and units chosen for the program. */
  #programChoice() {
    return ['machine', 'dialect', 'units'].map((k) => this.$(`p-${k}`).value);
  }

  /** Takes in the program `g` of `plan` (the plan shown) written for a machine, dialect and
   * units: listing, machining time, the tool's block. */
  #takeProgram(plan, g, machine, dialect, units) {
    plan.gcode = { ...g, machine, dialect, units, lineStarts: null, lineCount: 0 };
    // The machining time on this machine (the simulation's report keeps its other keys).
    for (const r of [plan.report, plan.planReport]) Object.assign(r, g.time);
    this.#showStats();
    this.#indexLines(plan.gcode);
    this.$('listing-title').textContent = `G-code: ${machine}, ${dialect}, ${units}`;
    this.$('p-machine').removeAttribute('aria-invalid');
    this.$('p-dialect').removeAttribute('aria-invalid');
    this.#scrubTo(Number(this.$('scrub').value));
    if (this.$('status').classList.contains('error') && !this.#validateAll().errors) this.#planStatus(' Program written.');
  }

  /** The program of `plan` (the plan shown) could not be written: says why. */
  #programFailed(plan, machine, dialect, message) {
    plan.gcode = null;
    this.$('listing').replaceChildren();
    this.$('listing-title').textContent = 'G-code';
    this.#status(`Could not write the program for ${machine} in ${dialect}: ${message}`, true);
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

  /** Simulates the cut of the plan shown as `tspath plan --verify --verify-samples N
   * --verify-max-samples M` does: from `samples` the count grows until the error bound is a
   * quarter of the scallop or reaches `max-samples`; the rest area is measured apart. The
   * report then takes in what the simulation found. */
  async #verify() {
    if (!this.plan) return;
    const plan = this.plan;
    const { values, errors } = validate(this.#raw(), { patches: this.model.summary.patches, fiveAxis: this.#fiveAxis, reachTiltDeg: this.#reachTilt });
    if (errors.samples || errors['max-samples']) return;
    const token = (this.verifyToken = (this.verifyToken || 0) + 1);
    this.dataset.verify = 'running';
    this.$('cancel').disabled = false;
    this.$('colour-heat').disabled = true;
    plan.verification = null;
    plan.preview = null;
    delete this.dataset.preview;
    plan.report = plan.planReport;
    this.dataset.status = plan.report.status;
    this.#showStats();
    this.#showColours();
    if (!(await this.#ensureWorkerPlan())) return;
    const start = values.samples;
    // A coarse heat map first (no bound between samples: a small share of the work), shown
    // while the simulation that proves the scallop runs, where that takes a while: its first
    // round samples `start`, or what the engine's spacing rule asks for if more.
    const first = Math.max(start, plan.verifyFirstSamples);
    const preview = first < PREVIEW_WORTH_SAMPLES ? 0 : Math.min(PREVIEW_SAMPLES, Math.floor(first / 4));
    if (preview >= byKey.samples.min) {
      if (!this.$('status').classList.contains('error')) this.#planStatus(` Simulating a preview of the cut from ${int(preview)} samples…`);
      try {
        const p = await this.client.call('verify', [{ samples: preview, preview: true }]);
        if (token !== this.verifyToken || plan !== this.plan) return;
        plan.preview = { heat: p.heat, summary: p.summary, samples: preview };
        this.dataset.preview = 'shown';
        this.$('colour-heat').disabled = false;
        this.#showColours();
      } catch (e) {
        if (token !== this.verifyToken || e instanceof CancelledError) return;
        // The full simulation below reports what went wrong.
      }
    }
    const bound = plan.options.scallop_mm * VERIFY_BOUND_SHARE;
    const cap = values['max-samples'];
    // Short enough that the progress after it stays within the status's two lines (the
    // sample counts are in the settings and, once simulated, in the results).
    const what = ` Simulating the cut until its error bound is ${mm(bound, 4)}…`;
    // An error shown meanwhile (a value typed during the preview) stays until the user acts.
    const erring = () => this.$('status').classList.contains('error');
    if (!erring()) this.#planStatus(what);
    const bar = this.$('progress');
    const t0 = performance.now();
    const done = () => {
      if (!this.planning) bar.hidden = true;
    };
    try {
      // The side the tool works from, as the preview found it (the same vote: the final
      // simulation need not take it again).
      const side = plan.preview ? { tool_side: plan.preview.summary.tool_side } : {};
      const v = await this.client.call('verify', [{ samples: start, bound_mm: bound, max_samples: cap, ...side }], (f) => {
        if (token !== this.verifyToken || plan !== this.plan || this.planning) return;
        bar.hidden = false;
        bar.value = f;
        // Progress, unless an error is being shown (it stays until the user acts).
        if (!erring()) {
          this.#planStatus(`${what} ${Math.round(100 * f)} % (${((performance.now() - t0) / 1000).toFixed(1)} s)`);
        }
      });
      done();
      if (token !== this.verifyToken || plan !== this.plan) return;
      plan.verification = { ...v, samples: start };
      plan.preview = null;
      delete this.dataset.preview;
      plan.report = v.report;
      this.dataset.status = v.report.status;
      this.dataset.verify = 'done';
      // From Plan to this final heat map, the first simulation of a plan only (the tests
      // read it; for a strategy picked from the comparison, from when its planning began).
      if (!plan.finalTimed) {
        plan.finalTimed = true;
        this.dataset.planToFinalMs = String(Math.round(performance.now() - plan.startedAt));
      }
      this.$('colour-heat').disabled = false;
      this.#showStats();
      this.#showColours();
      if (!this.hasAttribute('data-stale') && !this.$('status').classList.contains('error')) this.#planStatus();
    } catch (e) {
      done();
      if (token === this.verifyToken && plan === this.plan && plan.preview) {
        // The preview stood for a simulation that no longer runs.
        plan.preview = null;
        delete this.dataset.preview;
        this.$('colour-heat').disabled = true;
        this.#showColours();
      }
      if (token !== this.verifyToken || e instanceof CancelledError) return;
      this.dataset.verify = 'error';
      this.#status(`The cutting simulation failed: ${e.message}`, true);
    } finally {
      if (token === this.verifyToken && !this.planning) this.$('cancel').disabled = true;
    }
  }

  #clearPlan() {
    this.plan = null;
    delete this.dataset.planToFinalMs;
    this.#stopPlay();
    if (this.view) {
      this.view.setPath(null);
      this.view.setTool(null);
      this.view.setHeat(null);
      this.view.setRest(null);
      for (const o of Object.values(OVERLAYS)) this.view[o.setter](null);
    }
    this.$('colour-heat').disabled = true;
    this.$('scrub').disabled = true;
    this.$('scrub').max = '0';
    this.$('play').disabled = true;
    this.$('tool-readout').textContent = 'no path yet';
    this.$('listing').replaceChildren();
    this.$('listing-empty').hidden = false;
    this.$('listing-title').textContent = 'G-code';
    this.$('stats').replaceChildren();
    this.$('stats-empty').hidden = false;
    this.$('notes').replaceChildren();
    this.$('problems').replaceChildren();
    this.$('problems-box').hidden = true;
    this.$('heat-legend').hidden = true;
    this.$('rest-legend').hidden = true;
    this.$('layer-rest').disabled = true;
    for (const key of Object.keys(OVERLAYS)) {
      this.$(`${key}-legend`).hidden = true;
      this.$(`layer-${key}`).disabled = true;
      this.$(`layer-${key}`).checked = false;
    }
    delete this.dataset.verify;
    delete this.dataset.status;
    this.#markStale(false);
  }

  #showStats() {
    const p = this.plan;
    if (!p) return;
    const r = p.report;
    const v = p.verification ? p.verification.summary : null;
    const ctx = { ...(p.verification || {}), area_mm2: this.model.area_mm2, plain: !!p.options.isfc_plain };
    const rows = STATS.map(([id, label, f]) => [id, label, f(r, v, ctx), rawStat(id, r, v)]);
    const time = rows.find((x) => x[0] === 'machining_time_min');
    time[1] = `Machining time at ${int(p.options.feed_mm_min ?? 1000)} mm/min on ${r.time_machine} (accelerations, corners)`;
    if (r.rectangles) {
      // After the retractions: the regions and rectangles the surface was cut into.
      const at = rows.findIndex((x) => x[0] === 'retractions') + 1;
      const regions = r.regions || [];
      const convex = regions.filter((x) => x.kind === 'convex').length;
      rows.splice(at, 0,
        ['regions', 'Feature regions', r.strategy === 'watershed' ? `${int(regions.length)} (${int(convex)} convex, ${int(regions.length - convex)} concave)` : 'none (baseline)', String(regions.length)],
        ['rectangles', 'Rectangles', `${int(r.rectangles.length)}, ${int(r.rectangles.filter((x) => x.crossfeed === 'V').length)} cut along u`, String(r.rectangles.length)]);
    }
    if (r.strategy === 'isoplanar' && r.planes !== undefined) {
      // After the retractions: the planes and the pieces they cut.
      const at = rows.findIndex((x) => x[0] === 'retractions') + 1;
      const deformed = p.options.isoplanar_deform !== false;
      rows.splice(at, 0,
        ['planes', 'Slicing planes', `${int(r.planes)}, ${mm(r.slice_spacing_mm, 4)} apart ${deformed ? 'in the deformed space' : 'in plan view (baseline)'}`, String(r.planes)],
        ['segments', 'Pieces cut (boundary passes included)', int(r.segments), String(r.segments)]);
    }
    if (r.strategy === 'isfc' && r.grid) {
      // After the retractions: what the one pass is made of.
      const at = rows.findIndex((x) => x[0] === 'retractions') + 1;
      const x = { start: p.isfc?.start };
      rows.splice(at, 0, ...ISFC_STATS.map(([id, label, f, raw]) => [id, label, f(r, x), raw(r, x)]));
    }
    this.#facts(this.$('stats'), rows);
    this.$('stats-empty').hidden = true;
    markTerms(this.$('stats'), 'dt');
    if (v) this.$('stats-error_bound_target_mm').dataset.reached = String(v.error_bound_mm <= v.error_bound_target_mm);
    this.#showProblems();
    const notes = this.$('notes');
    notes.replaceChildren(...(r.notes || []).map((t) => {
      const li = document.createElement('li');
      li.textContent = t;
      return li;
    }));
  }

  /** The report's problems, each with its message (numbers in mm and mm²) and, where it has
   * a place, a button that puts the tool at the move nearest it. */
  #showProblems() {
    const p = this.plan;
    const list = this.$('problems');
    const problems = p.report.problems || [];
    list.replaceChildren(...problems.map((q, k) => {
      const li = document.createElement('li');
      li.dataset.kind = q.kind;
      const head = document.createElement('strong');
      head.textContent = `${PROBLEM_KINDS[q.kind] || q.kind}: `;
      li.append(head, q.message);
      const move = q.near_move ?? (q.at_mm ? this.#nearestMove(q.at_mm) : null);
      if (move !== null && move !== undefined) {
        const b = document.createElement('button');
        b.type = 'button';
        b.className = 'link';
        b.dataset.move = String(move);
        if (q.at_mm) b.dataset.at = JSON.stringify(q.at_mm);
        b.id = `problem-${k}-show`;
        b.textContent = q.near_move !== null && q.near_move !== undefined
          ? `Show the tool there (move ${int(move)})`
          : `Show the tool at the nearest move (${int(move)})`;
        li.append(' ', b);
      }
      return li;
    }));
    this.$('problems-box').hidden = problems.length === 0;
    this.$('problems-title').textContent = problems.length ? `Problems (${problems.length})` : 'Problems';
  }

  /** The cutting move whose contact point is nearest `at` (mm), for problems that have a
   * place but no move (the simulation's). */
  #nearestMove(at) {
    const { cc, kinds } = this.plan;
    let best = null;
    let bestD = Infinity;
    for (let i = 0; i < kinds.length; i++) {
      if (KINDS[kinds[i]]?.name !== 'feed') continue;
      const d = (cc[3 * i] - at[0]) ** 2 + (cc[3 * i + 1] - at[1]) ** 2 + (cc[3 * i + 2] - at[2]) ** 2;
      if (d < bestD) {
        bestD = d;
        best = i;
      }
    }
    return best;
  }

  /** Puts the tool at move `i` (as scrubbing there does) and frames the spot `at` (mm; the
   * move's contact point if not given) a few tool sizes wide. */
  #showMove(i, at = null) {
    const p = this.plan;
    if (!p) return;
    this.#stopPlay();
    this.$('scrub').value = String(i);
    this.#scrubTo(i);
    if (!this.$('layer-tool').checked) {
      this.$('layer-tool').checked = true;
      this.view.setLayers({ tool: true });
    }
    const spot = at || [p.cc[3 * i], p.cc[3 * i + 1], p.cc[3 * i + 2]];
    // Wide enough for the rest region there (the report's problems name its largest).
    const region = at && p.report.rest.find((g) => g.centre_mm.every((x, k) => x === at[k]));
    const size = region ? 1.2 * Math.sqrt(region.area_mm2 / Math.PI) : 0;
    const r = p.options.tool_radius_mm;
    this.view.focus(spot, Math.max(8 * r, 0.1 * this.view.modelRadius, size), this.#toolSideNormal(spot));
  }

  /** The unit normal of the drawn surface at its vertex nearest `at` (mm), on the side the
   * tool works from (that of the plan's cuts: ball centre minus contact point), so that the
   * view looks at the spot from outside; null if the plan has no cut. */
  #toolSideNormal(at) {
    const { positions: x, normals: n } = this.model;
    const nearest = (q) => {
      let best = 0;
      let bestD = Infinity;
      for (let v = 0; v < x.length; v += 3) {
        const d = (x[v] - q[0]) ** 2 + (x[v + 1] - q[1]) ** 2 + (x[v + 2] - q[2]) ** 2;
        if (d < bestD) {
          bestD = d;
          best = v;
        }
      }
      return best;
    };
    const { cl, cc, kinds } = this.plan;
    const cut = kinds.findIndex((k) => KINDS[k]?.name === 'feed');
    if (cut < 0) return null;
    const c = 3 * cut;
    const w = nearest([cc[c], cc[c + 1], cc[c + 2]]);
    const side = Math.sign((cl[c] - cc[c]) * n[w] + (cl[c + 1] - cc[c + 1]) * n[w + 1] + (cl[c + 2] - cc[c + 2]) * n[w + 2]) || 1;
    const v = nearest(at);
    return [side * n[v], side * n[v + 1], side * n[v + 2]];
  }

  /** The plan's rest area in the view, and its legend (area per reason). */
  #showRest() {
    const p = this.plan;
    const has = p && (p.rest.length > 0 || p.report.rest.length > 0);
    this.view.setRest(has ? { positions: p.rest, reasons: p.restReasons, regions: p.report.rest } : null);
    const box = this.$('layer-rest');
    box.disabled = !has;
    box.checked = has && !this.restHidden;
    const legend = this.$('rest-legend');
    legend.replaceChildren();
    if (has) {
      const title = document.createElement('div');
      title.className = 'title';
      title.textContent = `Rest area ${area(p.report.unreachable_area_mm2)}`;
      legend.append(title);
      for (const reason of REST_REASONS) {
        const regions = p.report.rest.filter((r) => r.why === reason.why);
        if (!regions.length) continue;
        const sw = document.createElement('span');
        sw.className = 'swatch';
        sw.dataset.why = reason.why;
        sw.style.setProperty('--c', hexCss(reason.colour));
        sw.textContent = `${reason.label}: ${area(regions.reduce((a, r) => a + r.area_mm2, 0))}`;
        legend.append(sw);
      }
    }
    this.#showRestLayer();
  }

  #showRestLayer() {
    const on = this.$('layer-rest').checked && !this.$('layer-rest').disabled;
    this.view.setLayers({ rest: on });
    this.$('rest-legend').hidden = !on;
  }

  /** A plan's own layer (OVERLAYS: a space-filling curve's cells and tree, a watershed
   * plan's regions and rectangles) in the view, off until asked for, and its legend. Plans
   * of other strategies have none: the box is off and says why. */
  #showOverlay(key) {
    const spec = OVERLAYS[key];
    const data = this.plan?.[key] || null;
    this.view[spec.setter](data);
    const box = this.$(`layer-${key}`);
    box.disabled = !data;
    box.checked = !!data && !!this.overlayShown[key];
    this.$(`layer-${key}-label`).title = data ? spec.title : spec.none;
    const legend = this.$(`${key}-legend`);
    legend.replaceChildren();
    if (data) {
      const title = document.createElement('div');
      title.className = 'title';
      title.textContent = spec.heading;
      const rows = spec.rows(data).map(([colour, text, fill]) => {
        const sw = document.createElement('span');
        sw.className = fill ? 'swatch' : 'swatch line';
        sw.style.setProperty('--c', hexCss(colour));
        sw.textContent = text;
        return sw;
      });
      legend.append(title, ...rows);
    }
    this.#showOverlayLayer(key);
  }

  #showOverlayLayer(key) {
    const on = this.$(`layer-${key}`).checked && !this.$(`layer-${key}`).disabled;
    this.view.setLayers({ [key]: on });
    this.$(`${key}-legend`).hidden = !on;
  }

  // ---------------------------------------------------------------- view

  #showColours() {
    // The simulation's heat map, or its preview while it runs.
    const shown = this.plan && (this.plan.verification || this.plan.preview);
    const heat = !!(this.$('colour-heat').checked && shown);
    // The path would hide the heat map: off while the map shows, back as it was after.
    if (heat !== !!this.heatShown) {
      const box = this.$('layer-path');
      if (heat) {
        this.pathBeforeHeat = box.checked;
        box.checked = false;
      } else if (this.pathBeforeHeat !== undefined) {
        box.checked = this.pathBeforeHeat;
      }
      this.view.setLayers({ path: box.checked });
      this.heatShown = heat;
    }
    if (heat) {
      this.view.setHeat(shown.heat, shown.summary.requested_scallop_mm);
      this.#heatLegend(shown.summary.requested_scallop_mm, this.plan.verification ? null : shown.samples);
    } else {
      this.view.setHeat(null);
      this.$('heat-legend').hidden = true;
    }
  }

  /** The heat map's legend for scallop `h` (mm); `preview`: the sample count of a preview
   * shown while the simulation runs. */
  #heatLegend(h, preview = null) {
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
    if (preview) {
      const note = document.createElement('div');
      note.id = 'heat-preview';
      note.textContent = `Preview from ${int(preview)} samples: the simulation that proves the scallop is still running.`;
      el.append(note);
    }
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
    this.$('listing-empty').hidden = true;
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
    if (!g || this.$('download-gcode').disabled) return;
    const ext = GCODE_EXT[g.dialect] || 'nc';
    download(`${this.#baseName()}-${g.dialect}.${ext}`, g.text, 'text/plain');
  }

  async #downloadCsv() {
    if (!this.plan || this.$('download-csv').disabled || !(await this.#ensureWorkerPlan())) return;
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

  /** With `sync-url`: the sample and every parameter not at its default, `plan=1` once
   * planned and `compare=1` while a comparison is shown, so the link opens the same. */
  #syncUrl() {
    if (!this.hasAttribute('sync-url') || !this.ready) return;
    const q = new URLSearchParams();
    if (this.model && this.model.sample) q.set('model', this.model.sample);
    else if (this.model && this.model.file) q.set('model', `${FILE_PREFIX}${this.model.file}`);
    const raw = this.#raw();
    for (const p of PARAMS) {
      const v = raw[p.key];
      const d = defaultText(p);
      if (v !== '' && v !== d && !(p.kind === 'number' && Number(v) === Number(d) && d !== '')) q.set(p.key, v);
    }
    if (this.plan) q.set('plan', '1');
    if (this.comparison) q.set('compare', '1');
    const query = q.toString().replace(/%2F/g, '/'); // `model=grapetec/Bike.tsm` reads better
    const url = `${location.pathname}${query ? `?${query}` : ''}${location.hash}`;
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

  /** Pixels a layer (`path`, `tool`, `cage`, `eps`, `rest`, `isfc`, `rects`) changes when shown (it is left
   * as it was). */
  layerPixels(layer) {
    const on = this.view.layers[layer];
    const n = this.pixelsChangedBy(() => this.view.setLayers({ [layer]: !on }));
    this.view.setLayers({ [layer]: on });
    this.view.renderNow();
    return n;
  }
}

customElements.define('tspath-planner', TspathPlanner);
