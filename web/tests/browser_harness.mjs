// What the browser tests share: the list of checks, a `uh` server started on a free loopback port
// (its URL read from what it prints), and a run on Debian's Chromium headless (never a downloaded
// browser) that checks the page logs no errors and fetches nothing from elsewhere.
import { spawn } from 'node:child_process';
import { chromium } from 'playwright-core';

const failures = [];
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
