// The live view of a soft object in Debian's Chromium (headless, driven by playwright-core; never a
// downloaded browser): `uh serve` on a free loopback port with the source tree as its root, and a
// controlling client (a WebSocket opened inside the page) opening scenes/soft_block.json and
// starting it, its ball pressing the block. Checks, on the page's own three.js mesh of the block
// (`uhView.softVertices`), that the view draws the deformed surfaces the states bring: the block's
// top under the ball goes down from the rest positions the page got first, its held base stays;
// that the canvas, with the tool hidden, is the same in two rest frames and differs in a pressed
// one; and that the console shows no errors. Writes a screenshot of the block at its deepest.
//
//   node soft_view_test.mjs UH_BINARY SOURCE_DIR SCREENSHOT.png
import { check, runBrowserTest, startServer } from './browser_harness.mjs';

const [uhBinary, sourceDir, screenshotPath] = process.argv.slice(2);
if (!uhBinary || !sourceDir || !screenshotPath) {
  console.error('usage: node soft_view_test.mjs UH_BINARY SOURCE_DIR SCREENSHOT.png');
  process.exit(2);
}
const kScene = 'scenes/soft_block.json';  // a 7 x 7 x 2 cm block, its top at z = 0, its base held
const kBlock = 'block';
const kBallRadiusM = 0.01;  // its ball (assets/meshes/ball.obj, radius 1 at 1 cm a unit)
// the ball presses the block's top several mm down (about 6 mm at its deepest): a view that moves the
// mesh with the states shows far more than this, one that ignores them nothing
const kMinDentM = 1e-3;
// two rest frames are the same to the pixel (checked): the pressed block's shading changes 0.2-0.4 %
const kMinChangedPixels = 0.001;
// `deformed` vertices are integers of 1e-5 m: a held vertex is drawn within half of one of them
// in each coordinate
const kHeldToleranceM = 1e-5;
const kPressSeconds = 8;  // how long to watch for the press (the ball is deepest 2 s after the start)

const server = await startServer(uhBinary, ['serve', '--port', '0', '--no-realtime', '--root', sourceDir],
                                 /live view: (http:\/\/127\.0\.0\.1:\d+\/)/);

// The top vertices (at rest on the block's highest z) within the ball's radius of the tool's axis,
// and the base ones (at rest on its lowest z), from a rest copy of the drawn vertices.
function restRegions(rest, tool) {
  let top = -Infinity, bottom = Infinity;
  for (let i = 2; i < rest.length; i += 3) {
    top = Math.max(top, rest[i]);
    bottom = Math.min(bottom, rest[i]);
  }
  const underBall = [], base = [];
  for (let i = 0; i < rest.length; i += 3) {
    const onAxis = Math.hypot(rest[i] - tool[0], rest[i + 1] - tool[1]) < kBallRadiusM;
    if (Math.abs(rest[i + 2] - top) < 1e-7 && onAxis) underBall.push(i);
    if (Math.abs(rest[i + 2] - bottom) < 1e-7) base.push(i);
  }
  return { underBall, base };
}

// How far down the top under the ball is drawn, and how far the held base moved [m].
function measure(rest, drawn, { underBall, base }) {
  let dent = 0, baseMoved = 0;
  for (const i of underBall) dent = Math.max(dent, rest[i + 2] - drawn[i + 2]);
  for (const i of base) {
    baseMoved = Math.max(baseMoved, Math.hypot(drawn[i] - rest[i], drawn[i + 1] - rest[i + 1], drawn[i + 2] - rest[i + 2]));
  }
  return { dent, baseMoved };
}

await runBrowserTest('soft view test', server, { width: 960, height: 600 }, async ({ page }) => {
  await page.goto(server.url);
  await page.waitForFunction(() => window.uhView && window.uhView.connected, null, { timeout: 15000 });

  // the controlling client, and in the page a grab of the canvas drawn with the tool hidden (two
  // animation frames after hiding it: the view's own frame has rendered by then)
  await page.evaluate(() => new Promise((resolve) => {
    const ws = new WebSocket(`ws://${location.host}/ws`);
    const waiting = new Map();
    let nextId = 1;
    ws.onmessage = (event) => {
      const m = JSON.parse(event.data);
      if (m.id !== undefined && waiting.has(m.id)) {
        waiting.get(m.id)(m);
        waiting.delete(m.id);
      }
    };
    window.testAsk = (message) => new Promise((reply) => {
      const id = nextId++;
      waiting.set(id, reply);
      ws.send(JSON.stringify({ ...message, id }));
    });
    window.testController = ws;
    const nextFrame = () => new Promise((done) => requestAnimationFrame(done));
    window.testFrames = {};
    window.testGrabFrame = async (name) => {
      window.uhView.showTool(false);
      await nextFrame();
      await nextFrame();
      const canvas = document.querySelector('#view canvas');
      const copy = document.createElement('canvas');
      copy.width = canvas.width;
      copy.height = canvas.height;
      const context = copy.getContext('2d');
      context.drawImage(canvas, 0, 0);
      window.testFrames[name] = context.getImageData(0, 0, copy.width, copy.height).data;
      window.uhView.showTool(true);
    };
    // the share of the pixels that differ clearly (summed over red, green, blue) between two frames
    window.testFrameDifference = (a, b) => {
      const [x, y] = [window.testFrames[a], window.testFrames[b]];
      let different = 0;
      for (let i = 0; i < x.length; i += 4) {
        if (Math.abs(x[i] - y[i]) + Math.abs(x[i + 1] - y[i + 1]) + Math.abs(x[i + 2] - y[i + 2]) > 24) different++;
      }
      return different / (x.length / 4);
    };
    ws.onopen = resolve;
  }));
  const ask = (message) => page.evaluate((m) => window.testAsk(m), message);

  const welcome = await ask({ type: 'hello', protocol: 1 });
  check(welcome.type === 'welcome', `the controller is welcomed (${welcome.type})`);
  const opened = await ask({ type: 'open', scene: kScene });
  check(opened.type === 'opened', `it opens ${kScene} (${opened.type}${opened.message ? ': ' + opened.message : ''})`);

  await page.waitForFunction((name) => window.uhView.meshes >= 2 && window.uhView.softVertices(name) !== null,
                             kBlock, { timeout: 30000 });
  const rest = await page.evaluate((name) => window.uhView.softVertices(name), kBlock);
  check(rest.length > 3 * 1000, `the view draws the block's refined surface (${rest.length / 3} vertices)`);
  await page.evaluate(() => window.testGrabFrame('rest'));
  await page.evaluate(() => window.testGrabFrame('rest again'));
  const still = await page.evaluate(() => window.testFrameDifference('rest', 'rest again'));
  check(still === 0, `two rest frames, the tool hidden, are the same (${(100 * still).toFixed(3)} % of pixels differ)`);

  // the first build packs the block and meshes its volume: seconds on a fresh cache
  const started = await ask({ type: 'start', seconds: 60 });
  check(started.type === 'started', `it starts the session (${started.type}${started.message ? ': ' + started.message : ''})`);

  await page.waitForFunction(() => window.uhView.deformed >= 3, null, { timeout: 15000 })
    .catch(() => {});
  const deformedStates = await page.evaluate(() => window.uhView.deformed);
  check(deformedStates >= 3, `the view redraws the block from the states' deformed surfaces (${deformedStates} so far)`);

  // the ball moves along z above the block's centre: the top under it is found from the tool's axis
  const tool = await page.evaluate(() => window.uhView.toolPosition);
  const regions = restRegions(rest, tool);
  check(regions.underBall.length >= 10 && regions.base.length >= 10,
        `the block's top under the ball and its base are found at rest (${regions.underBall.length}, ${regions.base.length} vertices)`);

  // watch the press; the pressed frame and the screenshot (the ball on the block) are taken at the
  // deepest dent seen
  let deepest = { dent: 0, baseMoved: 0 }, baseMoved = 0, samples = 0;
  for (const until = Date.now() + kPressSeconds * 1000; Date.now() < until; samples++) {
    const drawn = await page.evaluate((name) => window.uhView.softVertices(name), kBlock);
    const now = measure(rest, drawn, regions);
    baseMoved = Math.max(baseMoved, now.baseMoved);
    if (now.dent > deepest.dent) {
      deepest = now;
      await page.evaluate(() => window.testGrabFrame('pressed'));
      await page.screenshot({ path: screenshotPath });
    }
    await page.waitForTimeout(100);
  }
  if (deepest.dent === 0) await page.screenshot({ path: screenshotPath });  // what the page showed instead
  check(deepest.dent > kMinDentM, `the block's top is drawn ${(1e3 * deepest.dent).toFixed(2)} mm down under the ball ` +
                                  `(at most, over ${samples} looks in ${kPressSeconds} s; more than ${1e3 * kMinDentM} mm)`);
  check(baseMoved < kHeldToleranceM, `its held base stays where it was drawn at rest (${(1e6 * baseMoved).toFixed(1)} um at most)`);
  const changed = deepest.dent > 0 ? await page.evaluate(() => window.testFrameDifference('rest', 'pressed')) : 0;
  check(changed > kMinChangedPixels,
        `the canvas, the tool hidden, differs between the rest and the pressed frame (${(100 * changed).toFixed(2)} % of pixels)`);
  await page.evaluate(() => window.testController.close());
});
