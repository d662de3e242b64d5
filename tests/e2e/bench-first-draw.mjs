// Benchmark (issue 19): how long a visitor waits for the first model, from the navigation's
// start to the page's first WebGL draw of it (the element's data-first-draw-at-ms, read off
// the page's own clock), in fresh browser contexts of Debian's headless Chromium, as the
// browser tests run it. Target: ≤ 1000 ms in every run of six.
// Usage: scripts/build-wasm && node tests/e2e/bench-first-draw.mjs [RUNS]
import { timeFreshLoads } from './bench-page.mjs';

await timeFreshLoads({
  runs: Number(process.argv[2] || 6),
  path: '',
  selector: 'tspath-planner[data-state="model-loaded"]',
  read: async (page) => [
    Number(await page.getAttribute('tspath-planner', 'data-first-draw-at-ms')),
    `${await page.getAttribute('tspath-planner', 'data-renderer')} view`,
  ],
  label: 'first model drawn from navigation',
  targetMs: 1000,
});
