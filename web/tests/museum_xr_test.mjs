// Vive in VR: the museum page on an emulated headset with two controllers (IWER, the Immersive Web
// Emulation Runtime, bundled into a test copy of the page's script only) in Debian's Chromium
// headless, driven by playwright-core (never a downloaded browser), against `uh museum serve` with
// the automated Phantom (`uh museum play --bot phantom`). The page is the one `uh` serves; only its
// script is swapped for the test copy. Checks that the "Enter VR" button shows where WebXR offers
// `immersive-vr` (and not on the shipped page in a browser without it), the session starts and
// renders both eyes, the left stick walks Vive on the server within walking speed (the comfort
// vignette narrowing the view meanwhile), the right stick turns by snaps and teleports only onto
// walkable floor, the player's own head movement moves the server's Vive (running, and heard, when
// faster than walking), the trigger breaks a case and the grip takes and delivers its piece (the
// server's events arrive, the controllers pulse), the wrist panel shows the timer and Falcon's
// targets, and the whole round ends with the blind bot's verdict in the summary. Writes a picture
// of each eye.
//
//   node museum_xr_test.mjs UH_BINARY OUT_DIR XR_BUNDLE
import { spawn } from 'node:child_process';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { check, pixelStats, runBrowserTest, startServer } from './browser_harness.mjs';

const [uhBinary, outDir, xrBundle] = process.argv.slice(2);
if (!uhBinary || !outDir || !xrBundle) {
  console.error('usage: node museum_xr_test.mjs UH_BINARY OUT_DIR XR_BUNDLE');
  process.exit(2);
}
const kRoundMinutes = 2;
const kPhantomPatience = 150000;  // the blind bot studies the targets before it sits down (seconds of CPU each)
const kIwerMark = 'Offer superseded by a new offerSession call.';  // a string of IWER's, to find it in a bundle

const server = await startServer(uhBinary, ['museum', 'serve', '--port', '0', '--seed', '2', '--minutes', String(kRoundMinutes)],
                                 /Vive plays in a browser at (http:\/\/127\.0\.0\.1:\d+\/)/);
const url = server.url;
const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1]);
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

await runBrowserTest('museum VR test', server, { width: 1000, height: 500 }, async ({ page, browser }) => {
  // the shipped script carries no emulator
  const shipped = await (await fetch(`${url}museum.js`)).text();
  const test = readFileSync(xrBundle, 'utf8');
  check(!shipped.includes(kIwerMark) && test.includes(kIwerMark), 'the emulator is in the test copy of the script only, never in the page uh serves');

  await page.route(`${url}museum.js`, (route) => route.fulfill({ body: test, contentType: 'text/javascript' }));
  await page.goto(url);
  await page.waitForFunction(() => window.uhMuseum && window.uhMuseum.connected && window.uhMuseum.snapshot, null, { timeout: 15000 });
  await page.waitForFunction(() => window.uhMuseum.xr.supported, null, { timeout: 5000 }).catch(() => {});
  const button = await page.evaluate(() => getComputedStyle(document.getElementById('vr-panel')).display !== 'none');
  check(button, 'the "Enter VR" button shows where WebXR offers immersive-vr');

  // the blind bot joins while Vive puts the headset on
  const phantom = spawn(uhBinary, ['museum', 'play', '--bot', 'phantom', '--server', url, '--seed', '2'], { stdio: ['ignore', 'pipe', 'inherit'] });
  phantom.output = '';
  phantom.stdout.on('data', (chunk) => { phantom.output += chunk; });
  phantom.exited = new Promise((resolve) => phantom.on('exit', (code, signal) => resolve({ code, signal })));

  await page.click('#enter-vr');
  await page.waitForFunction(() => window.uhMuseum.xr.presenting && window.uhMuseum.xr.frames > 10 &&
    window.uhMuseum.xr.hands.left && window.uhMuseum.xr.hands.right, null, { timeout: 20000 });
  const entered = await page.evaluate(() => ({ head: window.uhMuseum.xr.head, body: window.uhMuseum.predicted, frames: window.uhMuseum.xr.frames }));
  check(dist(entered.head, entered.body) < 0.05, `the session starts with two controllers and renders (${entered.frames} frames); the head stands where Vive does (${entered.head.map((v) => v.toFixed(2))})`);

  // drive the emulated devices: the head's yaw (level frame, from east) and place, the sticks and buttons
  const device = {
    // turns the headset to face `angle` (level frame) given the rig's turn, keeping where it is
    face: (angle) => page.evaluate((a) => {
      const psi = a - Math.PI / 2 - window.uhMuseum.xr.rigYaw;
      window.uhXRDevice.quaternion.set(0, Math.sin(psi / 2), 0, Math.cos(psi / 2));
    }, angle),
    move: (dx, dz, dy = 0) => page.evaluate(([x, z, y]) => {
      const p = window.uhXRDevice.position;
      p.set(p.x + x, p.y + y, p.z + z);
    }, [dx, dz, dy]),
    stick: (hand, x, y, pressed = false) => page.evaluate(([h, sx, sy, down]) => {
      const c = window.uhXRDevice.controllers[h];
      c.updateAxes('thumbstick', sx, sy);
      c.updateButtonValue('thumbstick', down ? 1 : 0);
    }, [hand, x, y, pressed]),
    // a press held over a few frames (the trigger and grip act on their own events, at once)
    press: async (hand, button, holdMs = 100) => {
      await page.evaluate(([h, b]) => window.uhXRDevice.controllers[h].updateButtonValue(b, 1), [hand, button]);
      await sleep(holdMs);
      await page.evaluate(([h, b]) => window.uhXRDevice.controllers[h].updateButtonValue(b, 0), [hand, button]);
      await sleep(holdMs);
    },
    // points the right controller from under the head at yaw `angle` and `pitch` (radians, up positive)
    aim: (angle, pitch) => page.evaluate(([a, p]) => {
      const psi = a - Math.PI / 2 - window.uhMuseum.xr.rigYaw;
      const head = window.uhXRDevice.position;
      const c = window.uhXRDevice.controllers.right;
      c.position.set(head.x, head.y - 0.4, head.z);
      const [sy, cy, sx, cx] = [Math.sin(psi / 2), Math.cos(psi / 2), Math.sin(p / 2), Math.cos(p / 2)];
      c.quaternion.set(cy * sx, sy * cx, -sy * sx, cy * cx);
    }, [angle, pitch]),
  };
  const state = () => page.evaluate(() => ({
    head: window.uhMuseum.xr.head, body: [...window.uhMuseum.predicted], server: [...window.uhMuseum.snapshot.vive.pos],
    tick: window.uhMuseum.snapshot.tick, phase: window.uhMuseum.snapshot.phase, events: window.uhMuseum.events.map((e) => e.event),
  }));
  const waitFor = (what, fn, arg, timeout) => page.waitForFunction(fn, arg, { timeout }).catch(async () => {
    throw new Error(`timed out waiting for ${what}: ${JSON.stringify(await state())}`);
  });
  // walks with the left stick along `path` (level frame), the head turned to each waypoint in turn,
  // the stick pressed in to run: steered in the page at every frame (a step from the test's side
  // of the browser could overshoot a waypoint on a busy machine); then waits for the server's Vive
  // to stand where the head stopped
  await page.evaluate(() => {
    window.uhSteer = null;  // {path, run}
    const steer = () => {
      const plan = window.uhSteer, xr = window.uhMuseum.xr, device = window.uhXRDevice;
      if (plan && xr.head) {
        const stick = device.controllers.left;
        const gap = (p) => Math.hypot(p[0] - xr.head[0], p[1] - xr.head[1]);
        while (plan.path.length > 1 && gap(plan.path[0]) < 0.4) plan.path.shift();
        const to = plan.path[0];
        if (plan.path.length === 1 && gap(to) < 0.1) {
          stick.updateAxes('thumbstick', 0, 0);
          stick.updateButtonValue('thumbstick', 0);
          window.uhSteer = null;
        } else {
          const psi = Math.atan2(to[1] - xr.head[1], to[0] - xr.head[0]) - Math.PI / 2 - xr.rigYaw;
          device.quaternion.set(0, Math.sin(psi / 2), 0, Math.cos(psi / 2));
          const share = plan.path.length === 1 ? Math.max(0.25, Math.min(1, gap(to) / 0.5)) : 1;  // slow down for the last
          stick.updateAxes('thumbstick', 0, -share);
          stick.updateButtonValue('thumbstick', plan.run ? 1 : 0);
        }
      }
      requestAnimationFrame(steer);
    };
    steer();
  });
  const stickAlong = async (path, run = false) => {
    await page.evaluate(([p, r]) => { window.uhSteer = { path: p, run: r }; }, [path, run]);
    await waitFor(`the walk to (${path[path.length - 1]})`, () => window.uhSteer === null, null, 30000);
    await waitFor("the server's Vive where the head stopped", () => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - window.uhMuseum.xr.head[0], window.uhMuseum.snapshot.vive.pos[1] - window.uhMuseum.xr.head[1]) < 0.05, null, 8000);
  };

  // both eyes render the museum: the dock, the door to the great hall, the left hand's panel in view
  await page.evaluate(() => {
    const head = window.uhXRDevice.position;
    window.uhXRDevice.controllers.left.position.set(head.x - 0.08, head.y - 0.3, head.z - 0.35);
    window.uhXRDevice.controllers.left.quaternion.set(0, 0, 0, 1);
  });
  await page.waitForTimeout(800);
  const eye = async (from, to) => (await page.evaluate(pixelStats, { selector: 'canvas[data-engine]', from, to }))[0];
  const eyes = [await eye(0, 0.5), await eye(0.5, 1)];
  check(eyes.every((e) => e.variety > 0.2 && e.deviation > 10),
        `each eye's picture is not blank (${eyes.map((e) => `${(100 * e.variety).toFixed(0)} % away from the commonest colour, brightness spread ${e.deviation.toFixed(0)}`).join('; ')})`);
  const box = await page.locator('canvas[data-engine]').boundingBox();
  await page.screenshot({ path: path.join(outDir, 'museum_vr_left_eye.png'), clip: { x: box.x, y: box.y, width: box.width / 2, height: box.height } });
  await page.screenshot({ path: path.join(outDir, 'museum_vr_right_eye.png'), clip: { x: box.x + box.width / 2, y: box.y, width: box.width / 2, height: box.height } });

  await waitFor('the round to play (the blind bot studies the targets first)', () => window.uhMuseum.snapshot.phase === 'playing', null, kPhantomPatience);
  const panel = await page.evaluate(() => ({ text: window.uhMuseum.xr.panelText, targets: window.uhMuseum.welcome.targets }));
  check(/\d:\d\d/.test(panel.text) && panel.targets.every((kind) => panel.text.includes(kind)),
        `the wrist panel shows the timer and Falcon's targets ("${panel.text}")`);

  // the heist of the desktop test, in VR: the hall's guard starts east along a long side of its
  // round, Vive walks with the stick to the case at (12, 1.5) and waits until the guard is 6 m away
  await waitFor('the guard to start east', () => {
    const g = window.uhMuseum.snapshot.guards[0];
    return g.mode === 'patrol' && g.facing[0] > 0.99 && g.pos[0] > 9.2 && g.pos[0] < 10.5;
  }, null, 40000);
  const before = await state();
  const runsBefore = await page.evaluate(() => window.uhMuseum.runningSnapshots);
  const vignetteSeen = page.waitForFunction(() => window.uhMuseum.xr.vignette > 0.3, null, { timeout: 10000 }).then(() => true, () => false);
  await stickAlong([[6.5, 3], [7.6, 2.6], [12, 2.2]]);
  const atCase = await state();
  const runsAtCase = await page.evaluate(() => window.uhMuseum.runningSnapshots);
  const rules = await page.evaluate(() => window.uhMuseum.welcome.level.rules);
  check(dist(atCase.server, [12, 2.2]) < 0.15 && runsAtCase === runsBefore && !atCase.events.includes('guard_heard'),
        `the left stick walks the server's Vive to the case (${dist(before.server, atCase.server).toFixed(1)} m as the crow flies in ${((atCase.tick - before.tick) * rules.tick_s).toFixed(1)} s of game time; walking in every snapshot, unheard)`);
  check(await vignetteSeen, 'the comfort vignette narrows the view while the stick walks');

  await waitFor('the guard 6 m away', () => {
    const g = window.uhMuseum.snapshot.guards[0];
    return Math.hypot(g.pos[0] - 12, g.pos[1] - 1.5) >= 6;
  }, null, 25000);
  // the trigger, the grip at once (as E twice on the desktop: the page counts its break as done until
  // a snapshot says so) and off she runs, the stick pressed in, before the guard that hears the glass
  // comes near
  await page.evaluate(() => { window.uhXRPulses.length = 0; });
  await device.press('right', 'trigger', 80);
  await device.press('right', 'squeeze', 80);
  const runBack = stickAlong([[7.6, 2.6], [6.5, 3], [4.7, 3]], true);
  await waitFor('the glass to break', () => window.uhMuseum.events.some((e) => e.event === 'case_broken'), null, 5000);
  await waitFor('the piece taken', () => window.uhMuseum.events.some((e) => e.event === 'item_taken'), null, 5000);
  const heist = await page.evaluate(() => ({
    actions: window.uhMuseum.xr.actions, pulses: [...window.uhXRPulses],
    broken: window.uhMuseum.events.find((e) => e.event === 'case_broken'),
    heard: window.uhMuseum.events.filter((e) => e.event === 'guard_heard').length,
  }));
  check(heist.broken && heist.broken.case === 1 && JSON.stringify(heist.actions.slice(0, 2)) === '[["trigger","break"],["grip","take"]]',
        `the trigger breaks the case in reach and the grip takes its piece (the server's events: case ${heist.broken && heist.broken.case} broken, the piece taken; ${JSON.stringify(heist.actions)})`);
  // the glass: a short pulse on each hand; a guard hearing it: a long strong one on each
  const glassPulses = heist.pulses.filter((p) => p.duration === 120).map((p) => p.hand).sort();
  const heardPulses = heist.pulses.filter((p) => p.duration === 300).length;
  check(JSON.stringify(glassPulses) === '["left","right"]' && heardPulses === 2 * heist.heard,
        `the glass breaking pulses both controllers' haptic actuators, and so does each guard hearing it (${JSON.stringify(heist.pulses)})`);

  // heard running back, and pulsed when a guard hears her
  await runBack;
  const ran = await page.evaluate(() => ({ pulses: window.uhXRPulses.filter((p) => p.duration === 300).length / 2, heard: window.uhMuseum.events.filter((e) => e.event === 'guard_heard').length }));
  await device.press('right', 'squeeze');
  await waitFor('the delivery', () => window.uhMuseum.events.some((e) => e.event === 'items_delivered'), null, 5000);
  const home = await state();
  const caught = await page.evaluate(() => window.uhMuseum.snapshot.vive.times_caught);
  const runsHome = await page.evaluate(() => window.uhMuseum.runningSnapshots);
  check(home.events.includes('items_delivered') && caught === 0 && runsHome > runsAtCase + 20,
        `she runs back with the stick pressed in (${runsHome - runsAtCase} snapshots running), uncaught, and the grip delivers (${home.events.join(', ')})`);
  check(ran.heard > 0 && ran.pulses === ran.heard, `a guard hearing her pulses the controllers (${ran.heard} heard, ${ran.pulses} pulses on each hand)`);

  // teleports: through the dock's south wall refused, across the dock's floor taken (the body walks there, unheard)
  const teleport = async (to) => {
    const { head } = await state();
    const angle = Math.atan2(to[1] - head[1], to[0] - head[0]);
    const range = dist(head, to);
    const origin = await page.evaluate(() => window.uhXRDevice.position.y + window.uhMuseum.xr.heightOffset - 0.4);
    // the pitch whose arc (the page's launch speed and gravity) lands `range` away
    let lo = -1.2, hi = 0.7;
    for (let i = 0; i < 40; i++) {
      const p = (lo + hi) / 2;
      const vx = 7 * Math.cos(p), vy = 7 * Math.sin(p);
      const t = (vy + Math.sqrt(vy * vy + 2 * 9.81 * origin)) / 9.81;
      if (vx * t < range) lo = p; else hi = p;
    }
    await device.aim(angle, (lo + hi) / 2);
    await device.stick('right', 0, -1);
    await waitFor('the arc', () => window.uhMuseum.xr.aiming, null, 3000);
    await page.waitForTimeout(200);
    const aimed = await page.evaluate(() => window.uhMuseum.xr.aiming);
    await device.stick('right', 0, 0);
    await page.waitForTimeout(300);
    return aimed;
  };
  const refusedBefore = await page.evaluate(() => window.uhMuseum.xr.refused);
  const wallAim = await teleport([4.7, -1.5]);
  const afterWall = await state();
  const refused = await page.evaluate(() => window.uhMuseum.xr.refused);
  check(!wallAim.ok && refused === refusedBefore + 1 && dist(afterWall.head, home.head) < 0.1,
        `a teleport aimed through the dock's south wall is refused (${wallAim.why}; the head stays at ${afterWall.head.map((v) => v.toFixed(2))})`);
  const teleportsBefore = await page.evaluate(() => window.uhMuseum.xr.teleports);
  const floorAim = await teleport([2, 4]);
  const landed = await page.evaluate(() => ({ teleports: window.uhMuseum.xr.teleports, last: window.uhMuseum.xr.lastTeleport, head: window.uhMuseum.xr.head }));
  const onFloor = (p) => p[0] >= 0 && p[0] <= 6 && p[1] >= 0 && p[1] <= 6;
  check(floorAim.ok && landed.teleports === teleportsBefore + 1 && dist(landed.head, [2, 4]) < 0.3 && onFloor(landed.head),
        `a teleport aimed across the dock lands on its floor (at ${landed.head.map((v) => v.toFixed(2))}, aimed at 2,4)`);
  await waitFor("the server's Vive at the teleport's landing", (p) => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - p[0], window.uhMuseum.snapshot.vive.pos[1] - p[1]) < 0.15, landed.head, 8000);
  const afterTeleport = await state();
  check(afterTeleport.events.filter((e) => e === 'guard_heard').length === ran.heard, 'the body walks to the landing silently (no guard hears it)');

  // snap turning: 30 degrees a push
  const facingBefore = await page.evaluate(() => window.uhMuseum.xr.facing);
  await device.stick('right', 1, 0);
  await page.waitForTimeout(200);
  await device.stick('right', 0, 0);
  await page.waitForTimeout(200);
  const turned = await page.evaluate(() => ({ facing: window.uhMuseum.xr.facing, turns: window.uhMuseum.xr.turns }));
  const turnDeg = ((((turned.facing - facingBefore) * 180) / Math.PI + 540) % 360) - 180;
  check(turned.turns === 1 && Math.abs(turnDeg + 30) < 1, `the right stick turns by a snap of 30 degrees to the right (${turnDeg.toFixed(1)})`);

  // the player's own steps: slowly, Vive walks; quickly, she runs (heard)
  const stepStart = await state();
  for (let i = 0; i < 12; i++) { await device.move(0.05, 0); await sleep(100); }
  await waitFor("the server's Vive to follow the head", () => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - window.uhMuseum.xr.head[0], window.uhMuseum.snapshot.vive.pos[1] - window.uhMuseum.xr.head[1]) < 0.05, null, 5000);
  const stepped = await state();
  const slowRun = await page.evaluate(() => window.uhMuseum.snapshot.vive.running);
  check(Math.abs(dist(stepped.server, stepStart.server) - 0.6) < 0.08 && !slowRun,
        `a step of the player's own moves the server's Vive with the head (${dist(stepped.server, stepStart.server).toFixed(2)} m for 0.6 m, walking)`);
  const runSeen = page.waitForFunction(() => window.uhMuseum.snapshot.vive.running, null, { timeout: 3000, polling: 10 }).then(() => true, () => false);
  for (let i = 0; i < 4; i++) { await device.move(-0.2, 0); await sleep(50); }
  check(await runSeen, 'a quick lunge (faster than walking) runs on the server');
  await waitFor("the server's Vive to follow the lunge", () => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - window.uhMuseum.xr.head[0], window.uhMuseum.snapshot.vive.pos[1] - window.uhMuseum.xr.head[1]) < 0.05, null, 5000);

  // the stick (walking speed alone: walking, as on the way to the case) and the player's own steps
  // forward together are faster than walking: she runs
  await device.face(0);
  await waitFor('her to stand', () => !window.uhMuseum.snapshot.vive.running, null, 3000);
  const bothRun = page.waitForFunction(() => window.uhMuseum.snapshot.vive.running, null, { timeout: 4000, polling: 10 }).then(() => true, () => false);
  await device.stick('left', 0, -1);
  for (let i = 0; i < 16; i++) {
    await page.evaluate(() => {
      const d = window.uhXRDevice;
      const psi = 2 * Math.atan2(d.quaternion.y, d.quaternion.w);  // the head's turn, as face() set it
      d.position.set(d.position.x - 0.05 * Math.sin(psi), d.position.y, d.position.z - 0.05 * Math.cos(psi));
    });
    await sleep(50);
  }
  await device.stick('left', 0, 0);
  check(await bothRun, "walking with the stick while stepping forward (faster than walking together) runs on the server");
  await waitFor("the server's Vive to follow", () => Math.hypot(window.uhMuseum.snapshot.vive.pos[0] - window.uhMuseum.xr.head[0], window.uhMuseum.snapshot.vive.pos[1] - window.uhMuseum.xr.head[1]) < 0.05, null, 5000);

  // seated: X switches, and Y puts the eyes of a player sitting down (0.5 m lower) at standing height
  const eyeHeight = () => page.evaluate(() => window.uhXRDevice.position.y + window.uhMuseum.xr.heightOffset);
  const standingEyes = await eyeHeight();
  await device.press('left', 'x-button', 300);
  await device.move(0, 0, -0.5);
  await device.press('left', 'y-button', 300);
  const seated = await page.evaluate(() => window.uhMuseum.xr.mode);
  const seatedEyes = await eyeHeight();
  await device.press('left', 'x-button', 300);
  await device.move(0, 0, 0.5);
  const standingAgain = { mode: await page.evaluate(() => window.uhMuseum.xr.mode), eyes: await eyeHeight() };
  check(seated === 'seated' && Math.abs(seatedEyes - 1.6) < 0.01 && standingAgain.mode === 'standing' && Math.abs(standingAgain.eyes - standingEyes) < 0.01,
        `X switches to seated and Y calibrates the height: eyes at ${seatedEyes.toFixed(2)} m sitting, ${standingAgain.eyes.toFixed(2)} m standing again (${standingEyes.toFixed(2)} m before)`);

  // the round ends: the blind bot's verdict on the delivered piece, the summary
  await waitFor("Phantom's verdict", () => window.uhMuseum.events.some((e) => e.event === 'verdict'), null, kPhantomPatience);
  await waitFor('the summary', () => window.uhMuseum.summary, null, kRoundMinutes * 60 * 1000 + 15000);
  // the panel is redrawn at most 5 times a second
  await page.waitForFunction(() => /round over/.test(window.uhMuseum.xr.panelText), null, { timeout: 3000 }).catch(() => {});
  const end = await page.evaluate(() => ({
    summary: window.uhMuseum.summary, verdict: window.uhMuseum.events.find((e) => e.event === 'verdict'),
    taken: window.uhMuseum.events.find((e) => e.event === 'item_taken'), panel: window.uhMuseum.xr.panelText,
  }));
  const botEnded = await phantom.exited;
  check(end.verdict.item === end.taken.item && botEnded.code === 0 && /round over/.test(end.panel),
        `the round ends: the blind bot judged the delivered piece (${end.verdict.verdict}), left with exit ${botEnded.code}, the wrist panel says "${end.panel.split(' | ')[1]}"`);

  // the shipped page, in a browser without a WebXR runtime, shows no VR button
  const plain = await browser.newPage();
  await plain.goto(url);
  await plain.waitForFunction(() => window.uhMuseum && document.readyState === 'complete', null, { timeout: 15000 });
  await plain.waitForTimeout(1000);
  const plainButton = await plain.evaluate(() => getComputedStyle(document.getElementById('vr-panel')).display !== 'none');
  check(!plainButton, 'the shipped page in a browser without immersive-vr shows no VR button');
});
