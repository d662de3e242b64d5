// Short definitions of the terms the page uses, for students and for engineers new to
// T-splines. The page marks each term where it appears (hover or focus shows the
// definition) and lists them all under "Glossary".

/** [term, definition]; the term as it is written on the page (matched case-insensitively,
 * longest first, a plural "s" allowed). */
export const GLOSSARY = [
  ['CL point', 'Cutter location: where the ball-end\u2019s centre is (the tool tip is one radius below it along the tool axis).'],
  ['CC point', 'Cutter contact: the point where the ball touches the surface.'],
  ['scallop', 'The ridge of material left between two neighbouring passes of a ball-end mill; its height is the finish asked for.'],
  ['chordal tolerance', 'How far a straight move may stray from the curved surface it replaces; smaller means more, shorter moves.'],
  ['patch', 'A four-sided piece of the surface with its own (u, v) parameters; the isoparametric strategy cuts patch by patch.'],
  ['extraordinary point', 'A vertex of the control mesh where other than four faces meet; patches meet there and the surface is less regular.'],
  ['T-junction', 'A vertex of a T-spline\u2019s control mesh where a line of control points ends on another: it lets a T-spline add detail locally.'],
  ['control mesh', 'The cage of control points that defines a T-spline or subdivision surface; the surface follows it without passing through it.'],
  ['reversal', 'A place where the cutting direction turns back by more than 90\u00b0: each one makes the machine slow down and stop.'],
  ['retraction', 'The tool leaving the surface up to the safe plane, to come down elsewhere: air time, and a mark where it re-enters.'],
  ['link', 'A move along the surface between two cuts at the cutting feed, instead of lifting the tool.'],
  ['plunge', 'The feed move that brings the tool onto the surface at the start of a cut.'],
  ['feed height', 'Where a rapid approach stops above the cut; from there the tool comes down at the plunge feed.'],
  ['rest area', 'Surface the plan leaves uncut (too tight for the ball, out of reach of the tool axis, facing away): another tool or set-up must do it.'],
  ['tool axis', 'The direction of the tool, from its tip towards the spindle; a three-axis machine keeps it vertical.'],
  ['lead', 'Tilt of the tool axis forward along the feed, away from the surface normal.'],
  ['tilt', 'Tilt of the tool axis sideways, across the feed.'],
  ['stepover', 'The distance between neighbouring passes, set so the scallop stays within its height.'],
  ['work offset', 'G54\u2013G59: the machine register holding where the program\u2019s zero is on the table; the operator sets it by probing.'],
  ['program zero', 'The point the program\u2019s X0 Y0 Z0 refers to, on the part or the stock.'],
  ['stock', 'The block of material the part is cut from.'],
  ['heat map', 'The surface coloured by the scallop the cutting simulation finds: green within the limit, red over it.'],
  ['space-filling curve', 'One continuous path that visits every cell of a grid on the surface, so a part is finished without lifting the tool.'],
  ['watershed', 'Splitting the surface into regions around curvature peaks, as water flows down to basins, to cut each feature its own way.'],
  ['iso-planar', 'Passes where parallel planes cut the surface, as most CAM systems do; here the planes are spaced on a deformed surface so the scallop stays even.'],
];

const escape = (s) => s.replace(/[.*+?^${}()|[\]\\]/g, '\\$&');
const byLength = [...GLOSSARY].sort((a, b) => b[0].length - a[0].length);
const PATTERN = new RegExp(`\\b(${byLength.map(([t]) => escape(t)).join('|')})(s|es)?\\b`, 'i');

/** The definition of `term` (as written, any case, singular or plural), or null. */
export function define(term) {
  const t = term.toLowerCase().replace(/(es|s)$/, '');
  const hit = GLOSSARY.find(([k]) => k.toLowerCase() === term.toLowerCase() || k.toLowerCase() === t);
  return hit ? hit[1] : null;
}

/** Marks glossary terms in `el` (only inside elements matching `within`, if given), each
 * term once (its first place): a focusable span whose title and accessible description are
 * the definition, shown on hover and on focus.
 * Idempotent (marked terms are skipped). */
export function markTerms(el, within = null) {
  const done = new Set([...el.querySelectorAll('.term')].map((t) => t.dataset.definition));
  const doc = el.ownerDocument;
  const walker = doc.createTreeWalker(el, 4 /* NodeFilter.SHOW_TEXT */);
  const nodes = [];
  for (let n = walker.nextNode(); n; n = walker.nextNode()) {
    const parent = n.parentElement;
    if (!parent || parent.closest('.term, option, select, button, input, textarea, summary, a')) continue;
    if (within && !parent.closest(within)) continue;
    nodes.push(n);
  }
  for (const n of nodes) {
    const m = PATTERN.exec(n.data);
    if (!m) continue;
    const def = define(m[0]);
    if (!def || done.has(def)) continue;
    done.add(def);
    const after = n.splitText(m.index);
    after.splitText(m[0].length);
    const span = doc.createElement('span');
    span.className = 'term';
    span.tabIndex = 0;
    span.title = def;
    span.dataset.definition = def;
    span.setAttribute('aria-description', def);
    span.textContent = after.data;
    after.replaceWith(span);
  }
}
