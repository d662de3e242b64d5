// The planner's parameters: one table that gives each its form control, label and unit, its
// name in the URL and as an attribute of <tspath-planner>, its PlanOptions field, its range
// and default, and the checks across fields. Lengths in mm, angles in degrees.

/**
 * `key`: URL/attribute name; `field`: PlanOptions field (snake_case) or null for page-only
 * settings; `kind`: number | patch | choice | flag (a checkbox: `1` in the URL, or the bare
 * attribute); `default`: value when absent (null = the engine's own default, said by `auto`).
 * `fiveAxis`: only for machines that tilt the tool; `isfcOnly`: only for the space-filling
 * curve; `isoplanarOnly`: only for iso-planar slicing; `invert`: a flag whose PlanOptions
 * field is its negation; `numeric`: a choice whose PlanOptions field is a number.
 */
export const PARAMS = [
  // Placement of the model (not plan options: the model is read again with them). As the
  // CLI's --model-units, --scale, --up, --rotate and --on-table.
  { key: 'model-units', field: null, group: 'placement', placement: true, label: 'File\u2019s unit (for files that do not say: OBJ)', kind: 'choice', choices: [['', 'as the file says (OBJ: its header comment, else mm)'], ['mm', 'millimetres'], ['cm', 'centimetres'], ['m', 'metres'], ['inch', 'inches']], default: '' },
  { key: 'scale', field: null, group: 'placement', placement: true, label: 'Scale', unit: '×', kind: 'number', min: 0.000001, max: 1000000, step: 0.1, default: 1 },
  { key: 'up', field: null, group: 'placement', placement: true, label: 'The file\u2019s up axis', kind: 'choice', choices: [['z', '+Z (machines)'], ['y', '+Y (most modelling tools): turned to +Z']], default: 'z' },
  { key: 'rotate', field: null, group: 'placement', placement: true, label: 'Turn about Z (counter-clockwise from above)', unit: '°', kind: 'choice', choices: [['0', '0°'], ['90', '90°'], ['180', '180°'], ['270', '270°']], default: '0' },
  { key: 'on-table', field: null, group: 'placement', placement: true, label: 'Lowest point on the table (Z 0)', kind: 'flag', default: false },
  { key: 'stock-side', field: null, group: 'placement', placement: true, label: 'Stock beyond the part, each side (X, Y)', unit: 'mm', kind: 'number', min: 0, max: 10000, step: 0.5, default: 0 },
  { key: 'stock-top', field: null, group: 'placement', placement: true, label: 'Stock above the part', unit: 'mm', kind: 'number', min: 0, max: 10000, step: 0.5, default: 0 },
  { key: 'zero', field: null, group: 'placement', placement: true, label: 'Program zero (X0 Y0 Z0)', kind: 'choice', choices: [['model', 'the model\u2019s origin'], ['stock-top-centre', 'stock top, centre'], ['stock-top-corner', 'stock top, front-left corner'], ['stock-bottom-centre', 'stock bottom, centre'], ['stock-bottom-corner', 'stock bottom, front-left corner'], ['point', 'a point typed below']], default: 'model' },
  { key: 'zero-x', field: null, group: 'placement', placement: true, zeroPoint: true, label: 'Program zero at X (model as placed)', unit: 'mm', kind: 'number', min: -100000, max: 100000, step: 1, default: 0 },
  { key: 'zero-y', field: null, group: 'placement', placement: true, zeroPoint: true, label: 'Program zero at Y', unit: 'mm', kind: 'number', min: -100000, max: 100000, step: 1, default: 0 },
  { key: 'zero-z', field: null, group: 'placement', placement: true, zeroPoint: true, label: 'Program zero at Z', unit: 'mm', kind: 'number', min: -100000, max: 100000, step: 1, default: 0 },
  // Strategy
  { key: 'strategy', field: 'strategy', group: 'strategy', label: 'How the surface is cut', kind: 'choice', choices: [['isoparametric', 'Patch by patch (isoparametric)'], ['isfc', 'One continuous pass (space-filling curve)'], ['watershed', 'Feature regions in rectangles (watershed)'], ['multi-rectangle', 'Rectangles, one direction (multi-rectangle)'], ['isoplanar', 'Parallel planes (iso-planar, deformed CL surface)']], default: 'isoparametric' },
  { key: 'isfc-plain', field: 'isfc_plain', group: 'strategy', label: 'Plain curve: the paper\u2019s baseline, without the parity repair and the corner compensation', kind: 'flag', default: false, isfcOnly: true },
  { key: 'slice-angle', field: 'slice_angle_deg', group: 'strategy', label: 'Slicing planes\u2019 normal, from +X in XY', unit: '°', kind: 'number', min: -360, max: 360, step: 5, default: 0, isoplanarOnly: true },
  { key: 'no-deform', field: 'isoplanar_deform', group: 'strategy', label: 'Constant plane spacing: the baseline, without the CL-surface deformation', kind: 'flag', default: false, invert: true, isoplanarOnly: true },
  { key: 'shear', field: 'isoplanar_shear', group: 'strategy', label: 'The paper\u2019s shear form of the deformation ratio (eq. 9, denser)', kind: 'flag', default: false, isoplanarOnly: true },
  { key: 'axis-preset', field: null, group: 'strategy', label: 'Tool axis preset', kind: 'choice', choices: [['', 'none: lead and tilt as set under Tool axis'], ['gan2014', 'Gan et al. 2014: 10\u00b0 lead from the surface normal'], ['yuan2012', 'Yuan & Shao 2012: area-weighted normal of the CL facets (iso-planar)']], default: '', fiveAxis: true },
  // Tool
  { key: 'tool-radius', field: 'tool_radius_mm', group: 'tool', label: 'Ball-end radius', unit: 'mm', kind: 'number', min: 0.05, max: 25, step: 0.05, default: 0.5 },
  { key: 'shank-radius', field: 'shank_radius_mm', group: 'tool', label: 'Shank radius', unit: 'mm', kind: 'number', min: 0.05, max: 50, step: 0.05, default: null, auto: 'ball radius' },
  { key: 'flute-length', field: 'flute_length_mm', group: 'tool', label: 'Flute length', unit: 'mm', kind: 'number', min: 0, max: 200, step: 0.5, default: null, auto: '4 ball radii' },
  { key: 'shank-length', field: 'shank_length_mm', group: 'tool', label: 'Shank length (ball centre to holder)', unit: 'mm', kind: 'number', min: 0.5, max: 300, step: 1, default: 20 },
  { key: 'holder-radius', field: 'holder_radius_mm', group: 'tool', label: 'Holder radius', unit: 'mm', kind: 'number', min: 0.5, max: 200, step: 0.5, default: 10 },
  { key: 'holder-length', field: 'holder_length_mm', group: 'tool', label: 'Holder length', unit: 'mm', kind: 'number', min: 0.5, max: 500, step: 1, default: 40 },
  // Accuracy
  { key: 'scallop', field: 'scallop_mm', group: 'accuracy', label: 'Scallop height', unit: 'mm', kind: 'number', min: 0.0005, max: 2, step: 0.001, default: 0.01 },
  { key: 'chordal', field: 'chordal_mm', group: 'accuracy', label: 'Chordal tolerance', unit: 'mm', kind: 'number', min: 0.0001, max: 1, step: 0.001, default: 0.005 },
  { key: 'max-cl-points', field: 'max_cl_points', group: 'accuracy', label: 'Most CL points (estimated before planning; more is refused)', unit: 'points', kind: 'number', min: 1000, max: 100000000, step: 100000, default: 2000000, integer: true },
  // Tool axis (five-axis machines only)
  { key: 'max-tilt', field: 'max_tilt_deg', group: 'axis', label: 'Largest tilt to clear the holder', unit: '°', kind: 'number', min: 0, max: 135, step: 1, default: 60, fiveAxis: true },
  { key: 'max-axis-step', field: 'max_axis_step_deg', group: 'axis', label: 'Largest axis turn between cut points', unit: '°', kind: 'number', min: 0.5, max: 45, step: 0.5, default: 5, fiveAxis: true },
  { key: 'lead', field: 'lead_deg', group: 'axis', label: 'Lead angle', unit: '°', kind: 'number', min: -79, max: 79, step: 1, default: 0, fiveAxis: true },
  { key: 'tilt', field: 'tilt_deg', group: 'axis', label: 'Tilt angle', unit: '°', kind: 'number', min: -79, max: 79, step: 1, default: 0, fiveAxis: true },
  // Order
  { key: 'start-patch', field: 'start_patch', group: 'order', label: 'Start patch', kind: 'patch', default: null, auto: 'patch 0' },
  { key: 'finish-patch', field: 'finish_patch', group: 'order', label: 'Finish patch', kind: 'patch', default: null, auto: 'shortest order' },
  { key: 'crossfeed', field: 'crossfeed', group: 'order', label: 'Pass direction', kind: 'choice', choices: [['', 'auto (fewer, longer passes)'], ['U', 'passes along v (u = const)'], ['V', 'passes along u (v = const)']], default: '' },
  // Feeds
  { key: 'feed', field: 'feed_mm_min', group: 'feeds', label: 'Cutting feed', unit: 'mm/min', kind: 'number', min: 1, max: 100000, step: 50, default: 1000 },
  { key: 'plunge-feed', field: 'plunge_feed_mm_min', group: 'feeds', label: 'Plunge feed', unit: 'mm/min', kind: 'number', min: 1, max: 100000, step: 50, default: 300 },
  { key: 'spindle', field: 'spindle_rpm', group: 'feeds', label: 'Spindle speed', unit: 'rpm', kind: 'number', min: 1, max: 100000, step: 500, default: 12000 },
  { key: 'clearance', field: 'clearance_mm', group: 'feeds', label: 'Clearance under the tool on rapids', unit: 'mm', kind: 'number', min: 0.1, max: 500, step: 1, default: 5 },
  { key: 'full-retract', field: 'full_retract', group: 'feeds', label: 'Rapids between cuts at the safe plane (else the clearance over what lies beneath)', kind: 'flag', default: false },
  { key: 'feed-height', field: 'feed_height_mm', group: 'feeds', label: 'Feed height above each cut', unit: 'mm', kind: 'number', min: 0, max: 500, step: 0.5, default: 2 },
  // Output (not plan options: they choose the program written from the plan)
  { key: 'machine', field: null, group: 'output', label: 'Machine', kind: 'choice', choices: [], default: '3-axis' },
  { key: 'dialect', field: null, group: 'output', label: 'G-code dialect', kind: 'choice', choices: [], default: 'linuxcnc' },
  { key: 'work-offset', field: 'work_offset', group: 'output', label: 'Work offset (program zero)', kind: 'choice', numeric: true, choices: [['54', 'G54'], ['55', 'G55'], ['56', 'G56'], ['57', 'G57'], ['58', 'G58'], ['59', 'G59']], default: '54' },
  { key: 'units', field: null, group: 'output', label: 'Program units', kind: 'choice', choices: [['mm', 'millimetres (G21)'], ['inch', 'inches (G20)']], default: 'mm' },
  // Simulation
  // As `tspath plan --verify --verify-samples N --verify-max-samples M`: the simulation
  // starts at `samples` and grows until its error bound is a quarter of the scallop, or
  // until `max-samples`.
  { key: 'samples', field: null, group: 'sim', label: 'Simulation samples to start with', unit: 'points', kind: 'number', min: 10000, max: 20000000, step: 10000, default: 100000, integer: true },
  { key: 'max-samples', field: null, group: 'sim', label: 'Most simulation samples (grown to prove the scallop)', unit: 'points', kind: 'number', min: 10000, max: 50000000, step: 100000, default: 8000000, integer: true },
];

export const GROUPS = [
  ['placement', 'Placement of the model'],
  ['accuracy', 'Accuracy'],
  ['strategy', 'Strategy'],
  ['tool', 'Tool, shank and holder'],
  ['output', 'Machine and program'],
  ['axis', 'Tool axis (five-axis machines)'],
  ['order', 'Patch order'],
  ['feeds', 'Feeds and clearance'],
  ['sim', 'Cutting simulation'],
];

export const byKey = Object.fromEntries(PARAMS.map((p) => [p.key, p]));

/**
 * Checks raw values (strings from controls, URL or attributes, keyed by `key`) and returns
 * `{values, errors}`: numbers parsed (null where `auto`), and per key a message saying what
 * is wrong. `patches` is the model's patch count, `fiveAxis` whether the machine tilts.
 */
export function validate(raw, { patches = 1, fiveAxis = false, reachTiltDeg = 180 } = {}) {
  const values = {};
  const errors = {};
  for (const p of PARAMS) {
    const s = raw[p.key] === undefined || raw[p.key] === null ? '' : String(raw[p.key]).trim();
    if (p.kind === 'number') {
      if (s === '') {
        if (p.default === null) values[p.key] = null;
        else errors[p.key] = `${p.label} is required (${p.unit})`;
        continue;
      }
      // A decimal comma (“0,02”) is read as the point it stands for.
      const v = /^[+-]?\d*,\d+$/.test(s) ? Number(s.replace(',', '.')) : s === '' ? NaN : Number(s);
      if (!Number.isFinite(v)) {
        errors[p.key] = `${p.label}: “${s}” is not a number (${p.unit}; write decimals as 0.02 or 0,02)`;
      } else if (v < p.min || v > p.max) {
        errors[p.key] = `${p.label} must be between ${p.min} and ${p.max} ${p.unit}`;
      } else if (p.integer && !Number.isInteger(v)) {
        errors[p.key] = `${p.label} must be a whole number`;
      } else {
        values[p.key] = v;
      }
    } else if (p.kind === 'patch') {
      if (s === '') values[p.key] = null;
      else {
        const v = Number(s);
        if (!Number.isInteger(v) || v < 0 || v >= patches) errors[p.key] = `${p.label} must be a patch from 0 to ${patches - 1}`;
        else values[p.key] = v;
      }
    } else if (p.kind === 'flag') {
      values[p.key] = s === '' ? p.default : flagOn(s);
    } else if (s !== '' && p.choices.length && !p.choices.some(([c]) => c === s)) {
      // A value from the URL or an attribute that is not one of the choices.
      const named = p.choices.map(([c, text]) => (c ? c : text.replace(/:.*/, ''))).join(', ');
      errors[p.key] = `${p.label}: \u201c${s}\u201d is not one of the choices (${named})`;
    } else {
      values[p.key] = s === '' ? p.default : s;
    }
  }
  const v = values;
  const fine = (...keys) => keys.every((k) => !(k in errors));
  if (fine('scallop', 'tool-radius') && v.scallop >= v['tool-radius']) {
    errors.scallop = `Scallop height must be smaller than the ball-end radius (${v['tool-radius']} mm)`;
  }
  const shank = v['shank-radius'] ?? v['tool-radius'];
  if (fine('holder-radius', 'shank-radius', 'tool-radius') && v['holder-radius'] < shank) {
    errors['holder-radius'] = `Holder radius must be at least the shank radius (${shank} mm)`;
  }
  const flute = v['flute-length'] ?? 4 * v['tool-radius'];
  if (fine('flute-length', 'shank-length', 'tool-radius') && flute >= v['shank-length']) {
    errors['flute-length'] = `Flute length (${flute} mm) must be shorter than the shank length (${v['shank-length']} mm)`;
  }
  if (fiveAxis && fine('max-tilt') && v['max-tilt'] > reachTiltDeg) {
    errors['max-tilt'] = `${byKey['max-tilt'].label} must be at most ${reachTiltDeg}° on this machine (the travel of its tilting axis)`;
  }
  if (!fiveAxis) {
    for (const k of ['lead', 'tilt']) {
      if (fine(k) && v[k] !== 0 && !v['axis-preset']) errors[k] = `${byKey[k].label} needs a five-axis machine`;
    }
    if (fine('axis-preset') && v['axis-preset']) errors['axis-preset'] = `${byKey['axis-preset'].label} needs a five-axis machine: choose one, or set the preset to none`;
  }
  return { values, errors };
}

/** A flag's text (URL, attribute, checkbox) as on or off: anything but 0/false/no/off is on,
 * the bare attribute included. */
export function flagOn(s) {
  return !['0', 'false', 'no', 'off'].includes(String(s).trim().toLowerCase());
}

/** PlanOptions for the engine from validated values (a three-axis machine keeps +Z; the
 * `gan2014` axis preset sets lead `paperLeadDeg` and tilt 0, as `--axis-preset gan2014`;
 * options of the space-filling curve and of iso-planar slicing go only with theirs). */
export function planOptions(values, { fiveAxis, paperLeadDeg = 10 }) {
  const o = {};
  for (const p of PARAMS) {
    if (!p.field) continue;
    const v = values[p.key];
    if (v === null || v === '' || v === undefined) continue;
    if (p.isfcOnly && values.strategy !== 'isfc') continue;
    if (p.isoplanarOnly && values.strategy !== 'isoplanar') continue;
    o[p.field] = p.invert ? !v : p.numeric ? Number(v) : v;
  }
  if (fiveAxis && values['axis-preset'] === 'gan2014') {
    o.lead_deg = paperLeadDeg;
    o.tilt_deg = 0;
  }
  if (fiveAxis && values['axis-preset'] === 'yuan2012') o.facet_normal_axis = true;
  if (!fiveAxis) {
    o.max_tilt_deg = 0;
    o.lead_deg = 0;
    o.tilt_deg = 0;
  }
  return o;
}

/** The model placement the values ask for (Model.fromBytesPlaced's `setup`), or null when
 * it changes nothing. */
export function placement(values) {
  const s = {
    model_units: values['model-units'] || null,
    scale: Number(values.scale ?? 1),
    up: values.up || 'z',
    rotate_deg: Number(values.rotate || 0),
    on_table: !!values['on-table'],
    stock_side_mm: Number(values['stock-side'] || 0),
    stock_top_mm: Number(values['stock-top'] || 0),
    zero: values.zero === 'point'
      ? { at: ['zero-x', 'zero-y', 'zero-z'].map((k) => Number(values[k] || 0)) }
      : values.zero || 'model',
  };
  const identity = !s.model_units && s.scale === 1 && s.up === 'z' && s.rotate_deg === 0 && !s.on_table
    && !s.stock_side_mm && !s.stock_top_mm && s.zero === 'model';
  return identity ? null : s;
}
