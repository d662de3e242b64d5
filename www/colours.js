// Colours shared by the 3D view, its 2D fallback and the legends: patches, path kinds and the
// scallop heat map. sRGB hex.

/** Surface colour of patch i (cycled). */
export const PATCH_COLOURS = [
  0x7aa6dc, 0xe6a25a, 0x7cc08a, 0xd77a8e, 0xab8fd6, 0xcfc066, 0x6cc0c0, 0xc29878,
  0x9bb4e8, 0xe08d6e, 0x97cf7a, 0xb08bc4,
];

/** Path colour of patch i: a darker shade of its surface colour, readable over it. */
export function pathColour(patch) {
  const c = PATCH_COLOURS[patch % PATCH_COLOURS.length];
  const k = 0.45;
  return (((c >> 16 & 255) * k) << 16) | (((c >> 8 & 255) * k) << 8) | ((c & 255) * k);
}

/** Move kinds (as Plan.moveKinds gives them) and how the path draws them. */
export const KINDS = [
  { name: 'feed', label: 'cutting (colour of its patch)', colour: null, dashed: false },
  { name: 'link', label: 'link on the surface between cuts', colour: 0x111111, dashed: false },
  { name: 'retract', label: 'retraction', colour: 0xd62728, dashed: true },
  { name: 'rapid', label: 'rapid, clear of the model', colour: 0xd62728, dashed: true },
  { name: 'plunge', label: 'plunge onto the surface', colour: 0xff7f0e, dashed: false },
  { name: 'approach', label: 'approach from the feed height, at the plunge feed', colour: 0xff7f0e, dashed: true },
];

export const BACKGROUND = 0xeef1f5;
/** The program-zero triad: X, Y, Z. */
export const ZERO_TRIAD = [0xd62728, 0x2ca02c, 0x1f5fd6];
/** The stock block: its edges, and its faces (translucent). */
export const STOCK = { edge: 0x8a6d3b, face: 0xc8a96e, opacity: 0.12 };

/** The table grid under the part. */
export const GRID = { line: 0xb9c0ca };

/** Standard views: the direction from the model towards the viewer (Z up). Top and bottom
 * lean a hair towards -Y so that +Y is up on the screen and the camera's up stays defined. */
export const VIEWS = {
  top: [0, -1e-4, 1],
  front: [0, -1, 0],
  side: [1, 0, 0],
  iso: [-0.6, -1, 1.1],
};

/** A grid on the plane Z = `box.min[2]` covering `box` (mm) with a margin, at a round
 * spacing (1, 2 or 5 × 10^k mm, about a tenth of the larger side): `{lines, spacing}` with
 * `lines` as x0 y0 z0 x1 y1 z1 per line; null for no box. */
export function tableGrid(box) {
  if (!box) return null;
  const side = Math.max(box.max[0] - box.min[0], box.max[1] - box.min[1], 1e-6);
  const raw = side / 10;
  const p = 10 ** Math.floor(Math.log10(raw));
  const spacing = [1, 2, 5, 10].map((k) => k * p).find((s) => s >= raw);
  const lo = [0, 1].map((k) => Math.floor(box.min[k] / spacing - 1) * spacing);
  const hi = [0, 1].map((k) => Math.ceil(box.max[k] / spacing + 1) * spacing);
  const z = box.min[2];
  const lines = [];
  const n = [0, 1].map((k) => Math.round((hi[k] - lo[k]) / spacing));
  for (let i = 0; i <= n[0]; i++) lines.push(lo[0] + i * spacing, lo[1], z, lo[0] + i * spacing, hi[1], z);
  for (let j = 0; j <= n[1]; j++) lines.push(lo[0], lo[1] + j * spacing, z, hi[0], lo[1] + j * spacing, z);
  return { lines, spacing };
}

/** The 12 edges of the box `{min, max}` (mm) as line segments: x0 y0 z0 x1 y1 z1 each. */
export function boxEdges(b) {
  const c = (i) => [i & 1 ? b.max[0] : b.min[0], i & 2 ? b.max[1] : b.min[1], i & 4 ? b.max[2] : b.min[2]];
  const out = [];
  for (let i = 0; i < 8; i++) {
    for (const bit of [1, 2, 4]) if (!(i & bit)) out.push(...c(i), ...c(i | bit));
  }
  return out;
}

/** Ground of small drawings on the page (the comparison's paths). */
export const BACKGROUND_LIGHT = 0xf8f9fb;
export const EP_COLOUR = 0xffd400;
export const CAGE_COLOUR = 0x303848;

/** Heat-map colour of a value (mm): material left from 0 (blue) to the requested scallop
 * (yellow), more than requested red, gouges magenta, never reached grey. */
export function heatColour(v, scallopMm) {
  if (!Number.isFinite(v)) return 0x9a9a9a;
  if (v < 0) return 0xd01bd0;
  const t = v / scallopMm;
  if (t > 1) return 0xd62728;
  // blue (0) -> cyan (1/3) -> green (2/3) -> yellow (1)
  const stops = [[0x2c, 0x5b, 0xd6], [0x2c, 0xc0, 0xd0], [0x3c, 0xb0, 0x4a], [0xf2, 0xd0, 0x2a]];
  const x = Math.min(1, Math.max(0, t)) * 3;
  const i = Math.min(2, Math.floor(x));
  const f = x - i;
  const c = stops[i].map((a, k) => Math.round(a + (stops[i + 1][k] - a) * f));
  return (c[0] << 16) | (c[1] << 8) | c[2];
}

export const hexCss = (c) => `#${c.toString(16).padStart(6, '0')}`;

/** The space-filling curve's layer: cell outlines, tree links within a patch and across a
 * patch side. */
export const ISFC_LAYER = { cell: 0x1f3b73, tree: 0xd81b60, across: 0xff8f00 };

/** The watershed strategies' layer: rectangle fills by region kind (in the order of
 * `Plan.rectangleKinds()`: background, convex, concave), outlines and direction arrows. */
export const RECT_LAYER = {
  kinds: [
    { name: 'background', label: 'outside feature regions', colour: 0xb9c0ca },
    { name: 'convex', label: 'in convex feature regions (bosses)', colour: 0xe4572e },
    { name: 'concave', label: 'in concave feature regions (dimples)', colour: 0x2e86de },
  ],
  outline: 0x1b1f3b,
  arrow: 0x111111,
};

/** Why part of the surface is left as rest area, in the order of `Plan.restReasons()`
 * (0–3) and with the name the report's rest regions use (`why`). */
export const REST_REASONS = [
  { why: 'faces_away', label: 'faces away from the tool', colour: 0x5b2a86 },
  { why: 'tool_hits', label: 'shank or holder would hit', colour: 0xe07b00 },
  { why: 'too_tight', label: 'tighter than the ball', colour: 0xc2185b },
  { why: 'no_way_out', label: 'no way in or out', colour: 0x00897b },
];
