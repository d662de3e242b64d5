// Benchmark (issue 19): from Plan to the final heat map of the keycap at the page's defaults
// (the element's data-plan-to-final-ms: planning, the program, the cutting simulation and
// the heat map drawn, read off the page's own clock), in fresh browser contexts of Debian's
// headless Chromium, as the browser tests run it. Target: ≤ 1500 ms.
// Usage: scripts/build-wasm && node tests/e2e/bench-plan-to-heat.mjs [RUNS]
import { timeFreshLoads } from './bench-page.mjs';

await timeFreshLoads({
  runs: Number(process.argv[2] || 6),
  path: '?model=keycap-convex&plan=1',
  selector: 'tspath-planner[data-verify="done"]',
  read: async (page) => Number(await page.getAttribute('tspath-planner', 'data-plan-to-final-ms')),
  label: 'Plan to the final heat map (keycap-convex, page defaults)',
  targetMs: 1500,
});
