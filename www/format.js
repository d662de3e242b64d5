// Number formatting for the page: every number with its unit.

export const mm = (x, d = 3) => (Number.isFinite(x) ? `${x.toFixed(d)} mm` : '—');
/** A whole number with commas between thousands (`8,386`), as `toLocaleString('en-US')`
 * writes it, without the locale machinery: its first call took about 30 ms of the page's start. */
export const int = (x) => (Number.isFinite(x) ? String(Math.round(x)).replace(/\B(?=(\d{3})+$)/g, ',') : '—');
export const pct = (x, d = 2) => (Number.isFinite(x) ? `${(100 * x).toFixed(d)} %` : '—');
export const deg = (x, d = 2) => (Number.isFinite(x) ? `${x.toFixed(d)}°` : '—');
export const ms = (x) => (Number.isFinite(x) ? `${Math.round(x)} ms` : '—');

/** Minutes as `12.3 min` or `2 h 05 min`. */
export function minutes(x) {
  if (!Number.isFinite(x)) return '—';
  if (x < 60) return `${x.toFixed(1)} min`;
  const h = Math.floor(x / 60);
  return `${h} h ${String(Math.round(x - 60 * h)).padStart(2, '0')} min`;
}

/** A file size in bytes as text. */
export function bytes(n) {
  if (n < 1024) return `${n} B`;
  if (n < 1048576) return `${(n / 1024).toFixed(1)} KB`;
  return `${(n / 1048576).toFixed(1)} MB`;
}

/** Decimals that show `x` to about two significant digits, and at least `least`. */
function decimalsFor(x, least) {
  if (!(Math.abs(x) > 0)) return least;
  return Math.min(8, Math.max(least, 1 - Math.floor(Math.log10(Math.abs(x)))));
}

/** A small or large length with about two significant digits: `0.0016 mm`, `12.50 mm`. */
export const mmSig = (x) => (Number.isFinite(x) ? `${x.toFixed(decimalsFor(x, 2))} mm` : '—');

/** An area: `0.265 mm²`, `8924.90 mm²`, `0 mm²`. */
export function area(x) {
  if (!Number.isFinite(x)) return '—';
  if (x === 0) return '0 mm²';
  return `${x.toFixed(Math.abs(x) >= 1 ? 2 : decimalsFor(x, 2) + 1)} mm²`;
}

/** A share of a whole as a percentage, never rounded to a misleading 0: `0.06 %`, `< 0.01 %`. */
export function share(part, whole) {
  if (!(Number.isFinite(part) && whole > 0)) return '—';
  const x = part / whole;
  if (x === 0) return '0 %';
  if (x < 1e-4) return '< 0.01 %';
  return pct(x);
}
