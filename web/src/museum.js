// Vive's client of the museum heist (docs/museum.md): joins `uh museum serve` as Vive over its
// WebSocket messages and shows the museum in first person: the rooms, cases and Phantom's table
// from the welcome's level, the guards with their view cones, rings showing how far noise carries,
// Falcon's targets with pictures, what Vive carries, the timer and, at the end, the summary.
//
// The server is authoritative. Vive's own position is predicted here with the rules' movement
// (walk or run, sliding along walls) so the view answers the keys at once, and pulled towards
// what the server says (reconciliation); everything else is drawn a little in the past,
// interpolated between the two snapshots around that moment. Bundled with three.js at build
// time; it fetches nothing but the server's own files. Where the browser offers WebXR's
// `immersive-vr`, an "Enter VR" button puts Vive in virtual reality (museum_xr.js).
import * as THREE from 'three';
import { createXR } from './museum_xr.js';

// Okabe-Ito: told apart with the common colour-vision deficiencies
const Colour = {
  orange: 0xe69f00, sky: 0x56b4e9, green: 0x009e73, yellow: 0xf0e442,
  blue: 0x0072b2, vermillion: 0xd55e00, purple: 0xcc79a7,
};
const kGuardModeColour = { patrol: Colour.sky, investigate: Colour.vermillion, returning: Colour.yellow };
const kEyeHeight = 1.6;            // [m]
const kWallHeight = 3.0;           // [m]
const kWallCell = 0.25;            // wall blocks sample the floor plan at this step [m] (rooms lie on 0.5 m)
const kInterpolationDelayS = 0.1;  // others are drawn this far in the past: two snapshots at 20 Hz
const kPauseS = 0.3;               // snapshots this much later than the game clock says follow a pause
const kSnapDistance = 1.5;         // a server position this far from the prediction is a jump (caught) [m]
const kCorrectionPerSnapshot = 0.25;  // share of the prediction's error removed at each snapshot
const kMouseRadiansPerPixel = 0.0025;
const kTurnRadiansPerS = 2.2;      // turning with keys
const kAutopilotBrakeS = 0.3;      // a scripted walk slows down this long before its end
const kPieceDisplayM = 0.35;       // pieces in the cases are shown enlarged to this size [m]

// ---- keys: remappable, kept in localStorage ---------------------------------------------------
const kActions = [
  ['forward', 'walk forward', ['KeyW', 'ArrowUp']],
  ['back', 'walk back', ['KeyS', 'ArrowDown']],
  ['left', 'step left', ['KeyA']],
  ['right', 'step right', ['KeyD']],
  ['turn_left', 'turn left', ['ArrowLeft', 'KeyQ']],
  ['turn_right', 'turn right', ['ArrowRight']],
  ['run', 'run (hold; guards hear it)', ['ShiftLeft', 'ShiftRight']],
  ['use', 'break a case / take / deliver', ['KeyE', 'Space']],
  ['settings', 'this panel', ['KeyO']],
];
const kKeysStorage = 'uh-museum-keys';
function defaultKeys() {
  return Object.fromEntries(kActions.map(([name, , codes]) => [name, [...codes]]));
}
function loadKeys() {
  const keys = defaultKeys();
  try {
    const stored = JSON.parse(localStorage.getItem(kKeysStorage) || '{}');
    for (const [name, codes] of Object.entries(stored)) {
      if (name in keys && Array.isArray(codes) && codes.every((c) => typeof c === 'string')) keys[name] = codes;
    }
  } catch (error) {
    // an unreadable stored map falls back to the defaults
  }
  return keys;
}
let keys = loadKeys();
const held = new Set();  // key codes down now
const isHeld = (action) => keys[action].some((code) => held.has(code));

// ---- what the page shows, readable from outside (the browser test reads it) --------------------
const museum = {
  connected: false,
  welcome: null,
  snapshot: null,        // the newest snapshot
  snapshots: 0,          // snapshots received
  runningSnapshots: 0,   // snapshots with Vive running
  summary: null,
  events: [],            // events received, oldest first
  errors: [],            // error messages from the server
  predicted: null,       // Vive's predicted position [x, y] (level frame)
  corrections: 0,        // snapshots that moved the prediction
  jumps: 0,              // snapshots that replaced it (caught: back to the entrance)
  guardsDrawn: [],       // where each guard was drawn last frame [x, y]
  frames: 0,
  pictures: {},          // kind -> data URL of Falcon's picture
  trace: null,           // when an array (tests): {drawn: guards} per frame, {snapshot: guards} per snapshot
  // a scripted walk (tests, demos): {path: [[x, y], ...], run}; Vive walks it, facing where she goes,
  // through the same prediction and moves as the keys; null when done
  autopilot: null,
  ringsDrawn: 0,         // noise rings drawn (not counting the one around Vive while she runs)
  running: false,        // whether Vive runs now (the red ring around her shows)
  captions: [],          // the last captions shown, oldest first
  xr: {},                // the VR mode's state (museum_xr.js)
};
window.uhMuseum = museum;

const $ = (id) => document.getElementById(id);
const floorToWorld = (x, y, height = 0) => new THREE.Vector3(x, height, -y);  // level x east, y north

// ---- renderer, scene, camera -------------------------------------------------------------------
const container = $('view');
// multisampling costs a software renderer (the headless tests') more than it shows
const renderer = new THREE.WebGLRenderer({ antialias: !navigator.webdriver, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(0x1b1f27);
container.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.fog = new THREE.Fog(0x1b1f27, 12, 40);
const camera = new THREE.PerspectiveCamera(70, window.innerWidth / window.innerHeight, 0.05, 80);
camera.rotation.order = 'YXZ';
// the camera rides on a rig: still on the desktop; in VR the rig is where the player's floor is in
// the museum and the headset moves the camera on it
const rig = new THREE.Group();
rig.add(camera);
scene.add(rig);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404650, 1.4));
const sun = new THREE.DirectionalLight(0xffffff, 1.2);
sun.position.set(5, 20, 8);
scene.add(sun);

const levelGroup = new THREE.Group();
scene.add(levelGroup);
const guardsGroup = new THREE.Group();
scene.add(guardsGroup);
const ringsGroup = new THREE.Group();
scene.add(ringsGroup);

let yaw = 0;    // where Vive looks: radians from east, counter-clockwise
let pitch = -0.15;

// ---- the level -------------------------------------------------------------------------------
let level = null;
let rules = null;
const cases = [];      // {glass, shards, slot (a group holding the piece)}
let tableSlot = null;  // the pieces on Phantom's table
const guardObjects = [];
const pieceLooks = {};  // kind -> BufferGeometry (y up, metres), until its picture is rendered

function walkable(x, y) {
  return level.rooms.some((r) => x >= r.min[0] && x <= r.max[0] && y >= r.min[1] && y <= r.max[1]);
}

function buildLevel() {
  levelGroup.clear();
  cases.length = 0;
  // floors tiled in half-metre squares: walking shows against them
  const tiles = document.createElement('canvas');
  tiles.width = tiles.height = 64;
  const paint = tiles.getContext('2d');
  paint.fillStyle = '#ffffff';
  paint.fillRect(0, 0, 64, 64);
  paint.fillStyle = '#d0d0d0';
  paint.fillRect(0, 0, 32, 32);
  paint.fillRect(32, 32, 32, 32);
  const tileTexture = new THREE.CanvasTexture(tiles);
  tileTexture.wrapS = tileTexture.wrapT = THREE.RepeatWrapping;
  const floorMaterial = (colour, w, h) => {
    const map = tileTexture.clone();
    map.repeat.set(w, h);  // one 64 px tile (2 x 2 squares) per metre
    return new THREE.MeshLambertMaterial({ color: colour, map });
  };
  for (const room of level.rooms) {
    const w = room.max[0] - room.min[0];
    const h = room.max[1] - room.min[1];
    const floor = new THREE.Mesh(new THREE.PlaneGeometry(w, h), floorMaterial(/dock|door/.test(room.name) ? 0x7d838f : 0x9aa0aa, w, h));
    floor.rotation.x = -Math.PI / 2;
    floor.position.copy(floorToWorld((room.min[0] + room.max[0]) / 2, (room.min[1] + room.max[1]) / 2));
    levelGroup.add(floor);
  }
  // walls: the cells off the floor, merged into runs along x and runs of equal rows along y (a
  // few dozen boxes: a software renderer pays for every layer a pixel is drawn in)
  let minX = Infinity, minY = Infinity, maxX = -Infinity, maxY = -Infinity;
  for (const r of level.rooms) {
    minX = Math.min(minX, r.min[0]); minY = Math.min(minY, r.min[1]);
    maxX = Math.max(maxX, r.max[0]); maxY = Math.max(maxY, r.max[1]);
  }
  minX -= 1; minY -= 1; maxX += 1; maxY += 1;
  const nx = Math.round((maxX - minX) / kWallCell);
  const ny = Math.round((maxY - minY) / kWallCell);
  const wallMaterial = new THREE.MeshLambertMaterial({ color: 0x3d4556 });
  const boxes = [];      // [x0, x1, y0, y1]
  let open = new Map();  // runs of the previous row, by "x0 x1", still growing along y
  for (let j = 0; j <= ny; j++) {
    const y = minY + (j + 0.5) * kWallCell;
    const runs = new Map();
    let runStart = -1;
    for (let i = 0; j < ny && i <= nx; i++) {
      const wall = i < nx && !walkable(minX + (i + 0.5) * kWallCell, y);
      if (wall && runStart < 0) runStart = i;
      if (!wall && runStart >= 0) {
        const x0 = minX + runStart * kWallCell, x1 = minX + i * kWallCell;
        const grown = open.get(`${x0} ${x1}`);
        runs.set(`${x0} ${x1}`, grown ? [x0, x1, grown[2], y + kWallCell / 2] : [x0, x1, y - kWallCell / 2, y + kWallCell / 2]);
        runStart = -1;
      }
    }
    for (const [key, box] of open) if (!runs.has(key)) boxes.push(box);
    open = runs;
  }
  const wallGeometry = new THREE.BoxGeometry(1, kWallHeight, 1);
  const walls = new THREE.InstancedMesh(wallGeometry, wallMaterial, boxes.length);
  const m = new THREE.Matrix4();
  boxes.forEach(([x0, x1, y0, y1], index) => {
    m.makeScale(x1 - x0, 1, y1 - y0).setPosition(floorToWorld((x0 + x1) / 2, (y0 + y1) / 2, kWallHeight / 2));
    walls.setMatrixAt(index, m);
  });
  levelGroup.add(walls);

  // the cases: a pedestal, a glass box (gone once broken, shards on the floor) and the piece
  const pedestalMaterial = new THREE.MeshLambertMaterial({ color: Colour.blue });
  const glassMaterial = new THREE.MeshLambertMaterial({ color: Colour.sky, transparent: true, opacity: 0.28 });
  const edgeMaterial = new THREE.LineBasicMaterial({ color: 0xdff3ff });
  const shardMaterial = new THREE.MeshLambertMaterial({ color: Colour.sky, transparent: true, opacity: 0.6, side: THREE.DoubleSide });
  level.cases.forEach(([x, y], index) => {
    const group = new THREE.Group();
    group.position.copy(floorToWorld(x, y));
    const pedestal = new THREE.Mesh(new THREE.BoxGeometry(0.6, 0.9, 0.6), pedestalMaterial);
    pedestal.position.y = 0.45;
    const glassGeometry = new THREE.BoxGeometry(0.6, 0.55, 0.6);
    const glass = new THREE.Mesh(glassGeometry, glassMaterial);
    glass.add(new THREE.LineSegments(new THREE.EdgesGeometry(glassGeometry), edgeMaterial));
    glass.position.y = 0.9 + 0.275;
    const shards = new THREE.Group();
    for (let k = 0; k < 7; k++) {
      const shard = new THREE.Mesh(new THREE.CircleGeometry(0.08, 3), shardMaterial);
      const angle = (k / 7) * Math.PI * 2 + index;
      shard.position.set(Math.cos(angle) * (0.5 + 0.1 * (k % 3)), 0.01, Math.sin(angle) * (0.5 + 0.1 * (k % 2)));
      shard.rotation.set(-Math.PI / 2, 0, angle * 3);
      shards.add(shard);
    }
    shards.visible = false;
    const slot = new THREE.Group();
    slot.position.y = 0.9;
    group.add(pedestal, glass, shards, slot);
    levelGroup.add(group);
    cases.push({ glass, shards, slot, shown: undefined });
  });

  // Phantom's table: a wooden top with the delivered pieces in a row
  const table = new THREE.Group();
  table.position.copy(floorToWorld(level.table[0], level.table[1]));
  const top = new THREE.Mesh(new THREE.BoxGeometry(1.4, 0.08, 0.8), new THREE.MeshLambertMaterial({ color: 0x8b5a2b }));
  top.position.y = 0.78;
  table.add(top);
  for (const [dx, dz] of [[-0.62, -0.32], [0.62, -0.32], [-0.62, 0.32], [0.62, 0.32]]) {
    const leg = new THREE.Mesh(new THREE.BoxGeometry(0.06, 0.74, 0.06), top.material);
    leg.position.set(dx, 0.37, dz);
    table.add(leg);
  }
  tableSlot = new THREE.Group();
  tableSlot.position.y = 0.82;
  table.add(tableSlot);
  levelGroup.add(table);
  // the entrance: a green mat
  const mat = new THREE.Mesh(new THREE.PlaneGeometry(1, 1), new THREE.MeshLambertMaterial({ color: Colour.green }));
  mat.rotation.x = -Math.PI / 2;
  mat.position.copy(floorToWorld(level.entrance[0], level.entrance[1], 0.005));
  levelGroup.add(mat);
}

// a guard: a body, a head, a nose showing where it faces, and its view cone on the floor
function makeGuard() {
  const group = new THREE.Group();
  const bodyMaterial = new THREE.MeshLambertMaterial({ color: Colour.orange });
  const body = new THREE.Mesh(new THREE.CylinderGeometry(0.25, 0.3, 1.5, 16), bodyMaterial);
  body.position.y = 0.75;
  const head = new THREE.Mesh(new THREE.SphereGeometry(0.18, 16, 12), bodyMaterial);
  head.position.y = 1.68;
  const cap = new THREE.Mesh(new THREE.BoxGeometry(0.3, 0.08, 0.12), new THREE.MeshLambertMaterial({ color: 0x222222 }));
  cap.position.set(0.16, 1.78, 0);  // the cap's peak points the way the guard faces (+x locally)
  const half = (rules.view_half_angle_deg * Math.PI) / 180;
  const coneMaterial = new THREE.MeshBasicMaterial({ color: Colour.sky, transparent: true, opacity: 0.3, depthWrite: false, side: THREE.DoubleSide });
  const cone = new THREE.Mesh(new THREE.CircleGeometry(rules.view_range, 24, -half, 2 * half), coneMaterial);
  cone.rotation.x = -Math.PI / 2;
  cone.position.y = 0.02;
  group.add(body, head, cap, cone);
  guardsGroup.add(group);
  return { group, cone, coneMaterial };
}

// ---- artifact looks and Falcon's pictures ----------------------------------------------------
async function fetchLook(kind) {
  const response = await fetch(`/artifacts/${encodeURIComponent(kind)}.json`);
  if (!response.ok) throw new Error(`no look for the ${kind} (${response.status})`);
  const data = await response.json();
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(data.vertices, 3));
  geometry.setIndex(data.triangles);
  geometry.rotateX(-Math.PI / 2);  // z up (the artifact's frame) to y up
  geometry.computeVertexNormals();
  geometry.computeBoundingBox();
  pieceLooks[kind] = geometry;
  return geometry;
}

// a piece in a case or on the table: its picture on a sprite (the meshes are fine enough to touch,
// tens of thousands of triangles each: too many to draw every frame on a software renderer)
const pieceTextures = {};  // kind -> CanvasTexture of its picture
function pieceSprite(kind, size = kPieceDisplayM) {
  const texture = pieceTextures[kind];
  if (!texture) return new THREE.Group();  // drawn once its look arrives
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture }));
  sprite.scale.setScalar(size);
  sprite.position.y = size / 2;
  return sprite;
}

// a picture of the piece, rendered offscreen by the page's own renderer
function renderPicture(kind) {
  const size = 192;
  const target = new THREE.WebGLRenderTarget(size, size);
  const stage = new THREE.Scene();  // transparent around the piece: the page or the case shows through
  stage.add(new THREE.HemisphereLight(0xffffff, 0x303540, 1.6));
  const light = new THREE.DirectionalLight(0xffffff, 1.6);
  light.position.set(1, 2, 2);
  stage.add(light);
  const mesh = new THREE.Mesh(pieceLooks[kind], new THREE.MeshLambertMaterial({ color: Colour.orange }));
  mesh.rotation.y = 0.5;
  stage.add(mesh);
  const bounds = new THREE.Box3().setFromObject(mesh);
  const centre = bounds.getCenter(new THREE.Vector3());
  const radius = bounds.getSize(new THREE.Vector3()).length() / 2;
  const lens = new THREE.PerspectiveCamera(30, 1, radius / 10, radius * 20);
  lens.position.copy(centre).add(new THREE.Vector3(0, 0.55, 1).normalize().multiplyScalar(radius / Math.sin((15 * Math.PI) / 180)));
  lens.lookAt(centre);
  const clearAlpha = renderer.getClearAlpha();
  renderer.setClearAlpha(0);
  renderer.setRenderTarget(target);
  renderer.render(stage, lens);
  renderer.setClearAlpha(clearAlpha);
  const pixels = new Uint8Array(size * size * 4);
  renderer.readRenderTargetPixels(target, 0, 0, size, size, pixels);
  renderer.setRenderTarget(null);
  target.dispose();
  const canvas = document.createElement('canvas');
  canvas.width = size;
  canvas.height = size;
  const context = canvas.getContext('2d');
  const image = context.createImageData(size, size);
  for (let row = 0; row < size; row++) {  // WebGL rows run bottom-up
    image.data.set(pixels.subarray((size - 1 - row) * size * 4, (size - row) * size * 4), row * size * 4);
  }
  context.putImageData(image, 0, 0);
  mesh.material.dispose();
  pieceTextures[kind] = new THREE.CanvasTexture(canvas);
  pieceTextures[kind].colorSpace = THREE.SRGBColorSpace;
  return canvas.toDataURL('image/png');
}

function pictureOf(kind) {
  return museum.pictures[kind] || 'data:,';
}

async function loadLooks(allKinds, targets) {
  const kinds = allKinds.filter((kind) => !museum.pictures[kind]);  // a reconnect fetches nothing again
  await Promise.all(kinds.map((kind) => fetchLook(kind).catch((error) => caption(error.message, 'bad'))));
  for (const kind of kinds) {
    if (pieceLooks[kind]) museum.pictures[kind] = renderPicture(kind);
    if (pieceLooks[kind]) pieceLooks[kind].dispose();
    delete pieceLooks[kind];  // the picture is all the page draws of it
  }
  showTargets(targets);
  for (const c of cases) c.shown = undefined;  // redraw the pieces with their looks
  lastCarried = '';
}

// ---- the HUD ---------------------------------------------------------------------------------
function setStatus(text, kind) {
  $('status').textContent = text;
  $('status').className = kind;
}

function caption(text, kind = '') {
  const line = document.createElement('div');
  line.textContent = text;
  if (kind === 'bad') line.style.color = 'var(--vermillion)';
  if (kind === 'warn') line.style.color = 'var(--yellow)';
  museum.captions.push(text);
  if (museum.captions.length > 5) museum.captions.shift();
  const box = $('captions');
  box.appendChild(line);
  while (box.children.length > 5) box.removeChild(box.firstChild);
}

function showTargets(targets) {
  const list = $('targets');
  list.textContent = '';
  for (const kind of targets) {
    const row = document.createElement('div');
    row.className = 'target';
    row.dataset.kind = kind;
    const img = document.createElement('img');
    img.alt = `picture of the ${kind}`;
    img.src = pictureOf(kind);
    const text = document.createElement('div');
    text.innerHTML = '<div class="kind"></div><div class="caption"></div>';
    text.firstChild.textContent = kind;
    text.lastChild.textContent = `"The ${kind}. Find both cases; Phantom will know which is real."`;
    row.append(img, text);
    list.appendChild(row);
  }
}

let lastCarried = '';
function showCarried(carried) {
  const key = JSON.stringify(carried);
  if (key === lastCarried) return;
  lastCarried = key;
  const box = $('carried');
  box.querySelectorAll('.slot').forEach((slot) => slot.remove());
  const max = rules ? rules.max_carried : 2;
  for (let i = 0; i < max; i++) {
    const item = carried[i];
    const slot = document.createElement('div');
    slot.className = item ? 'slot' : 'slot empty';
    const img = document.createElement(item ? 'img' : 'div');
    if (item) {
      img.alt = `the ${item.kind} you carry`;
      img.src = pictureOf(item.kind);
    } else {
      img.className = 'hand';
    }
    const label = document.createElement('div');
    label.className = 'kind';
    label.textContent = item ? item.kind : 'empty';
    slot.append(img, label);
    box.appendChild(slot);
  }
}

function formatTime(s) {
  const t = Math.max(0, Math.ceil(s));
  return `${Math.floor(t / 60)}:${String(t % 60).padStart(2, '0')}`;
}

const kPlaces = { in_case: 'still in its case', carried: 'carried', on_table: 'on the table', kept: 'kept', rejected: 'put aside' };
function showSummary(s) {
  const box = $('summary');
  const rows = s.targets.map((t) => `<tr><td class="kind">${t.kind}</td><td>genuine ${kPlaces[t.genuine] || t.genuine}</td><td>forgery ${kPlaces[t.forgery] || t.forgery}</td></tr>`).join('');
  box.innerHTML = `<h2>The round is over${s.ended_early ? ' early' : ''}</h2>
    <div id="summary-points" style="font-size:24px;font-weight:600">${s.score.points} points</div>
    <div>genuine kept ${s.score.genuine_kept}, forgeries kept ${s.score.forgeries_kept}, time bonus ${s.score.time_bonus}</div>
    <div>caught ${s.times_caught} times, ${Math.round(s.seconds_played)} s played</div>
    <table>${rows}</table>`;
  box.style.display = 'block';
  if (document.pointerLockElement) document.exitPointerLock();
}

// the floor plan from above, with Vive (a triangle), the guards (dots with their mode's letter)
const minimap = $('minimap-canvas').getContext('2d');
function drawMinimap(vivePos, guards) {
  if (!level) return;
  const w = minimap.canvas.width, h = minimap.canvas.height;
  let maxX = 0, maxY = 0;
  for (const r of level.rooms) { maxX = Math.max(maxX, r.max[0]); maxY = Math.max(maxY, r.max[1]); }
  const s = Math.min((w - 8) / maxX, (h - 8) / maxY);
  const px = (x) => 4 + x * s, py = (y) => h - 4 - y * s;
  minimap.clearRect(0, 0, w, h);
  minimap.fillStyle = '#5a606c';
  for (const r of level.rooms) minimap.fillRect(px(r.min[0]), py(r.max[1]), (r.max[0] - r.min[0]) * s, (r.max[1] - r.min[1]) * s);
  minimap.fillStyle = '#8b5a2b';
  minimap.fillRect(px(level.table[0]) - 3, py(level.table[1]) - 2, 6, 4);
  const snap = museum.snapshot;
  level.cases.forEach(([x, y], i) => {
    const c = snap && snap.cases[i];
    minimap.strokeStyle = '#56b4e9';
    minimap.fillStyle = c && c.item ? '#e69f00' : '#20242c';
    minimap.fillRect(px(x) - 2.5, py(y) - 2.5, 5, 5);
    if (!c || !c.broken) minimap.strokeRect(px(x) - 3.5, py(y) - 3.5, 7, 7);
  });
  for (const g of guards) {
    minimap.fillStyle = `#${kGuardModeColour[g.mode].toString(16).padStart(6, '0')}`;
    minimap.beginPath();
    minimap.arc(px(g.pos[0]), py(g.pos[1]), 3.5, 0, Math.PI * 2);
    minimap.fill();
  }
  if (vivePos) {
    minimap.save();
    minimap.translate(px(vivePos[0]), py(vivePos[1]));
    minimap.rotate(-yaw);
    minimap.fillStyle = '#009e73';
    minimap.strokeStyle = '#ffffff';
    minimap.beginPath();
    minimap.moveTo(6, 0); minimap.lineTo(-4, 4); minimap.lineTo(-4, -4); minimap.closePath();
    minimap.fill(); minimap.stroke();
    minimap.restore();
  }
}

// ---- settings: remapping keys ------------------------------------------------------------------
let listeningFor = null;  // the action waiting for its new key
function keyName(code) {
  return code.replace(/^Key/, '').replace(/^Digit/, '').replace(/^Arrow/, 'arrow ').replace(/(Left|Right)$/, ' $1').toLowerCase();
}
function showKeyTable() {
  const table = $('key-table');
  table.textContent = '';
  for (const [name, label] of kActions) {
    const row = table.insertRow();
    row.insertCell().textContent = label;
    row.insertCell().innerHTML = keys[name].map((c) => `<kbd>${keyName(c)}</kbd>`).join(' ');
    const button = document.createElement('button');
    button.textContent = listeningFor === name ? 'press a key' : 'change';
    button.className = listeningFor === name ? 'listening' : '';
    button.dataset.action = name;
    button.onclick = () => { listeningFor = name; showKeyTable(); };
    row.insertCell().appendChild(button);
  }
}
function toggleSettings(open = $('settings').style.display !== 'block') {
  $('settings').style.display = open ? 'block' : 'none';
  listeningFor = null;
  if (open) {
    showKeyTable();
    if (document.pointerLockElement) document.exitPointerLock();
  }
}
$('open-settings').onclick = () => toggleSettings();
$('close-settings').onclick = () => toggleSettings(false);
$('reset-keys').onclick = () => {
  keys = defaultKeys();
  localStorage.removeItem(kKeysStorage);
  showKeyTable();
};

window.addEventListener('keydown', (event) => {
  if (listeningFor) {
    event.preventDefault();
    if (event.code !== 'Escape') {
      for (const codes of Object.values(keys)) {  // a key does one thing
        const at = codes.indexOf(event.code);
        if (at >= 0) codes.splice(at, 1);
      }
      keys[listeningFor] = [event.code];
      localStorage.setItem(kKeysStorage, JSON.stringify(keys));
    }
    listeningFor = null;
    showKeyTable();
    return;
  }
  if (event.repeat) return;
  held.add(event.code);
  if (keys.settings.includes(event.code)) toggleSettings();
  else if (keys.use.includes(event.code)) useNearest();
  if (level && !museum.summary && !xr.presenting() && $('settings').style.display !== 'block') readInput(0);  // so does a start
  if (Object.values(keys).some((codes) => codes.includes(event.code))) event.preventDefault();
});
window.addEventListener('keyup', (event) => {
  held.delete(event.code);
  if (level && !museum.summary && !xr.presenting()) readInput(0);  // a stop goes out at once
});
window.addEventListener('blur', () => held.clear());

renderer.domElement.addEventListener('click', () => {
  if (!museum.summary && renderer.domElement.requestPointerLock) renderer.domElement.requestPointerLock();
});
document.addEventListener('pointerlockchange', () => {
  $('hint').style.display = document.pointerLockElement ? 'none' : 'block';
});
document.addEventListener('mousemove', (event) => {
  if (document.pointerLockElement !== renderer.domElement) return;
  yaw -= event.movementX * kMouseRadiansPerPixel;
  pitch = Math.max(-1.3, Math.min(1.3, pitch - event.movementY * kMouseRadiansPerPixel));
});

// ---- the connection ----------------------------------------------------------------------------
let socket = null;
function send(message) {
  if (socket && socket.readyState === WebSocket.OPEN) socket.send(JSON.stringify(message));
}

// what `use` does where Vive stands: deliver at the table, else break or take at the nearest case
// actions sent and not yet in a snapshot count as done, so a quick second press takes what the
// first one's glass uncovered (the server applies queued actions one a tick)
const sentActions = new Map();  // "break 3", "take 3" -> when sent [s]
const kActionPendingS = 0.5;
const pending = (action, i) => performance.now() / 1000 - (sentActions.get(`${action} ${i}`) ?? -Infinity) < kActionPendingS;

function usableAction() {
  const s = museum.snapshot;
  if (!s || !museum.predicted || s.phase !== 'playing') return null;
  const [x, y] = museum.predicted;
  const near = (p) => Math.hypot(p[0] - x, p[1] - y) <= rules.reach;
  if (s.vive.carried.length > 0 && near(level.table)) return { action: 'deliver', text: 'deliver to Phantom' };
  const broken = (i) => s.cases[i].broken || pending('break', i);
  const holds = (i) => s.cases[i].item && !pending('take', i);
  let best = -1, bestD = Infinity;
  level.cases.forEach((p, i) => {
    const d = Math.hypot(p[0] - x, p[1] - y);
    if (d <= rules.reach && d < bestD && (!broken(i) || holds(i))) { best = i; bestD = d; }
  });
  if (best < 0) return null;
  if (!broken(best)) return { action: 'break', case: best, text: `break the case (heard within ${rules.glass_hear_radius} m)` };
  if (s.vive.carried.length >= rules.max_carried) return { action: null, text: `hands full (${rules.max_carried} pieces)` };
  return { action: 'take', case: best, text: `take the ${s.cases[best].item.kind}` };
}
function useNearest(allowed = null) {
  const use = usableAction();
  if (use && use.action && (!allowed || allowed.includes(use.action))) {
    send({ type: 'action', action: use.action });
    if (use.case !== undefined) sentActions.set(`${use.action} ${use.case}`, performance.now() / 1000);
  }
  return use && use.action && (!allowed || allowed.includes(use.action)) ? use.action : null;
}
museum.use = useNearest;  // what the use key does, for scripts: the action sent, or null

const kEventText = {
  case_broken: (e) => [`Glass breaks: heard within ${e.radius} m`, 'warn'],
  case_empty: () => ['Falcon: "That case was empty."', ''],
  item_taken: () => ['You take the piece.', ''],
  items_delivered: (e) => [`You hand Phantom ${e.count} piece${e.count === 1 ? '' : 's'}.`, ''],
  guard_heard: (e) => [`A guard heard something ${Math.round(e.radius)} m away and comes to look.`, 'warn'],
  vive_caught: (e) => [`Caught! ${e.items_lost} piece${e.items_lost === 1 ? '' : 's'} back in the cases; time lost.`, 'bad'],
  verdict: (e) => [`Phantom: "item ${e.item} is ${e.verdict === 'genuine' ? 'genuine' : 'a forgery'}."`, ''],
  time_warning: (e) => [`Falcon: "${e.seconds_left} seconds left."`, 'warn'],
  round_ended: () => ['The round is over.', ''],
};

function onEvent(e) {
  museum.events.push(e);
  const text = kEventText[e.event];
  if (text) caption(...text(e));
  xr.onEvent(e);
  if (e.event === 'case_broken') addRing(e.pos, e.radius, Colour.purple, 2.0);
  if (e.event === 'guard_heard') addRing(e.pos, 0.6, Colour.vermillion, 1.5);
}

function onMessage(m) {
  switch (m.type) {
    case 'welcome': {
      museum.welcome = m;
      level = m.level;
      rules = m.level.rules;
      buildLevel();
      guardsGroup.clear();
      guardObjects.length = 0;
      showTargets(m.targets);
      showCarried([]);
      loadLooks(m.level.artifact_kinds, m.targets);
      museum.connected = true;
      setStatus('waiting for Phantom', 'wait');
      break;
    }
    case 'snapshot':
      onSnapshot(m);
      break;
    case 'event':
      onEvent(m);
      break;
    case 'summary':
      museum.summary = m;
      showSummary(m);
      setStatus('round over', 'ok');
      break;
    case 'pong':
      if (typeof m.id === 'number' && pings.has(m.id)) {
        const sample = performance.now() / 1000 - pings.get(m.id);
        pings.delete(m.id);
        rttS = rttS === null ? sample : rttS * 0.8 + sample * 0.2;
      }
      break;
    case 'error':
      museum.errors.push(m.message);
      caption(`server: ${m.message}`, 'bad');
      break;
    default:
      break;
  }
}

const pings = new Map();
let rttS = null;  // round trip to the server [s], smoothed
let nextPing = 1;
setInterval(() => {
  if (!museum.connected) return;
  const id = nextPing++;
  pings.set(id, performance.now() / 1000);
  send({ type: 'ping', id });
}, 1000);

function connect() {
  const token = new URLSearchParams(location.search).get('token');
  socket = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  socket.onopen = () => send({ type: 'hello', protocol: 1, role: 'vive', ...(token ? { token } : {}) });
  socket.onmessage = (event) => onMessage(JSON.parse(event.data));
  socket.onclose = () => {
    museum.connected = false;
    lastMove = null;
    if (museum.summary) return;
    setStatus('disconnected, retrying', 'bad');
    setTimeout(connect, 1000);
  };
}

// ---- snapshots: interpolation buffer and reconciliation --------------------------------------
const buffer = [];      // {t: game time [s], snap}, oldest first
let clockOffsetS = null;  // local time minus game time, for the newest snapshots [s]
const history = [];     // Vive's predicted positions {t: local [s], x, y}, oldest first

function predictedAt(t) {
  if (history.length === 0) return null;
  if (t <= history[0].t) return history[0];
  for (let i = history.length - 1; i >= 0; i--) {
    if (history[i].t <= t) {
      const a = history[i], b = history[i + 1];
      if (!b) return a;
      const u = (t - a.t) / (b.t - a.t);
      return { x: a.x + (b.x - a.x) * u, y: a.y + (b.y - a.y) * u };
    }
  }
  return history[0];
}

function onSnapshot(s) {
  const now = performance.now() / 1000;
  museum.snapshot = s;
  museum.snapshots++;
  if (s.vive.running) museum.runningSnapshots++;
  const t = s.tick * rules.tick_s;
  if (museum.trace) museum.trace.push({ snapshot: s.guards.map((g) => [...g.pos]) });
  buffer.push({ t, snap: s });
  while (buffer.length > 40) buffer.shift();
  // the offset follows a faster clock at once, a late frame gently and a pause (game time stood
  // while this clock ran on) at once
  const sample = now - t;
  const behind = clockOffsetS === null ? 0 : sample - clockOffsetS;
  clockOffsetS = clockOffsetS === null || behind < 0 || behind > kPauseS ? sample : clockOffsetS + behind * 0.05;

  // reconciliation: the server's position answers the moves sent about one round trip ago
  const [sx, sy] = s.vive.pos;
  if (!museum.predicted) {
    museum.predicted = [sx, sy];
  } else {
    const then = predictedAt(now - (rttS || 0) - rules.tick_s);
    const ex = sx - (then ? then.x : museum.predicted[0]);
    const ey = sy - (then ? then.y : museum.predicted[1]);
    const error = Math.hypot(ex, ey);
    if (error > kSnapDistance || s.phase !== 'playing') {
      if (error > 1e-6) museum.jumps += error > kSnapDistance ? 1 : 0;
      museum.predicted = [sx, sy];
      history.length = 0;
    } else if (error > 0.005) {
      const k = kCorrectionPerSnapshot;
      museum.predicted[0] += ex * k;
      museum.predicted[1] += ey * k;
      for (const h of history) { h.x += ex * k; h.y += ey * k; }
      museum.corrections++;
    }
  }

  $('timer').textContent = formatTime(s.time_left_s);
  $('timer').className = s.time_left_s <= 30 ? 'low' : '';
  $('table-line').textContent = `On Phantom's table: ${s.table.length}, judged: ${s.judged}`;
  $('caught-line').textContent = `Caught: ${s.vive.times_caught}`;
  const phaseText = {
    waiting: [`waiting for ${s.players.phantom ? 'the round' : 'Phantom'}`, 'wait'],
    playing: ['playing', 'ok'],
    paused: [`paused: ${s.players.phantom ? 'Vive' : 'Phantom'} dropped out`, 'wait'],
    ended: ['round over', 'ok'],
  }[s.phase];
  if (phaseText) setStatus(...phaseText);
  showCarried(s.vive.carried);
  updateCases(s);
}

function updateCases(s) {
  s.cases.forEach((c, i) => {
    const view = cases[i];
    if (!view) return;
    view.glass.visible = !c.broken;
    view.shards.visible = c.broken;
    const kind = c.item ? c.item.kind : null;
    const shown = kind && pieceTextures[kind] ? kind : null;
    if (view.shown !== shown) {
      view.slot.clear();
      if (shown) view.slot.add(pieceSprite(shown));
      view.shown = shown;
    }
  });
  const onTable = JSON.stringify(s.table);
  if (tableSlot.userData.key !== onTable || tableSlot.userData.looks !== Object.keys(pieceTextures).length) {
    tableSlot.clear();
    s.table.forEach((item, i) => {
      const mesh = pieceSprite(item.kind, 0.25);
      mesh.position.x = -0.45 + 0.3 * (i % 4);
      mesh.position.z = -0.15 + 0.3 * Math.floor(i / 4);
      tableSlot.add(mesh);
    });
    tableSlot.userData.key = onTable;
    tableSlot.userData.looks = Object.keys(pieceTextures).length;
  }
}

// the guards at game time t, between the two snapshots around it
function guardsAt(t) {
  if (buffer.length === 0) return [];
  if (t <= buffer[0].t) return buffer[0].snap.guards;
  const last = buffer[buffer.length - 1];
  if (t >= last.t) return last.snap.guards;
  let i = buffer.length - 2;
  while (i > 0 && buffer[i].t > t) i--;
  const a = buffer[i], b = buffer[i + 1];
  const u = (t - a.t) / (b.t - a.t);
  return a.snap.guards.map((ga, g) => {
    const gb = b.snap.guards[g] || ga;
    const fx = ga.facing[0] + (gb.facing[0] - ga.facing[0]) * u;
    const fy = ga.facing[1] + (gb.facing[1] - ga.facing[1]) * u;
    return {
      pos: [ga.pos[0] + (gb.pos[0] - ga.pos[0]) * u, ga.pos[1] + (gb.pos[1] - ga.pos[1]) * u],
      facing: Math.hypot(fx, fy) > 1e-9 ? [fx, fy] : gb.facing,
      mode: u < 0.5 ? ga.mode : gb.mode,
    };
  });
}

// ---- noise rings -------------------------------------------------------------------------------
function addRing(pos, radius, colour, seconds) {
  const material = new THREE.MeshBasicMaterial({ color: colour, transparent: true, opacity: 0.8, depthWrite: false, side: THREE.DoubleSide });
  const ring = new THREE.Mesh(new THREE.RingGeometry(0.92, 1, 64), material);
  ring.rotation.x = -Math.PI / 2;
  ring.position.copy(floorToWorld(pos[0], pos[1], 0.03));
  ring.userData = { radius, born: performance.now() / 1000, seconds };
  ringsGroup.add(ring);
  museum.ringsDrawn++;
}
// the ring of Vive's own running: how far the guards hear her feet
const runRing = new THREE.Mesh(new THREE.RingGeometry(0.95, 1, 64),
  new THREE.MeshBasicMaterial({ color: Colour.vermillion, transparent: true, opacity: 0.7, depthWrite: false, side: THREE.DoubleSide }));
runRing.rotation.x = -Math.PI / 2;
runRing.visible = false;
scene.add(runRing);

function updateRings(now) {
  for (const ring of [...ringsGroup.children]) {
    const { radius, born, seconds } = ring.userData;
    const age = (now - born) / seconds;
    if (age >= 1) {
      ringsGroup.remove(ring);
      ring.geometry.dispose();
      ring.material.dispose();
      continue;
    }
    ring.scale.setScalar(Math.max(0.05, radius * Math.min(1, age * 3)));  // spreads, then fades
    ring.material.opacity = 0.85 * (1 - age);
  }
}

// ---- Vive: input, prediction, the camera ------------------------------------------------------
let lastMove = null;   // the move last sent {x, y, run}
let lastMoveSentS = 0;
let accumulatorS = 0;
let wanted = [0, 0];
let running = false;

// the wanted move of the scripted walk: towards its next waypoint, slowing down for the last so
// she stops on it; null when there is none
function autopilotMove(dt) {
  const pilot = museum.autopilot;
  if (!pilot || !museum.predicted) return null;
  const speed = pilot.run ? rules.run_speed : rules.walk_speed;
  const distanceTo = (p) => Math.hypot(p[0] - museum.predicted[0], p[1] - museum.predicted[1]);
  while (pilot.path.length > 1 && distanceTo(pilot.path[0]) <= Math.max(0.15, speed * dt)) pilot.path.shift();
  if (pilot.path.length === 1 && distanceTo(pilot.path[0]) <= 0.05) pilot.path.shift();
  if (pilot.path.length === 0) {
    museum.autopilot = null;
    return null;
  }
  const dx = pilot.path[0][0] - museum.predicted[0], dy = pilot.path[0][1] - museum.predicted[1];
  const n = Math.hypot(dx, dy);
  yaw = Math.atan2(dy, dx);
  const share = pilot.path.length === 1 ? Math.min(1, n / (speed * kAutopilotBrakeS)) : 1;
  return [(dx / n) * share, (dy / n) * share];
}

function readInput(dt) {
  if (isHeld('turn_left')) yaw += kTurnRadiansPerS * dt;
  if (isHeld('turn_right')) yaw -= kTurnRadiansPerS * dt;
  const f = (isHeld('forward') ? 1 : 0) - (isHeld('back') ? 1 : 0);
  const r = (isHeld('right') ? 1 : 0) - (isHeld('left') ? 1 : 0);
  let x = Math.cos(yaw) * f + Math.sin(yaw) * r;
  let y = Math.sin(yaw) * f - Math.cos(yaw) * r;
  let n = Math.hypot(x, y);
  if (n > 1) { x /= n; y /= n; }
  let run = isHeld('run');
  const piloted = autopilotMove(dt);
  if (piloted) {
    [x, y] = piloted;
    n = Math.hypot(x, y);
    run = museum.autopilot.run;
  }
  want(x, y, run);
}

// the move Vive wants now (a direction, longer than 1 counts as 1), sent when it changes
function want(x, y, run) {
  const n = Math.hypot(x, y);
  wanted = [x, y];
  running = run && n > 0;
  museum.running = running;
  const now = performance.now() / 1000;
  const changed = !lastMove || lastMove.run !== running ||
    Math.hypot(lastMove.x - x, lastMove.y - y) > 0.03 || ((x !== 0 || y !== 0) !== (lastMove.x !== 0 || lastMove.y !== 0));
  if (changed && museum.connected && now - lastMoveSentS > 1 / 30) {
    send({ type: 'move', move: [x, y], run: running });
    lastMove = { x, y, run: running };
    lastMoveSentS = now;
  }
}

// the rules' movement (src/museum/rules.cpp, move_vive): where the floor ends, slide along the
// wall on the axis that stays on the floor
function moveVive(pos, dx, dy) {
  const [x, y] = pos;
  for (const [tx, ty] of [[x + dx, y + dy], [x + dx, y], [x, y + dy]]) {
    if (walkable(tx, ty)) return [tx, ty];
  }
  return pos;
}

function predict(dt) {
  const now = performance.now() / 1000;
  const s = museum.snapshot;
  if (!museum.predicted || !s || s.phase !== 'playing') {
    accumulatorS = 0;
    return;
  }
  // fixed rule ticks, as the server steps
  accumulatorS += dt;
  const speed = running ? rules.run_speed : rules.walk_speed;
  while (accumulatorS >= rules.tick_s) {
    museum.predicted = moveVive(museum.predicted, wanted[0] * speed * rules.tick_s, wanted[1] * speed * rules.tick_s);
    accumulatorS -= rules.tick_s;
  }
  history.push({ t: now, x: museum.predicted[0], y: museum.predicted[1] });
  while (history.length > 0 && history[0].t < now - 2) history.shift();
}

function placeGuards(guards) {
  while (guardObjects.length < guards.length) guardObjects.push(makeGuard());
  museum.guardsDrawn = guards.map((g, i) => {
    const view = guardObjects[i];
    view.group.position.copy(floorToWorld(g.pos[0], g.pos[1]));
    view.group.rotation.y = Math.atan2(g.facing[1], g.facing[0]);
    view.coneMaterial.color.set(kGuardModeColour[g.mode] ?? Colour.sky);
    return [g.pos[0], g.pos[1]];
  });
}

let lastFrameS = performance.now() / 1000;
function frame(time, xrFrame) {
  const now = performance.now() / 1000;
  const dt = Math.min(0.25, now - lastFrameS);
  lastFrameS = now;
  const inVR = xr.presenting();
  if (level) {
    if (inVR) xr.update(dt, museum.summary ? null : xrFrame);
    else if (!museum.summary && $('settings').style.display !== 'block') readInput(dt);
    predict(dt);
    const guards = clockOffsetS === null ? [] : guardsAt(now - clockOffsetS - kInterpolationDelayS);
    placeGuards(guards);
    if (museum.predicted) {
      const [x, y] = museum.predicted;
      if (!inVR) camera.position.copy(floorToWorld(x, y, kEyeHeight));
      runRing.visible = running && museum.snapshot && museum.snapshot.phase === 'playing';
      runRing.position.copy(floorToWorld(x, y, 0.03));
      runRing.scale.setScalar(rules.run_hear_radius);
    }
    updateRings(now);
    const use = usableAction();
    $('prompt').style.display = use ? 'block' : 'none';
    if (use) $('prompt').innerHTML = use.action ? `<kbd>${keyName(keys.use[0] || '?')}</kbd> ${use.text}` : use.text;
    drawMinimap(museum.predicted, guards);
    if (museum.trace) museum.trace.push({ drawn: museum.guardsDrawn.map((p) => [...p]) });
  }
  if (!inVR) camera.rotation.set(pitch, yaw - Math.PI / 2, 0);
  else if (!level || museum.summary) renderer.xr.updateCamera(camera);
  renderer.render(scene, camera);
  museum.frames++;
}

window.addEventListener('resize', () => {
  if (xr.presenting()) return;  // the headset sizes its own views
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

// what the wrist panel shows in VR: the HUD's lines
function panelView() {
  const s = museum.snapshot;
  const use = usableAction();
  const button = { break: 'trigger', take: 'grip', deliver: 'grip' };
  return {
    timer: s ? formatTime(s.time_left_s) : '--:--',
    low: !!s && s.time_left_s <= 30,
    status: museum.summary ? `round over: ${museum.summary.score.points} points` : $('status').textContent,
    caught: s ? s.vive.times_caught : 0,
    table: s ? s.table.length : 0,
    targets: (museum.welcome ? museum.welcome.targets : []).map((kind) => ({ kind, picture: pictureOf(kind) })),
    carried: s ? s.vive.carried.map((item) => item.kind) : [],
    prompt: use ? (use.action ? `${button[use.action]}: ${use.text}` : use.text) : '',
    captions: museum.captions,
  };
}

const xr = createXR({
  renderer, scene, camera, rig, colours: Colour, state: museum.xr,
  game: {
    level: () => level,
    rules: () => rules,
    snapshot: () => museum.snapshot,
    walkable: (x, y) => walkable(x, y),
    body: () => museum.predicted,
    act: useNearest,
    want,
    yaw: () => yaw,
    setYaw: (radians) => { yaw = radians; },
    panel: panelView,
    floorToWorld,
    wallHeight: kWallHeight,
  },
});

showCarried([]);
connect();
renderer.setAnimationLoop(frame);
