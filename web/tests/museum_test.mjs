// Vive's browser client in Debian's Chromium (headless, driven by playwright-core; never a
// downloaded browser): `uh museum serve` on a free loopback port with a seed and a short round,
// the page joined as Vive and driven with the keyboard, Phantom played by the automated blind
// player (`uh museum play --bot phantom`: it studies the targets' genuine pieces, then judges each
// piece in its hands by touch on a simulated device). Checks that the page draws
// the museum (the canvas is not blank), Falcon's pictures are rendered, snapshots arrive and the
// timer runs, Vive moves when keys are held (the prediction and the server agree where she is),
// the guards are drawn between snapshots (interpolated, on the path the snapshots trace), the keys
// can be remapped, the summary arrives at the end, and the console shows no errors. Writes two
// screenshots: the museum view and Falcon's panel.
//
//   node museum_test.mjs UH_BINARY OUT_DIR
import { spawn } from 'node:child_process';
import path from 'node:path';
import { check, pixelStats, runBrowserTest, startServer } from './browser_harness.mjs';

const [uhBinary, outDir] = process.argv.slice(2);
if (!uhBinary || !outDir) {
  console.error('usage: node museum_test.mjs UH_BINARY OUT_DIR');
  process.exit(2);
}
const kRoundMinutes = 1;  // 60 s of play: enough to walk, watch the guards, a heist, a verdict by touch and the end
// the blind bot studies the targets before it sits down (the round waits) and judges a piece by touch:
// seconds of CPU each, more on a busy machine
const kPhantomPatience = 150000;

const server = await startServer(uhBinary, ['museum', 'serve', '--port', '0', '--seed', '2', '--minutes', String(kRoundMinutes)],
                                 /Vive plays in a browser at (http:\/\/127\.0\.0\.1:\d+\/)/);
const url = server.url;

await runBrowserTest('museum browser test', server, { width: 800, height: 500 }, async ({ page, browser }) => {
  await page.goto(url);
  await page.waitForFunction(() => window.uhMuseum && window.uhMuseum.connected && window.uhMuseum.snapshot, null, { timeout: 15000 });
  const waiting = await page.evaluate(() => window.uhMuseum.snapshot.phase);
  check(waiting === 'waiting', `the page joins as Vive and the round waits for Phantom (${waiting})`);

  // Phantom: the automated blind player, a process of its own joining the server
  const phantomBot = () => {
    const bot = spawn(uhBinary, ['museum', 'play', '--bot', 'phantom', '--server', url, '--seed', '2'],
                      { stdio: ['ignore', 'pipe', 'inherit'] });
    bot.output = '';
    bot.stdout.on('data', (chunk) => { bot.output += chunk; });
    bot.exited = new Promise((resolve) => bot.on('exit', (code, signal) => resolve({ code, signal })));
    return bot;
  };
  let phantom = phantomBot();
  await page.waitForFunction(() => window.uhMuseum.snapshot.phase === 'playing', null, { timeout: kPhantomPatience });
  check(true, 'the round plays once Phantom joins');

  const round = await page.evaluate(() => ({
    targets: window.uhMuseum.welcome.targets,
    rules: window.uhMuseum.welcome.level.rules,
  }));
  // distances are checked against the game time the snapshots report, never the wall clock's
  const gameSeconds = (fromTick, toTick) => (toTick - fromTick) * round.rules.tick_s;
  const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
  // a wait that says, when it times out, what it waited for and where the round stood
  const waitFor = (what, fn, arg, timeout) => page.waitForFunction(fn, arg, { timeout }).catch(async () => {
    const where = await page.evaluate(() => JSON.stringify({
      vive: window.uhMuseum.snapshot.vive, predicted: window.uhMuseum.predicted, guards: window.uhMuseum.snapshot.guards,
      events: window.uhMuseum.events.map((e) => e.event), phase: window.uhMuseum.snapshot.phase,
    }));
    throw new Error(`timed out waiting for ${what}: ${where}`);
  });

  // Falcon's pictures: one per target, rendered (not a flat square)
  await page.waitForFunction((n) => Object.keys(window.uhMuseum.pictures).length >= n &&
    [...document.querySelectorAll('#targets img')].every((img) => img.complete && img.naturalWidth > 0), round.targets.length, { timeout: 15000 });
  const pictures = (await page.evaluate(pixelStats, { selector: '#targets img' })).map((stats) => stats.variety);
  check(pictures.length === round.targets.length && pictures.every((share) => share > 0.05 && share < 0.9),
        `Falcon shows a picture of each target (${round.targets.join(', ')}: ${pictures.map((p) => `${(100 * p).toFixed(0)} %`).join(', ')} of each picture is the piece)`);

  // a scripted heist, walked by the page (its autopilot: the same prediction and moves as the keys)
  // and acted with the use key: from the entrance to the case in front of the south wall of the
  // great hall, break it, take the piece, run back to Phantom's table and deliver it. The hall's
  // guard walks the rectangle (9, 3.5)-(17.5, 5.5) of the easy level, either way round. Vive sets
  // off as it starts east along either long side (x 9.2-10.5): she follows it unseen (it faces
  // away) and waits at the case, where it cannot see her from its other legs (too steep an angle).
  const kCase = 1;
  const heist = await page.evaluate((c) => ({
    at: window.uhMuseum.welcome.level.cases[c],
    piece: window.uhMuseum.snapshot.cases[c].item,
    tick: window.uhMuseum.snapshot.tick,
  }), kCase);
  check(heist.at[0] === 12 && heist.at[1] === 1.5 && heist.piece !== null,
        `case ${kCase} at (${heist.at}) holds a piece (${heist.piece ? heist.piece.kind : 'none'})`);
  await page.waitForFunction(() => {
    const g = window.uhMuseum.snapshot.guards[0];
    return g.mode === 'patrol' && g.facing[0] > 0.99 && g.pos[0] > 9.2 && g.pos[0] < 10.5;
  }, null, { timeout: 30000 });
  const setOff = await page.evaluate(() => window.uhMuseum.snapshot.tick);
  console.log(`     (the heist sets off ${gameSeconds(heist.tick, setOff).toFixed(1)} s of game time after Falcon's pictures)`);
  await page.evaluate(() => { window.uhMuseum.autopilot = { path: [[6.5, 3], [7.6, 2.6], [12, 2.2]], run: false }; });
  await waitFor('the walk to the case', () => window.uhMuseum.autopilot === null, null, 20000);
  await waitFor('the server to have her at the case', () => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - 12, window.uhMuseum.snapshot.vive.pos[1] - 2.2) < 0.2, null, 5000);
  const rings = await page.evaluate(() => window.uhMuseum.ringsDrawn);
  const prompt = await page.evaluate(() => document.getElementById('prompt').textContent);
  // the guard hears the glass: she breaks it once the guard is 6 m or more away, takes the piece
  // with a second E at once (the page counts its break as done until a snapshot says so) and runs
  await waitFor('the guard 6 m away', (at) => {
    const g = window.uhMuseum.snapshot.guards[0];
    return Math.hypot(g.pos[0] - at[0], g.pos[1] - at[1]) >= 6;
  }, heist.at, 25000);
  await page.keyboard.press('e');
  await page.keyboard.press('e');
  await page.evaluate(() => { window.uhMuseum.autopilot = { path: [[7.6, 2.6], [6.5, 3], [4.7, 3]], run: true }; });
  await waitFor('the piece taken', () => window.uhMuseum.events.some((e) => e.event === 'item_taken'), null, 5000);
  const broken = await page.evaluate(() => ({
    events: window.uhMuseum.events.map((e) => e.event),
    rings: window.uhMuseum.ringsDrawn,
    captions: document.getElementById('captions').textContent,
  }));
  check(/break the case/.test(prompt) && broken.events.includes('case_broken') && broken.rings > rings &&
        /Glass breaks: heard within 8 m/.test(broken.captions),
        `E breaks the case the prompt names ("${prompt}"): a noise ring is drawn and captioned`);
  await waitFor('a snapshot of her carrying it', () => window.uhMuseum.snapshot.vive.carried.length === 1 || window.uhMuseum.snapshot.vive.times_caught > 0, null, 5000);
  const carried = await page.evaluate(() => [...document.querySelectorAll('#carried .slot img')].map((img) => img.alt));
  check(carried.length === 1 && carried[0] === `the ${heist.piece.kind} you carry`, `E takes the piece; its picture shows in Vive's hands (${carried})`);
  const ran = await page.waitForFunction(() => window.uhMuseum.running, null, { timeout: 5000 }).then(() => true, () => false);
  await waitFor('the run back', () => window.uhMuseum.autopilot === null, null, 20000);
  await waitFor('the server to have her at the table', () => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - 4.7, window.uhMuseum.snapshot.vive.pos[1] - 3) < 0.2, null, 5000);
  const deliverPrompt = await page.evaluate(() => document.getElementById('prompt').textContent);
  await page.keyboard.press('e');
  await waitFor('the delivery', () => window.uhMuseum.events.some((e) => e.event === 'items_delivered'), null, 5000);
  const home = await page.evaluate(() => ({
    events: window.uhMuseum.events.map((e) => e.event),
    caught: window.uhMuseum.snapshot.vive.times_caught,
    table: document.getElementById('table-line').textContent,
  }));
  check(ran && /deliver to Phantom/.test(deliverPrompt) && home.events.includes('items_delivered') && home.caught === 0,
        `she runs back uncaught and delivers (${home.events.join(', ')}; ${home.table})`);

  // Vive walks forward (west, the way she came: into the loading dock) for 1.5 s, then stops
  const start = await page.evaluate(() => ({
    snapshots: window.uhMuseum.snapshots,
    timeLeft: window.uhMuseum.snapshot.time_left_s,
    timer: document.getElementById('timer').textContent,
    predicted: [...window.uhMuseum.predicted],
    server: [...window.uhMuseum.snapshot.vive.pos],
    tick: window.uhMuseum.snapshot.tick,
  }));
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
  const walked = dist(after.server, start.server);
  const walkLimit = round.rules.walk_speed * gameSeconds(start.tick, after.tick) + 0.05;
  check(walked > 1.0 && walked <= walkLimit,
        `Vive walks when W is held (the server has her ${walked.toFixed(2)} m on, at most walking speed: ${walkLimit.toFixed(2)} m in that game time)`);
  check(dist(walking.predicted, start.predicted) > 0.8, `the prediction moves her before the server answers (${dist(walking.predicted, start.predicted).toFixed(2)} m while walking)`);
  check(settled && after.jumps === 0,
        `prediction and server agree once she stops (${(100 * dist(after.predicted, after.server)).toFixed(1)} cm apart, ${after.jumps} jumps)`);
  check(after.snapshots > start.snapshots + 30, `snapshots arrive (${after.snapshots - start.snapshots} while she walked)`);
  check(after.timeLeft < start.timeLeft - 1.5 && after.timer !== start.timer,
        `the timer runs (${start.timeLeft.toFixed(1)} s -> ${after.timeLeft.toFixed(1)} s, shown ${start.timer} -> ${after.timer})`);

  // Phantom drops out: the round pauses (the page says so, the timer stands); a new hello resumes it
  phantom.kill('SIGTERM');
  await phantom.exited;
  await waitFor('the pause', () => window.uhMuseum.snapshot.phase === 'paused', null, 5000);
  const paused = await page.evaluate(() => ({ status: document.getElementById('status').textContent, left: window.uhMuseum.snapshot.time_left_s, at: [...window.uhMuseum.predicted] }));
  await page.waitForTimeout(500);
  const pausedLater = await page.evaluate(() => ({ left: window.uhMuseum.snapshot.time_left_s, at: [...window.uhMuseum.predicted] }));
  phantom = phantomBot();
  await waitFor('the round to resume', () => window.uhMuseum.snapshot.phase === 'playing', null, kPhantomPatience);
  // the new Phantom is handed the piece on the table and judges it by touch
  await waitFor("Phantom's verdict", () => window.uhMuseum.events.some((e) => e.event === 'verdict'), null, kPhantomPatience);
  check(paused.status === 'paused: Phantom dropped out' && pausedLater.left === paused.left && dist(pausedLater.at, paused.at) < 1e-9,
        `Phantom dropping out pauses the round ("${paused.status}", the timer stands at ${paused.left.toFixed(1)} s) and a new hello resumes it`);

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

  // facing east again, through the dock door into the great hall
  await page.evaluate(() => { window.uhMuseum.autopilot = { path: [[3.6, 3.2]], run: false }; });
  await waitFor('the turn to the east', () => window.uhMuseum.autopilot === null, null, 10000);
  const [look] = await page.evaluate(pixelStats, { selector: '#view canvas' });
  check(look.variety > 0.2 && look.deviation > 10,
        `the canvas is not blank (${(100 * look.variety).toFixed(0)} % of pixels away from the commonest colour, brightness varies by ${look.deviation.toFixed(0)} of 255)`);
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
  check(JSON.stringify(stored) === '["KeyI"]' && iWalked > 0.3 && iWalked <= round.rules.walk_speed * gameSeconds(before.tick, withI.tick) + 0.05 &&
        dist(withW.at, withI.at) < 1e-9,
        `keys remap: forward is now I (stored ${JSON.stringify(stored)}), Vive walks ${iWalked.toFixed(2)} m with it and W moves her ${dist(withW.at, withI.at).toFixed(3)} m`);

  // the end: the summary arrives and is shown
  const leftAtEnd = await page.evaluate(() => window.uhMuseum.snapshot.time_left_s);
  console.log(`     (${leftAtEnd.toFixed(1)} s of the round left when the checks were done)`);
  await waitFor('the summary', () => window.uhMuseum.summary, null, kRoundMinutes * 60 * 1000 + 15000);
  const summary = await page.evaluate(() => ({
    summary: window.uhMuseum.summary,
    shown: getComputedStyle(document.getElementById('summary')).display !== 'none',
    points: document.getElementById('summary-points').textContent,
    ended: window.uhMuseum.events.some((e) => e.event === 'round_ended'),
  }));
  const verdict = await page.evaluate(() => window.uhMuseum.events.find((e) => e.event === 'verdict'));
  const outcome = summary.summary.targets.find((t) => t.kind === heist.piece.kind);
  const place = verdict.verdict === 'genuine' ? 'kept' : 'rejected';
  const judged = outcome && (outcome.genuine === place || outcome.forgery === place);
  const right = outcome && (verdict.verdict === 'genuine' ? outcome.genuine === 'kept' : outcome.forgery === 'rejected');
  check(verdict.item === heist.piece.item && judged,
        `the summary has the delivered ${heist.piece.kind} ${place} as the blind bot judged it by touch (${verdict.verdict}: ${right ? 'right' : 'wrong'})`);
  const botEnded = await phantom.exited;
  check(botEnded.code === 0, `the blind bot leaves when the round ends (exit ${botEnded.code}; ${phantom.output.trim().split('\n').pop()})`);
  check(summary.shown && summary.ended && Number.isInteger(summary.summary.score.points) &&
        summary.points === `${summary.summary.score.points} points` && summary.summary.targets.length === round.targets.length,
        `the round ends and the summary is shown (${summary.points}, ${summary.summary.seconds_played.toFixed(0)} s played)`);
  await page.screenshot({ path: path.join(outDir, 'museum_summary.png') });
});
