// Number formatting for the page: every number with its unit.

export const mm = (x, d = 3) => (Number.isFinite(x) ? `${x.toFixed(d)} mm` : '—');
export const int = (x) => (Number.isFinite(x) ? Math.round(x).toLocaleString('en-US') : '—');
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
