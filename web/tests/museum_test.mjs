// Vive's browser client in Debian's Chromium (headless, driven by playwright-core; never a
// downloaded browser): `uh museum serve` on a free loopback port with a seed and a short round,
// the page joined as Vive and driven with the keyboard, Phantom played by a scripted client (a
// second page's WebSocket that judges whatever lands on the table). Checks that the page draws
// the museum (the canvas is not blank), Falcon's pictures are rendered, snapshots arrive and the
// timer runs, Vive moves when keys are held (the prediction and the server agree where she is),
// the guards are drawn between snapshots (interpolated, on the path the snapshots trace), the keys
// can be remapped, the summary arrives at the end, and the console shows no errors. Writes two
// screenshots: the museum view and Falcon's panel.
//
//   node museum_test.mjs UH_BINARY OUT_DIR
import path from 'node:path';
import { check, runBrowserTest, startServer } from './browser_harness.mjs';

const [uhBinary, outDir] = process.argv.slice(2);
if (!uhBinary || !outDir) {
  console.error('usage: node museum_test.mjs UH_BINARY OUT_DIR');
  process.exit(2);
}
const kRoundMinutes = 0.3;  // 18 s of play: enough to walk, watch the guards and see the end

const server = await startServer(uhBinary, ['museum', 'serve', '--port', '0', '--seed', '2', '--minutes', String(kRoundMinutes)],
                                 /Vive plays in a browser at (http:\/\/127\.0\.0\.1:\d+\/)/);
const url = server.url;

// For each element matching `selector` (a canvas or an image): the share of its pixels that differ
// from its commonest colour (the background), and how many colours it has
function pixelStats(selector) {
  return [...document.querySelectorAll(selector)].map((element) => {
    const copy = document.createElement('canvas');
    copy.width = element.naturalWidth || element.width;
    copy.height = element.naturalHeight || element.height;
    const context = copy.getContext('2d');
    context.drawImage(element, 0, 0);
    const { data } = context.getImageData(0, 0, copy.width, copy.height);
    const counts = new Map();
    for (let i = 0; i < data.length; i += 4) {
      const key = (data[i] >> 3) << 15 | (data[i + 1] >> 3) << 10 | (data[i + 2] >> 3) << 5 | (data[i + 3] >> 3);
      counts.set(key, (counts.get(key) || 0) + 1);
    }
    return { variety: 1 - Math.max(...counts.values()) / (data.length / 4), colours: counts.size };
  });
}

await runBrowserTest('museum browser test', server, { width: 800, height: 500 }, async ({ page, browser }) => {
  await page.goto(url);
  await page.waitForFunction(() => window.uhMuseum && window.uhMuseum.connected && window.uhMuseum.snapshot, null, { timeout: 15000 });
  const waiting = await page.evaluate(() => window.uhMuseum.snapshot.phase);
  check(waiting === 'waiting', `the page joins as Vive and the round waits for Phantom (${waiting})`);

  // Phantom: a scripted client in a page of its own; it judges every piece that reaches the table
  const phantom = await browser.newPage();
  await phantom.goto(`${url}artifacts/none`).catch(() => {});
  await phantom.evaluate(() => {
    const ws = new WebSocket(`ws://${location.host}/ws`);
    const judged = new Set();
    ws.onopen = () => ws.send(JSON.stringify({ type: 'hello', protocol: 1, role: 'phantom' }));
    ws.onmessage = (event) => {
      const m = JSON.parse(event.data);
      if (m.type === 'snapshot' && m.table.length > 0 && !judged.has(m.table[0].item)) {
        judged.add(m.table[0].item);
        ws.send(JSON.stringify({ type: 'verdict', item: m.table[0].item, verdict: 'genuine' }));
      }
    };
  });
  await page.waitForFunction(() => window.uhMuseum.snapshot.phase === 'playing', null, { timeout: 10000 });
  check(true, 'the round plays once Phantom joins');

  const start = await page.evaluate(() => ({
    welcome: !!window.uhMuseum.welcome,
    snapshots: window.uhMuseum.snapshots,
    timeLeft: window.uhMuseum.snapshot.time_left_s,
    timer: document.getElementById('timer').textContent,
    predicted: [...window.uhMuseum.predicted],
    server: [...window.uhMuseum.snapshot.vive.pos],
    tick: window.uhMuseum.snapshot.tick,
    targets: window.uhMuseum.welcome.targets,
    rules: window.uhMuseum.welcome.level.rules,
  }));
  // distances are checked against the game time the snapshots report, never the wall clock's
  const gameSeconds = (fromTick, toTick) => (toTick - fromTick) * start.rules.tick_s;

  // Falcon's pictures: one per target, rendered (not a flat square)
  await page.waitForFunction((n) => Object.keys(window.uhMuseum.pictures).length >= n &&
    [...document.querySelectorAll('#targets img')].every((img) => img.complete && img.naturalWidth > 0), start.targets.length, { timeout: 15000 });
  const pictures = (await page.evaluate(pixelStats, '#targets img')).map((stats) => stats.variety);
  check(pictures.length === start.targets.length && pictures.every((share) => share > 0.05 && share < 0.9),
        `Falcon shows a picture of each target (${start.targets.join(', ')}: ${pictures.map((p) => `${(100 * p).toFixed(0)} %`).join(', ')} of each picture is the piece)`);

  // Vive walks forward (east, out of the loading dock) for 1.5 s, then stops
  await page.keyboard.down('w');
  await page.waitForTimeout(1500);
  const walking = await page.evaluate(() => ({ predicted: [...window.uhMuseum.predicted], server: [...window.uhMuseum.snapshot.vive.pos] }));
  await page.keyboard.up('w');
  // reconciliation: once the server has her standing still, the prediction settles on its position
  const settled = await page.waitForFunction(() => {
    const m = window.uhMuseum;
    return Math.hypot(m.predicted[0] - m.snapshot.vive.pos[0], m.predicted[1] - m.snapshot.vive.pos[1]) < 0.02;
  }, null, { timeout: 5000 }).then(() => true, () => false);
  const after = await page.evaluate(() => ({
    predicted: [...window.uhMuseum.predicted],
    server: [...window.uhMuseum.snapshot.vive.pos],
    tick: window.uhMuseum.snapshot.tick,
    snapshots: window.uhMuseum.snapshots,
    timeLeft: window.uhMuseum.snapshot.time_left_s,
    timer: document.getElementById('timer').textContent,
    jumps: window.uhMuseum.jumps,
  }));
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
  const walked = dist(after.server, start.server);
  const walkLimit = start.rules.walk_speed * gameSeconds(start.tick, after.tick) + 0.05;
  check(walked > 1.0 && walked <= walkLimit,
        `Vive walks when W is held (the server has her ${walked.toFixed(2)} m on, at most walking speed: ${walkLimit.toFixed(2)} m in that game time)`);
  check(dist(walking.predicted, start.predicted) > 0.8, `the prediction moves her before the server answers (${dist(walking.predicted, start.predicted).toFixed(2)} m while walking)`);
  check(settled && after.jumps === 0,
        `prediction and server agree once she stops (${(100 * dist(after.predicted, after.server)).toFixed(1)} cm apart, ${after.jumps} jumps)`);
  check(after.snapshots > start.snapshots + 30, `snapshots arrive (${after.snapshots - start.snapshots} while she walked)`);
  check(after.timeLeft < start.timeLeft - 1.5 && after.timer !== start.timer,
        `the timer runs (${start.timeLeft.toFixed(1)} s -> ${after.timeLeft.toFixed(1)} s, shown ${start.timer} -> ${after.timer})`);

  // the guards: drawn between snapshots, on the path the snapshots trace
  await page.evaluate(() => { window.uhMuseum.trace = []; });
  await page.waitForTimeout(2000);
  const trace = await page.evaluate(() => { const t = window.uhMuseum.trace; window.uhMuseum.trace = null; return t; });
  const snapshots = trace.filter((e) => e.snapshot).map((e) => e.snapshot);
  // frames drawn before the third traced snapshot may show a moment between earlier ones
  let seen = 0;
  const frames = trace.filter((e) => (e.snapshot ? ++seen : 0) || (e.drawn && seen >= 3)).filter((e) => e.drawn).map((e) => e.drawn);
  // without interpolation every drawn position would be a snapshot's; guards standing still
  // (looking around where they heard something) say nothing either way and are left out
  let between = 0, offPath = 0, drawn = 0;
  for (let g = 0; g < (snapshots[0] || []).length; g++) {
    const path = snapshots.map((s) => s[g]);
    let length = 0;
    for (let k = 0; k + 1 < path.length; k++) length += dist(path[k], path[k + 1]);
    if (length < 0.2) continue;
    for (const f of frames) {
      const p = f[g];
      if (!p) continue;
      drawn++;
      const nearestPoint = Math.min(...path.map((q) => dist(p, q)));
      let nearestSegment = Infinity;
      for (let k = 0; k + 1 < path.length; k++) {
        const [a, b] = [path[k], path[k + 1]];
        const abx = b[0] - a[0], aby = b[1] - a[1];
        const len2 = abx * abx + aby * aby;
        const u = len2 > 0 ? Math.max(0, Math.min(1, ((p[0] - a[0]) * abx + (p[1] - a[1]) * aby) / len2)) : 0;
        nearestSegment = Math.min(nearestSegment, dist(p, [a[0] + u * abx, a[1] + u * aby]));
      }
      if (nearestPoint > 0.002) between++;
      if (nearestSegment > 0.02) offPath++;
    }
  }
  check(frames.length >= 8 && snapshots.length >= 20, `frames drawn while the guards were traced (${frames.length} frames, ${snapshots.length} snapshots in 2 s)`);
  check(drawn > 0 && between / drawn > 0.25 && offPath <= drawn * 0.1,
        `the walking guards are interpolated: ${between} of ${drawn} drawn positions lie between snapshots, ${offPath} off the snapshots' path`);

  const [look] = await page.evaluate(pixelStats, '#view canvas');
  check(look.variety > 0.2 && look.colours > 50, `the canvas is not blank (${(100 * look.variety).toFixed(0)} % of pixels away from the commonest colour, ${look.colours} colours)`);
  await page.screenshot({ path: path.join(outDir, 'museum_vive.png') });
  await page.locator('#falcon').screenshot({ path: path.join(outDir, 'museum_falcon.png') });

  // remapping: 'forward' to I, kept in localStorage, and walking with it
  await page.keyboard.press('o');
  await page.click('#settings button[data-action="forward"]');
  await page.keyboard.press('i');
  const stored = await page.evaluate(() => JSON.parse(localStorage.getItem('uh-museum-keys')).forward);
  await page.click('#close-settings');
  const position = () => page.evaluate(() => ({ at: [...window.uhMuseum.snapshot.vive.pos], tick: window.uhMuseum.snapshot.tick }));
  const settle = () => page.waitForFunction(() => {
    const m = window.uhMuseum;
    return Math.hypot(m.predicted[0] - m.snapshot.vive.pos[0], m.predicted[1] - m.snapshot.vive.pos[1]) < 0.02;
  }, null, { timeout: 5000 });
  const before = await position();
  await page.keyboard.down('i');
  await page.waitForTimeout(500);
  await page.keyboard.up('i');
  await settle();
  const withI = await position();
  await page.keyboard.down('w');  // no longer bound
  await page.waitForTimeout(500);
  await page.keyboard.up('w');
  await page.waitForTimeout(300);
  const withW = await position();
  const iWalked = dist(withI.at, before.at);
  check(JSON.stringify(stored) === '["KeyI"]' && iWalked > 0.3 && iWalked <= start.rules.walk_speed * gameSeconds(before.tick, withI.tick) + 0.05 &&
        dist(withW.at, withI.at) < 1e-9,
        `keys remap: forward is now I (stored ${JSON.stringify(stored)}), Vive walks ${iWalked.toFixed(2)} m with it and W moves her ${dist(withW.at, withI.at).toFixed(3)} m`);

  // the end: the summary arrives and is shown
  await page.waitForFunction(() => window.uhMuseum.summary, null, { timeout: kRoundMinutes * 60 * 1000 + 15000 });
  const summary = await page.evaluate(() => ({
    summary: window.uhMuseum.summary,
    shown: getComputedStyle(document.getElementById('summary')).display !== 'none',
    points: document.getElementById('summary-points').textContent,
    ended: window.uhMuseum.events.some((e) => e.event === 'round_ended'),
  }));
  check(summary.shown && summary.ended && Number.isInteger(summary.summary.score.points) &&
        summary.points === `${summary.summary.score.points} points` && summary.summary.targets.length === start.targets.length,
        `the round ends and the summary is shown (${summary.points}, ${summary.summary.seconds_played.toFixed(0)} s played)`);
  await page.screenshot({ path: path.join(outDir, 'museum_summary.png') });
});
