// What the browser tests share: the list of checks, a `uh` server started on a free loopback port
// (its URL read from what it prints), and a run on Debian's Chromium headless (never a downloaded
// browser) that checks the page logs no errors and fetches nothing from elsewhere.
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

const failures = [];

// Runs in the page (`page.evaluate(pixelStats, {selector, from, to})`): for each element matching
// `selector` (a canvas or an image), over its columns from `from` to `to` (shares of its width: one
// eye of a stereo canvas), the share of the pixels that differ from their commonest colour (the
// background) and the standard deviation of their brightness
export function pixelStats({ selector, from = 0, to = 1 }) {
  return [...document.querySelectorAll(selector)].map((element) => {
    const width = element.naturalWidth || element.width;
    const copy = document.createElement('canvas');
    copy.width = Math.max(1, Math.floor(width * (to - from)));
    copy.height = element.naturalHeight || element.height;
    const context = copy.getContext('2d');
    context.drawImage(element, -Math.floor(width * from), 0);
    const { data } = context.getImageData(0, 0, copy.width, copy.height);
    const counts = new Map();
    let sum = 0, sumSquares = 0;
    for (let i = 0; i < data.length; i += 4) {
      const brightness = (data[i] + data[i + 1] + data[i + 2]) / 3;
      sum += brightness;
      sumSquares += brightness * brightness;
      const key = (data[i] >> 3) << 15 | (data[i + 1] >> 3) << 10 | (data[i + 2] >> 3) << 5 | (data[i + 3] >> 3);
      counts.set(key, (counts.get(key) || 0) + 1);
    }
    const n = data.length / 4;
    return { variety: 1 - Math.max(...counts.values()) / n, deviation: Math.sqrt(Math.max(0, sumSquares / n - (sum / n) ** 2)) };
  });
}
export function check(condition, what) {
  console.log(`${condition ? 'ok  ' : 'FAIL'} ${what}`);
  if (!condition) failures.push(what);
}

// Starts `uh ARGS...` and resolves to {url, exited} once a line it prints matches `urlPattern`
// (its first group is the URL); `exited` resolves to {code, signal}.
export async function startServer(uhBinary, args, urlPattern) {
  const server = spawn(uhBinary, args, { stdio: ['ignore', 'pipe', 'inherit'] });
  const exited = new Promise((resolve) => server.on('exit', (code, signal) => resolve({ code, signal })));
  const url = await new Promise((resolve, reject) => {
    let out = '';
    server.stdout.on('data', (chunk) => {
      out += chunk;
      const match = out.match(urlPattern);
      if (match) resolve(match[1]);
    });
    server.on('exit', (code) => reject(new Error(`uh ${args[0]} exited with ${code} before listening`)));
    setTimeout(() => reject(new Error(`uh ${args[0]} did not print its URL within 20 s`)), 20000);
  });
  return { url, exited, stop: () => server.kill('SIGTERM') };
}

function launchChromium() {
  return chromium.launch({
    executablePath: '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--disable-background-networking', '--disable-component-update', '--no-first-run'],
  });
}

// Runs `body({page, browser})` on a page of the server's URL, then checks that the page logged no
// console errors and fetched nothing from elsewhere and that the server stops cleanly on SIGTERM;
// prints the outcome and exits with it.
export async function runBrowserTest(name, server, viewport, body) {
  const browser = await launchChromium();
  try {
    const page = await browser.newPage({ viewport });
    const consoleErrors = [];
    page.on('console', (message) => { if (message.type() === 'error') consoleErrors.push(message.text()); });
    page.on('pageerror', (error) => consoleErrors.push(String(error)));
    const foreign = [];
    page.on('request', (request) => {
      if (!request.url().startsWith(server.url) && !request.url().startsWith('ws://127.0.0.1')) foreign.push(request.url());
    });
    await body({ page, browser });
    check(consoleErrors.length === 0, `no console errors${consoleErrors.length ? ': ' + consoleErrors.join(' | ') : ''}`);
    check(foreign.length === 0, `nothing fetched from elsewhere${foreign.length ? ': ' + foreign.join(' ') : ''}`);
  } catch (error) {
    check(false, String(error));
  } finally {
    await browser.close();
    server.stop();
  }
  const { code } = await server.exited;
  check(code === 0, `the server stops cleanly on SIGTERM (exit ${code})`);
  console.log(`${name}: ${failures.length === 0 ? 'passed' : `${failures.length} failed`}`);
  process.exit(failures.length === 0 ? 0 : 1);
}
