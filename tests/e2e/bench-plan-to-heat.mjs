// Benchmark (issue 19): from Plan to the final heat map of the keycap at the page's defaults
// (the element's data-plan-to-final-ms: planning, the program, the cutting simulation and
// the heat map drawn, read off the page's own clock), in fresh browser contexts of Debian's
// headless Chromium, as the browser tests run it. Target: ≤ 1500 ms.
// Usage: scripts/build-wasm && node tests/e2e/bench-plan-to-heat.mjs [RUNS]
import { chromium } from 'playwright-core';
import { startServer } from '../../scripts/serve.mjs';

const TARGET_MS = 1500;
const runs = Number(process.argv[2] || 6);
const { server, url } = await startServer(0, '127.0.0.1');
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
const times = [];
try {
  for (let i = 0; i < runs; i++) {
    const context = await browser.newContext({ viewport: { width: 1280, height: 860 } });
    const page = await context.newPage();
    await page.goto(`${url}?model=keycap-convex&plan=1`);
    await page.waitForSelector('tspath-planner[data-verify="done"]', { timeout: 60000, state: 'attached' });
    const ms = Number(await page.getAttribute('tspath-planner', 'data-plan-to-final-ms'));
    times.push(ms);
    console.log(`run ${i + 1}: Plan to the final heat map ${ms} ms`);
    await context.close();
  }
} finally {
  await browser.close();
  server.close();
}
const sorted = [...times].sort((a, b) => a - b);
const over = times.filter((t) => t > TARGET_MS).length;
console.log(`Plan to the final heat map (keycap-convex, page defaults): median ${sorted[sorted.length >> 1]} ms, max ${sorted[sorted.length - 1]} ms, min ${sorted[0]} ms; ${over} of ${runs} runs over the ${TARGET_MS} ms target`);
