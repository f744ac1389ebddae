// The live view in Debian's Chromium (headless, driven by playwright-core; never a downloaded
// browser): `uh serve` on a free loopback port, the page loaded, a controlling client (a WebSocket
// opened inside the page) starting the default session. Checks that the page connects, draws the
// scene (the canvas is not blank), that the tool's drawn position changes over time, and that the
// console shows no errors. Writes a screenshot.
//
//   node view_test.mjs UH_BINARY SCREENSHOT.png
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

const [uhBinary, screenshotPath] = process.argv.slice(2);
if (!uhBinary || !screenshotPath) {
  console.error('usage: node view_test.mjs UH_BINARY SCREENSHOT.png');
  process.exit(2);
}

const failures = [];
function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) failures.push(what);
}

// uh serve on any free port; it prints the URL it listens on
const server = spawn(uhBinary, ['serve', '--port', '0', '--no-realtime'], { stdio: ['ignore', 'pipe', 'inherit'] });
const url = await new Promise((resolve, reject) => {
  let out = '';
  server.stdout.on('data', (chunk) => {
    out += chunk;
    const match = out.match(/live view: (http:\/\/127\.0\.0\.1:\d+\/)/);
    if (match) resolve(match[1]);
  });
  server.on('exit', (code) => reject(new Error(`uh serve exited with ${code} before listening`)));
  setTimeout(() => reject(new Error('uh serve did not print its URL within 20 s')), 20000);
});
const serverExited = new Promise((resolve) => server.on('exit', (code, signal) => resolve({ code, signal })));

const browser = await chromium.launch({
  executablePath: '/usr/bin/chromium',
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
         '--disable-background-networking', '--disable-component-update', '--no-first-run'],
});
try {
  const page = await browser.newPage({ viewport: { width: 960, height: 600 } });
  const consoleErrors = [];
  page.on('console', (message) => { if (message.type() === 'error') consoleErrors.push(message.text()); });
  page.on('pageerror', (error) => consoleErrors.push(String(error)));
  // nothing but the service itself is fetched
  const foreign = [];
  page.on('request', (request) => { if (!request.url().startsWith(url) && !request.url().startsWith('ws://127.0.0.1')) foreign.push(request.url()); });

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

  // not blank: the canvas holds pixels away from the background colour
  const drawn = await page.evaluate(() => {
    const canvas = document.querySelector('#view canvas');
    const copy = document.createElement('canvas');
    copy.width = canvas.width;
    copy.height = canvas.height;
    const context = copy.getContext('2d');
    context.drawImage(canvas, 0, 0);
    const { data } = context.getImageData(0, 0, copy.width, copy.height);
    let different = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (Math.abs(data[i] - 0x15) + Math.abs(data[i + 1] - 0x18) + Math.abs(data[i + 2] - 0x1d) > 30) different++;
    }
    return different / (data.length / 4);
  });
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
  check(consoleErrors.length === 0, `no console errors${consoleErrors.length ? ': ' + consoleErrors.join(' | ') : ''}`);
  check(foreign.length === 0, `nothing fetched from elsewhere${foreign.length ? ': ' + foreign.join(' ') : ''}`);
} catch (error) {
  check(false, String(error));
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
const { code } = await serverExited;
check(code === 0, `uh serve stops cleanly on SIGTERM (exit ${code})`);
console.log(`view test: ${failures.length === 0 ? 'passed' : `${failures.length} failed`}`);
process.exit(failures.length === 0 ? 0 : 1);
