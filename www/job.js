// The job file: one JSON file holding the model (its bytes, when it is a file of the user's)
// and every parameter of the page, placement and machine included, so that opening it on
// any machine gives the same plan and the same program, byte for byte.

export const JOB_FORMAT = 'tspath-job';
export const JOB_VERSION = 1;
/** File name ending of a job: still JSON, so any editor opens it. */
export const JOB_SUFFIX = '.tspath-job.json';

/** Base64 of an ArrayBuffer, in slices (a 64 MB model would overflow one call). */
function toBase64(buf) {
  const u8 = new Uint8Array(buf);
  const SLICE = 0x8000;
  let s = '';
  for (let i = 0; i < u8.length; i += SLICE) s += String.fromCharCode(...u8.subarray(i, i + SLICE));
  return btoa(s);
}

function fromBase64(text) {
  const s = atob(text);
  const u8 = new Uint8Array(s.length);
  for (let i = 0; i < s.length; i++) u8[i] = s.charCodeAt(i);
  return u8.buffer;
}

/** The text of a job. `model` is `{sample}` (a built-in sample or a public file's id) or
 * `{file, bytes}` (a file of the user's: its name and ArrayBuffer); `parameters` maps every
 * parameter key to its text as the page shows it; `planned` says whether to plan on opening. */
export function writeJob({ model, parameters, planned, savedBy }) {
  const m = model.sample ? { sample: model.sample } : { file: model.file, bytes_base64: toBase64(model.bytes) };
  const job = { format: JOB_FORMAT, version: JOB_VERSION, saved_by: savedBy, model: m, parameters, planned: !!planned };
  return `${JSON.stringify(job, null, 1)}\n`;
}

/** Whether `text` (a .json file's) is a job rather than a model. */
export function isJob(text) {
  return /^\s*\{\s*"format"\s*:\s*"tspath-job"/.test(text);
}

/** Reads a job's text: `{model: {sample} | {file, bytes}, parameters, planned}`. Throws an
 * Error saying what is wrong (and what to do) for a file that is not one this page wrote. */
export function readJob(text) {
  let job;
  try {
    job = JSON.parse(text);
  } catch (e) {
    throw new Error(`it is not JSON (${e.message}); a job file is written by “Save job”`);
  }
  if (!job || job.format !== JOB_FORMAT) throw new Error(`it is not a job file (no "format": "${JOB_FORMAT}")`);
  if (job.version !== JOB_VERSION) {
    throw new Error(`it is a version ${job.version} job; this page reads version ${JOB_VERSION}`);
  }
  const m = job.model || {};
  let model;
  if (typeof m.sample === 'string' && m.sample) {
    model = { sample: m.sample };
  } else if (typeof m.file === 'string' && m.file && typeof m.bytes_base64 === 'string') {
    try {
      model = { file: m.file, bytes: fromBase64(m.bytes_base64) };
    } catch {
      throw new Error(`the model “${m.file}” in it is not base64 (the file was changed after saving)`);
    }
  } else {
    throw new Error('it names no model (a "sample", or a "file" with its "bytes_base64")');
  }
  const p = job.parameters;
  if (!p || typeof p !== 'object' || Array.isArray(p)) throw new Error('its "parameters" are not an object of key: value');
  const parameters = {};
  for (const [k, v] of Object.entries(p)) parameters[k] = String(v);
  return { model, parameters, planned: job.planned === true };
}
