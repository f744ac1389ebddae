// The live view in Debian's Chromium (headless, driven by playwright-core; never a downloaded
// browser): `uh serve` on a free loopback port, the page loaded, a controlling client (a WebSocket
// opened inside the page) starting the default session. Checks that the page connects, draws the
// scene (the canvas is not blank), that the tool's drawn position changes over time, and that the
// console shows no errors. Writes a screenshot.
//
//   node view_test.mjs UH_BINARY SCREENSHOT.png
import { check, pixelStats, runBrowserTest, startServer } from './browser_harness.mjs';

const [uhBinary, screenshotPath] = process.argv.slice(2);
if (!uhBinary || !screenshotPath) {
  console.error('usage: node view_test.mjs UH_BINARY SCREENSHOT.png');
  process.exit(2);
}

// uh serve on any free port; it prints the URL it listens on
const server = await startServer(uhBinary, ['serve', '--port', '0', '--no-realtime'], /live view: (http:\/\/127\.0\.0\.1:\d+\/)/);
const url = server.url;

await runBrowserTest('view test', server, { width: 960, height: 600 }, async ({ page }) => {
  await page.goto(url);
  await page.waitForFunction(() => window.uhView && window.uhView.connected, null, { timeout: 15000 });
  check(true, 'the page connects to the service');

  // a controlling client: opens and starts the default scene (packed on first use)
  const started = await page.evaluate(() => new Promise((resolve) => {
    const ws = new WebSocket(`ws://${location.host}/ws`);
    window.testController = ws;
    const steps = [{ type: 'hello', protocol: 1 }, { type: 'open' }, { type: 'start', seconds: 60 }];
    ws.onopen = () => ws.send(JSON.stringify(steps.shift()));
    ws.onmessage = (event) => {
      const m = JSON.parse(event.data);
      if (m.type === 'error') resolve(m.message);
      else if (m.type === 'started') resolve('started');
      else if (['welcome', 'opened'].includes(m.type) && steps.length) ws.send(JSON.stringify(steps.shift()));
    };
  }));
  check(started === 'started', `a client starts the default session (${started})`);

  await page.waitForFunction(() => window.uhView.meshes >= 2 && window.uhView.states > 10, null, { timeout: 30000 });
  check(true, 'the view draws the scene\'s meshes and receives states');

  const first = await page.evaluate(() => [...window.uhView.toolDrawn]);
  await page.waitForTimeout(1500);
  const second = await page.evaluate(() => [...window.uhView.toolDrawn]);
  const moved = Math.hypot(second[0] - first[0], second[1] - first[1]);
  check(moved > 2, `the tool's drawn position changes over time (${moved.toFixed(1)} px in 1.5 s)`);

  // not blank: the canvas holds pixels away from its commonest colour (the background)
  const [{ variety: drawn }] = await page.evaluate(pixelStats, { selector: '#view canvas' });
  check(drawn > 0.02, `the canvas is not blank (${(100 * drawn).toFixed(1)} % of pixels drawn)`);
  const panel = await page.evaluate(() => ({
    haptic: document.getElementById('haptic').textContent,
    force: document.getElementById('force').textContent,
  }));
  check(/Hz$/.test(panel.haptic) && /N$/.test(panel.force), `the panel shows rates and force (${panel.haptic}, ${panel.force})`);

  // the screenshot shows a contact when one comes soon (the sweep goes into the bunny)
  await page.waitForFunction(() => window.uhView.forceN > 0.5, null, { timeout: 15000 }).catch(() => {});
  await page.screenshot({ path: screenshotPath });
  await page.evaluate(() => window.testController.close());
});
