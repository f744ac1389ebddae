// Vive in virtual reality (WebXR, `immersive-vr`): the museum at true scale around the player's
// floor, for any headset whose browser opens WebXR pages. The page's desktop client stays the
// game's client; this module only turns the headset and its two controllers into the same wanted
// move and actions the keys give (museum.js sends them), so the server stays authoritative.
//
// Where Vive is: the view always follows the head (no forced camera motion). Her body, what the
// server moves, what guards see and what reaches the cases, chases the head at the rules' speeds:
// the page asks for the move that closes the gap, at walking speed, or running (heard by the
// guards) while the player runs with the stick or the head (the player's steps and the stick
// together) moves faster than walking. A head
// that leaves the floor (into a wall) or outruns the body by more than a metre is brought back to
// the body with a blink.
//
// Controls: left stick walks (smoothly, the comfort vignette narrowing the view while it does; the
// stick pressed in runs), right stick left or right turns by 30 degrees, right stick forward aims
// the teleport arc (released: lands there, only on walkable floor in clear line from where the
// player stands; the body walks there silently); trigger breaks the case in reach, grip takes the
// piece or delivers at Phantom's table; X switches standing and seated, Y calibrates the height.
import * as THREE from 'three';

const kSnapTurnRad = Math.PI / 6;
const kStickDead = 0.15;
const kStickOn = 0.7;            // a stick this far out turns or aims
const kStickOff = 0.3;           // and must come back this far before the next
const kFollowS = 0.15;           // the body closes its gap to the head at this time constant [s]
const kStillM = 0.02;            // a gap this small is no move (head tremor)
const kLeashM = 1.0;             // a head this far from the body is brought back to it [m]
const kTeleportMaxM = 6;         // the longest teleport [m]
const kTeleportLaunch = 7;       // the arc's launch speed [m/s]
const kGravity = 9.81;
const kArcPoints = 48;
const kArcStepS = 0.05;
const kClearStepM = 0.05;        // a teleport's straight line is sampled this often
const kSeatedEyeM = 1.6;         // a seated player's eyes are put at this height [m]
const kBlinkS = 0.25;
const kPanelHz = 5;
const kButtonX = 4, kButtonY = 5, kButtonStick = 3;
const kModeStorage = 'uh-museum-vr-mode';

// a point of the scene (y up) over the floor, in the level's frame (museum.js's floorToWorld backwards)
const toLevel = (v) => [v.x, -v.z];

// the comfort vignette: black outside a clear disc around the view's centre, in front of the eyes
function makeVignette() {
  const material = new THREE.ShaderMaterial({
    uniforms: { clear: { value: 0.3 }, opacity: { value: 0 } },
    vertexShader: 'varying vec2 vXY; void main() { vXY = position.xy; gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0); }',
    fragmentShader: 'uniform float clear; uniform float opacity; varying vec2 vXY;' +
      'void main() { gl_FragColor = vec4(0.0, 0.0, 0.0, opacity * smoothstep(clear, clear * 1.6, length(vXY))); }',
    transparent: true, depthTest: false, depthWrite: false,
  });
  const mesh = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), material);
  mesh.position.z = -0.2;
  mesh.renderOrder = 1000;
  mesh.frustumCulled = false;
  mesh.visible = false;
  return mesh;
}

// the teleport arc and its landing mark (a disc where it may land, a cross where it may not)
function makeArc(colours) {
  const positions = new Float32Array(kArcPoints * 3);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  const line = new THREE.Line(geometry, new THREE.LineBasicMaterial({ color: colours.sky }));
  line.frustumCulled = false;
  const ok = new THREE.Mesh(new THREE.CircleGeometry(0.3, 20), new THREE.MeshBasicMaterial({ color: colours.sky, transparent: true, opacity: 0.7 }));
  ok.rotation.x = -Math.PI / 2;
  const crossMaterial = new THREE.MeshBasicMaterial({ color: colours.vermillion });
  const no = new THREE.Group();
  for (const angle of [Math.PI / 4, -Math.PI / 4]) {
    const bar = new THREE.Mesh(new THREE.BoxGeometry(0.6, 0.02, 0.08), crossMaterial);
    bar.rotation.y = angle;
    no.add(bar);
  }
  const group = new THREE.Group();
  group.add(line, ok, no);
  group.visible = false;
  return { group, line, ok, no, positions };
}

// a controller as the player sees it: a low-detail handle in the grip and a short pointer along the ray
function addControllerLooks(ray, grip) {
  const handle = new THREE.Mesh(new THREE.CylinderGeometry(0.018, 0.024, 0.11, 8), new THREE.MeshLambertMaterial({ color: 0x5a606c }));
  handle.rotation.x = -Math.PI / 2.6;
  grip.add(handle);
  const pointer = new THREE.Line(new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(0, 0, 0), new THREE.Vector3(0, 0, -0.4)]),
    new THREE.LineBasicMaterial({ color: 0xf2f2f2, transparent: true, opacity: 0.5 }));
  ray.add(pointer);
}

// Creates the VR mode. `game` gives what museum.js knows: level(), rules(), snapshot(),
// walkable(x, y), body() (the predicted position of Vive's body), act(allowed) (sends the prompt's
// action when allowed), want(x, y, run) (the wanted move), yaw() and setYaw() (where Vive looks),
// panel() (what the wrist panel shows), floorToWorld(x, y, height) and wallHeight (how the scene is
// drawn). Fills `state` (what the page shows, for the tests); returns update() for each XR frame,
// onEvent() for the server's events and presenting().
export function createXR({ renderer, scene, camera, rig, colours, game, state }) {
  const toWorld = game.floorToWorld;
  renderer.xr.enabled = true;
  renderer.xr.setReferenceSpaceType('local-floor');
  renderer.xr.cameraAutoUpdate = false;  // updated after the rig moves, so what rides on the camera keeps up

  const vignette = makeVignette();
  camera.add(vignette);
  const arc = makeArc(colours);
  scene.add(arc.group);
  const bodyMark = new THREE.Mesh(new THREE.RingGeometry(0.18, 0.24, 24),
    new THREE.MeshBasicMaterial({ color: colours.green, transparent: true, opacity: 0.8, depthWrite: false }));
  bodyMark.rotation.x = -Math.PI / 2;
  scene.add(bodyMark);

  const xr = Object.assign(state, {
    supported: false, presenting: false, frames: 0,
    mode: localStorage.getItem(kModeStorage) === 'seated' ? 'seated' : 'standing',
    head: null,            // the head over the floor [x, y] (level frame)
    heightOffset: 0,       // added to the headset's height (seated: eyes at kSeatedEyeM) [m]
    teleports: 0, refused: 0, lastTeleport: null, aiming: null,
    turns: 0, blinks: 0, pulses: { case_broken: 0, guard_heard: 0 },
    actions: [], hands: {}, panelText: '',
  });

  // the controllers: rays (the teleport's aim, the wrist panel on the left) and grips, by handedness once connected
  const hands = {};  // handedness -> {ray, grip, source, pressed (its buttons down last frame), turnArmed}
  for (const index of [0, 1]) {
    const ray = renderer.xr.getController(index);
    const grip = renderer.xr.getControllerGrip(index);
    rig.add(ray, grip);
    addControllerLooks(ray, grip);
    ray.addEventListener('connected', (event) => {
      const source = event.data;
      const hand = { ray, grip, source, pressed: [], turnArmed: true };
      hands[source.handedness] = hand;
      xr.hands[source.handedness] = true;
      if (source.handedness === 'left') ray.add(panel.mesh);
    });
    ray.addEventListener('disconnected', () => {
      for (const [side, hand] of Object.entries(hands)) if (hand.ray === ray) { delete hands[side]; delete xr.hands[side]; }
    });
    ray.addEventListener('selectstart', () => { xr.actions.push(['trigger', game.act(['break'])]); });
    ray.addEventListener('squeezestart', () => { xr.actions.push(['grip', game.act(['take', 'deliver'])]); });
  }

  const panel = makePanel();
  let placed = false;
  let teleportWalk = null;  // {to, until}: the body walks to a teleport's landing; no leash meanwhile
  let blinkUntil = 0;
  let lastHead = null;      // the head over the floor last frame; null after a jump (a teleport)
  let headSpeed = 0;        // the head's speed over the floor, the player's steps and the stick together, smoothed [m/s]
  let calibrateNext = true;

  // ---- entering and leaving ----------------------------------------------------------------------
  const button = document.getElementById('enter-vr');
  const modeSelect = document.getElementById('vr-mode');
  if (modeSelect) {
    modeSelect.value = xr.mode;
    modeSelect.onchange = () => setMode(modeSelect.value);
  }
  if (navigator.xr && navigator.xr.isSessionSupported) {
    navigator.xr.isSessionSupported('immersive-vr').then((supported) => {
      xr.supported = supported;
      if (supported && button) button.parentElement.style.display = 'block';
    }, () => {});
  }
  if (button) {
    button.onclick = () => enter().catch((error) => {  // refused by the player or the browser: say so on the button
      button.textContent = 'Enter VR (refused)';
      button.title = String(error && error.message ? error.message : error);
    });
  }

  async function enter() {
    if (xr.presenting) return;
    const session = await navigator.xr.requestSession('immersive-vr', { requiredFeatures: ['local-floor'] });
    session.addEventListener('end', leave);
    await renderer.xr.setSession(session);
    xr.presenting = true;
    placed = false;
    lastHead = null;
    calibrateNext = true;
  }
  function leave() {
    xr.presenting = false;
    rig.position.set(0, 0, 0);
    rig.rotation.set(0, 0, 0);
    arc.group.visible = false;
    bodyMark.visible = false;
    game.want(0, 0, false);
  }

  function setMode(mode) {
    xr.mode = mode;
    localStorage.setItem(kModeStorage, mode);
    if (modeSelect) modeSelect.value = mode;
    calibrateNext = true;
  }

  // ---- where the head is ---------------------------------------------------------------------------
  const scratch = new THREE.Vector3();
  function headWorld(local) {
    rig.updateMatrixWorld();
    return scratch.set(local.x, local.y, local.z).applyMatrix4(rig.matrixWorld).clone();
  }
  // moves the rig over the floor so the head stands at [x, y] (level frame)
  function putHeadAt(local, [x, y]) {
    const head = headWorld(local);
    rig.position.x += x - head.x;
    rig.position.z += -y - head.z;
    rig.updateMatrixWorld();
  }
  // turns the rig about the head
  function turn(local, radians) {
    const at = toLevel(headWorld(local));
    rig.rotation.y += radians;
    putHeadAt(local, at);
  }
  function blink() {
    blinkUntil = performance.now() / 1000 + kBlinkS;
    xr.blinks++;
  }

  // ---- the teleport arc ----------------------------------------------------------------------------
  // true when the straight line from a to b stays on the floor (as the rules' clear_path, sampled)
  function clearLine(a, b) {
    const n = Math.max(1, Math.ceil(Math.hypot(b[0] - a[0], b[1] - a[1]) / kClearStepM));
    for (let i = 0; i <= n; i++) {
      if (!game.walkable(a[0] + ((b[0] - a[0]) * i) / n, a[1] + ((b[1] - a[1]) * i) / n)) return false;
    }
    return true;
  }
  // traces the arc from the hand's ray; returns {land [x, y], ok, why}
  function traceArc(hand, from) {
    hand.ray.updateMatrixWorld();
    const origin = new THREE.Vector3().setFromMatrixPosition(hand.ray.matrixWorld);
    const dir = new THREE.Vector3(0, 0, -1).transformDirection(hand.ray.matrixWorld);
    const velocity = dir.multiplyScalar(kTeleportLaunch);
    const p = origin.clone();
    let count = 0, hitWall = false;
    for (; count < kArcPoints; count++) {
      arc.positions.set([p.x, p.y, p.z], count * 3);
      if (p.y <= 0 || hitWall) break;
      const next = p.clone().addScaledVector(velocity, kArcStepS);
      velocity.y -= kGravity * kArcStepS;
      if (next.y <= 0) p.lerp(next, p.y / (p.y - next.y));  // down to the floor between two samples
      else p.copy(next);
      hitWall = p.y < game.wallHeight && !game.walkable(...toLevel(p));  // the arc ends where it meets a wall
    }
    arc.line.geometry.setDrawRange(0, Math.min(kArcPoints, count + 1));
    arc.line.geometry.attributes.position.needsUpdate = true;
    const land = toLevel(p);
    let why = '';
    if (teleportWalk) why = 'the body is still on its way';
    else if (hitWall) why = 'a wall';
    else if (p.y > 0.001) why = 'too far';
    else if (!game.walkable(...land)) why = 'not floor';
    else if (Math.hypot(land[0] - from[0], land[1] - from[1]) > kTeleportMaxM) why = 'too far';
    else if (!clearLine(from, land)) why = 'no clear way';
    const ok = why === '';
    arc.line.material.color.set(ok ? colours.sky : colours.vermillion);
    arc.ok.visible = ok;
    arc.no.visible = !ok;
    const mark = ok ? arc.ok : arc.no;
    mark.position.copy(toWorld(land[0], land[1], 0.04));
    return { land, ok, why };
  }

  // ---- the controllers' buttons and sticks, each frame ------------------------------------------------
  const edge = (hand, index) => {
    const buttons = hand.source.gamepad ? hand.source.gamepad.buttons : [];
    const down = !!(buttons[index] && buttons[index].pressed);
    const was = !!hand.pressed[index];
    hand.pressed[index] = down;
    return down && !was;
  };
  const stick = (hand) => {
    const axes = hand && hand.source.gamepad ? hand.source.gamepad.axes : [];
    const x = axes.length >= 4 ? axes[2] : axes[0] || 0;
    const y = axes.length >= 4 ? axes[3] : axes[1] || 0;
    return Math.hypot(x, y) < kStickDead ? [0, 0] : [x, y];
  };

  // the right stick: turn by snaps, aim and release the teleport
  function rightStick(hand, local, from, playing) {
    const [x, y] = stick(hand);
    if (Math.abs(x) < kStickOff && Math.abs(y) < kStickOff) {
      if (xr.aiming && playing) release(local, from);
      xr.aiming = null;
      arc.group.visible = false;
      hand.turnArmed = true;
      return;
    }
    if (hand.turnArmed && Math.abs(x) > kStickOn && Math.abs(x) > Math.abs(y)) {
      hand.turnArmed = false;
      turn(local, x > 0 ? -kSnapTurnRad : kSnapTurnRad);
      xr.turns++;
    }
    if (y < -kStickOn && playing) {
      xr.aiming = traceArc(hand, from);
      arc.group.visible = true;
    }
  }
  function release(local, from) {
    const { land, ok, why } = xr.aiming;
    if (!ok) {
      xr.refused++;
      xr.lastRefused = { land, why };
      return;
    }
    putHeadAt(local, land);
    lastHead = null;
    xr.teleports++;
    xr.lastTeleport = { from: [...from], to: land };
    teleportWalk = { to: land, until: performance.now() / 1000 + Math.hypot(land[0] - from[0], land[1] - from[1]) / game.rules().walk_speed + 1 };
  }

  // the left stick walks the rig (the head slides along walls as the rules slide Vive); returns how
  // far out the stick is and whether it runs
  function leftStick(hand, local, facing, dt) {
    const [sx, sy] = stick(hand);
    const magnitude = Math.min(1, Math.hypot(sx, sy));
    if (magnitude === 0) return { magnitude, run: false };
    const run = !!(hand.source.gamepad && hand.source.gamepad.buttons[kButtonStick] && hand.source.gamepad.buttons[kButtonStick].pressed);
    const rules = game.rules();
    const speed = (run ? rules.run_speed : rules.walk_speed) * dt;
    const f = -sy, r = sx;
    const dx = (facing[0] * f + facing[1] * r) * speed;
    const dy = (facing[1] * f - facing[0] * r) * speed;
    const [hx, hy] = toLevel(headWorld(local));
    for (const [tx, ty] of [[hx + dx, hy + dy], [hx + dx, hy], [hx, hy + dy]]) {
      if (game.walkable(tx, ty)) { putHeadAt(local, [tx, ty]); break; }
    }
    return { magnitude, run };
  }

  function calibrate(local) {
    xr.heightOffset = xr.mode === 'seated' ? kSeatedEyeM - local.y : 0;
    rig.position.y = xr.heightOffset;
    calibrateNext = false;
  }

  // ---- each XR frame ----------------------------------------------------------------------------------
  function update(dt, frame) {
    const pose = frame && frame.getViewerPose(renderer.xr.getReferenceSpace());
    const body = game.body();
    const now = performance.now() / 1000;
    if (game.level()) panel.draw(now, game.panel());
    if (!pose || !body || !game.level()) {
      renderer.xr.updateCamera(camera);
      return;
    }
    xr.frames++;
    const local = pose.transform.position;
    const q = pose.transform.orientation;
    if (calibrateNext) calibrate(local);
    if (!placed) {
      // the head where the body is, facing where the desktop view faced
      const forward = new THREE.Vector3(0, 0, -1).applyQuaternion(new THREE.Quaternion(q.x, q.y, q.z, q.w));
      rig.rotation.y = game.yaw() - Math.atan2(-forward.z, forward.x);
      putHeadAt(local, body);
      placed = true;
    }
    const s = game.snapshot();
    const playing = !!s && s.phase === 'playing';
    const left = hands.left || hands.none, right = hands.right;
    const orientation = new THREE.Quaternion(q.x, q.y, q.z, q.w).premultiply(rig.quaternion);
    const look = new THREE.Vector3(0, 0, -1).applyQuaternion(orientation);
    const lookLevel = [look.x, -look.z];
    const n = Math.hypot(...lookLevel) || 1;
    const facing = [lookLevel[0] / n, lookLevel[1] / n];
    game.setYaw(Math.atan2(facing[1], facing[0]));

    let walking = { magnitude: 0, run: false };
    if (left && playing) walking = leftStick(left, local, facing, dt);
    if (right) rightStick(right, local, toLevel(headWorld(local)), playing);
    if (left && edge(left, kButtonX)) setMode(xr.mode === 'seated' ? 'standing' : 'seated');
    if (left && edge(left, kButtonY)) calibrateNext = true;

    // the body chases the head; the leash brings the head back to a body that cannot follow
    let head = toLevel(headWorld(local));
    if (lastHead && dt > 0) {
      const moved = Math.hypot(head[0] - lastHead[0], head[1] - lastHead[1]) / dt;
      headSpeed += (moved - headSpeed) * Math.min(1, dt / 0.2);
    }
    let gap = [head[0] - body[0], head[1] - body[1]];
    let distance = Math.hypot(...gap);
    if (teleportWalk && (distance < 0.1 || now > teleportWalk.until)) teleportWalk = null;
    if (!teleportWalk && (distance > kLeashM || !game.walkable(...head))) {
      putHeadAt(local, body);
      blink();
      head = [...body];
      gap = [0, 0];
      distance = 0;
    }
    lastHead = head;
    const rules = game.rules();
    const run = playing && !teleportWalk && (walking.run || headSpeed > rules.walk_speed * 1.1);
    const speed = run ? rules.run_speed : rules.walk_speed;
    if (!playing || distance < kStillM) game.want(0, 0, false);
    else {
      const k = Math.min(1, distance / (speed * kFollowS)) / distance;
      game.want(gap[0] * k, gap[1] * k, run);
    }
    xr.head = head;
    xr.headSpeed = headSpeed;
    xr.facing = Math.atan2(facing[1], facing[0]);
    xr.rigYaw = rig.rotation.y;

    bodyMark.visible = distance > 0.15;
    bodyMark.position.copy(toWorld(body[0], body[1], 0.035));
    const blinking = now < blinkUntil;
    const strength = blinking ? 1 : walking.magnitude * (walking.run ? 0.9 : 0.7);
    vignette.visible = strength > 0.01;
    vignette.material.uniforms.opacity.value = blinking ? 1 : Math.min(1, strength * 1.4);
    vignette.material.uniforms.clear.value = blinking ? 0 : 0.3 - 0.2 * strength;
    xr.vignette = strength;
    renderer.xr.updateCamera(camera);
  }

  // ---- haptics: glass breaking and a guard hearing her, on every controller that can pulse ------------------
  function pulse(strength, ms) {
    for (const hand of Object.values(hands)) {
      const gamepad = hand.source.gamepad;
      if (!gamepad) continue;
      const actuator = gamepad.hapticActuators && gamepad.hapticActuators[0];
      if (actuator && actuator.pulse) actuator.pulse(strength, ms);
      else if (gamepad.vibrationActuator && typeof gamepad.vibrationActuator.playEffect === 'function') gamepad.vibrationActuator.playEffect('dual-rumble', { duration: ms, strongMagnitude: strength, weakMagnitude: strength });
    }
  }
  function onEvent(e) {
    if (!xr.presenting) return;
    if (e.event === 'case_broken') { pulse(0.7, 120); xr.pulses.case_broken++; }
    if (e.event === 'guard_heard') { pulse(1.0, 300); xr.pulses.guard_heard++; }  // only Vive makes noise
  }

  // ---- the wrist panel: Falcon's pictures, the timer, what she carries, what the buttons do ---------------
  function makePanel() {
    const canvas = document.createElement('canvas');
    canvas.width = 512;
    canvas.height = 384;
    const texture = new THREE.CanvasTexture(canvas);
    texture.colorSpace = THREE.SRGBColorSpace;
    const mesh = new THREE.Mesh(new THREE.PlaneGeometry(0.2, 0.15), new THREE.MeshBasicMaterial({ map: texture, transparent: true }));
    mesh.position.set(0, 0.05, 0.03);  // over the hand, tilted up at the eyes while the hand points ahead
    mesh.rotation.x = -0.7;
    const images = {};
    const image = (url) => {
      if (!images[url]) { images[url] = new Image(); images[url].onload = () => { lastKey = ''; }; images[url].src = url; }
      return images[url];
    };
    let lastKey = '', lastDraw = 0;
    function draw(now, view) {
      const key = JSON.stringify(view);
      if (key === lastKey || now - lastDraw < 1 / kPanelHz) return;
      lastKey = key;
      lastDraw = now;
      const c = canvas.getContext('2d');
      c.fillStyle = 'rgba(12, 14, 18, 0.9)';
      c.fillRect(0, 0, 512, 384);
      c.fillStyle = view.low ? '#f0e442' : '#f2f2f2';
      c.font = 'bold 56px system-ui, sans-serif';
      c.fillText(view.timer, 16, 60);
      c.fillStyle = '#f2f2f2';
      c.font = '22px system-ui, sans-serif';
      c.fillText(view.status, 200, 34);
      c.fillText(`caught ${view.caught}, on the table ${view.table}`, 200, 62);
      view.targets.forEach((t, i) => {
        const x = 16 + i * 124;
        const picture = image(t.picture);
        if (picture.complete && picture.naturalWidth > 0) c.drawImage(picture, x, 80, 96, 96);
        c.fillText(t.kind, x, 200);
      });
      c.fillText(`carrying: ${view.carried.length ? view.carried.join(', ') : 'nothing'}`, 16, 244);
      c.fillStyle = '#56b4e9';
      c.fillText(view.prompt, 16, 284);
      c.fillStyle = '#f2f2f2';
      view.captions.slice(-2).forEach((line, i) => c.fillText(line.slice(0, 44), 16, 326 + i * 30));
      texture.needsUpdate = true;
      xr.panelText = [view.timer, view.status, view.prompt, ...view.targets.map((t) => t.kind)].join(' | ');
    }
    return { mesh, draw };
  }

  return { update, onEvent, enter, presenting: () => xr.presenting };
}
