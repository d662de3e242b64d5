// Browser end-to-end tests: serve www/ on a free port, drive Debian's headless Chromium with
// playwright-core, and check what a user would see. Screenshots go to test-artifacts/e2e/.
// Usage: node tests/e2e/run.mjs   (after scripts/build-wasm)
import { chromium } from 'playwright-core';
import { mkdir, readFile } from 'node:fs/promises';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import { startServer } from '../../scripts/serve.mjs';

const root = fileURLToPath(new URL('../..', import.meta.url));
const shots = join(root, 'test-artifacts', 'e2e');
await mkdir(shots, { recursive: true });

const tests = [];
const test = (name, fn) => tests.push({ name, fn });
function check(cond, message) {
  if (!cond) throw new Error(message);
}

/** Counts canvas pixels that differ from the background colour. */
async function drawnPixels(page) {
  return page.evaluate(() => {
    const c = document.getElementById('view');
    const d = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) {
      if (Math.abs(d[i] - 0xee) + Math.abs(d[i + 1] - 0xf1) + Math.abs(d[i + 2] - 0xf5) > 24) n++;
    }
    return n;
  });
}

test('sample loads, plans, draws and downloads G-code', async (page, url) => {
  const t0 = Date.now();
  await page.goto(url);
  await page.waitForSelector('body[data-state="model-loaded"]', { timeout: 20000 });
  const firstDraw = Date.now() - t0;
  const before = await drawnPixels(page);
  check(before > 10000, `the surface should be drawn, only ${before} pixels differ from the background`);
  await page.screenshot({ path: join(shots, 'model-loaded.png') });

  await page.click('#plan');
  await page.waitForSelector('body[data-state="planned"]', { timeout: 60000 });
  const after = await drawnPixels(page);
  check(after > before, `the path should add drawn pixels (${before} before, ${after} after)`);
  const report = await page.textContent('#report');
  check(/CL points/.test(report) && /mm/.test(report), `the report should show numbers with units: ${report}`);
  await page.screenshot({ path: join(shots, 'planned.png') });

  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#download')]);
  check(download.suggestedFilename() === 'dome.nc', `download name ${download.suggestedFilename()}`);
  const gcode = await readFile(await download.path(), 'utf8');
  check(gcode.includes('G21') && gcode.includes('(model: dome)'), 'G-code header names units and model');
  const feeds = gcode.split('\n').filter((l) => l.startsWith('G1 ')).length;
  check(feeds > 1000, `G-code should hold the planned feed moves, found ${feeds}`);
  check(/M2\s*\n%\s*$/.test(gcode), 'G-code ends the program');
  return `first model drawn ${firstDraw} ms after navigation; ${feeds} G1 lines`;
});

test('a malformed file shows an error and the page stays usable', async (page, url) => {
  await page.goto(url);
  await page.waitForSelector('body[data-state="model-loaded"]', { timeout: 20000 });
  await page.setInputFiles('#file', {
    name: 'broken.json',
    mimeType: 'application/json',
    buffer: Buffer.from('{"format": "tspath-tmesh", "version": 1, "points": [[0, 0'),
  });
  await page.waitForSelector('#status.error', { timeout: 10000 });
  const msg = await page.textContent('#status');
  check(/broken\.json/.test(msg) && /line \d+ column \d+/.test(msg), `error should name file and line: ${msg}`);
  await page.screenshot({ path: join(shots, 'bad-file.png') });
  await page.click('#plan');
  await page.waitForSelector('body[data-state="planned"]', { timeout: 60000 });
  return `error shown: "${msg.trim()}"`;
});

const { server, url } = await startServer(0, '127.0.0.1');
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
  ],
});
let failed = 0;
try {
  for (const { name, fn } of tests) {
    const context = await browser.newContext({ acceptDownloads: true, viewport: { width: 1280, height: 860 } });
    const page = await context.newPage();
    const errors = [];
    page.on('pageerror', (e) => errors.push(e.message));
    const t0 = Date.now();
    try {
      const note = await fn(page, url);
      check(errors.length === 0, `uncaught page errors: ${errors.join('; ')}`);
      console.log(`ok   ${name} (${Date.now() - t0} ms)${note ? ` — ${note}` : ''}`);
    } catch (e) {
      failed++;
      await page.screenshot({ path: join(shots, `FAILED-${tests.indexOf(tests.find((t) => t.name === name))}.png`) }).catch(() => {});
      console.log(`FAIL ${name}: ${e.message}`);
    }
    await context.close();
  }
} finally {
  await browser.close();
  server.close();
}
console.log(`${tests.length - failed} passed, ${failed} failed; screenshots in test-artifacts/e2e/`);
process.exit(failed ? 1 : 0);
