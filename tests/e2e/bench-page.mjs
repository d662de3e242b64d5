// What the page benchmarks share: www/ served on a free port, Debian's headless Chromium
// started as the browser tests start it, and fresh browser contexts timed one after another.
import { chromium } from 'playwright-core';
import { startServer } from '../../scripts/serve.mjs';

/** Loads `path` (after the server's URL) in `runs` fresh contexts; in each, waits for
 * `selector` and takes `read(page)` (ms, or [ms, note]); prints each run and a summary
 * against `targetMs` under `label`. Returns the times. */
export async function timeFreshLoads({ runs, path, selector, read, label, targetMs }) {
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
      await page.goto(`${url}${path}`);
      await page.waitForSelector(selector, { timeout: 60000, state: 'attached' });
      const got = await read(page);
      const [ms, note] = Array.isArray(got) ? got : [got, ''];
      times.push(ms);
      console.log(`run ${i + 1}: ${label} ${ms} ms${note ? ` (${note})` : ''}`);
      await context.close();
    }
  } finally {
    await browser.close();
    server.close();
  }
  const sorted = [...times].sort((a, b) => a - b);
  const over = times.filter((t) => t > targetMs).length;
  console.log(`${label}: median ${sorted[sorted.length >> 1]} ms, max ${sorted[sorted.length - 1]} ms, min ${sorted[0]} ms; ${over} of ${runs} runs over the ${targetMs} ms target`);
  return times;
}
