// The live view of `uh serve` (docs/protocol.md): watches the open session over the WebSocket
// protocol and draws its objects, the tool following the device and the force sent to it, with a
// panel of the session's rates. Bundled with three.js at build time; it fetches nothing else.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const kStateRateHz = 60;
const kForceArrowMetersPerNewton = 0.03;  // arrow length per newton of force

// What the page shows, readable from outside (the browser test reads it).
const live = {
  connected: false,
  scene: null,
  meshes: 0,            // meshes drawn
  states: 0,            // state messages received
  toolPosition: null,   // [x, y, z] of the newest state [m, world]
  toolDrawn: null,      // where the tool was drawn last frame [px, canvas]
  forceN: 0,            // |force| of the newest state [N]
  lastContact: null,
  deformed: 0,          // soft objects' surfaces redrawn from a state's `deformed`
};
const softMeshes = new Map();  // a soft object's name -> its drawn mesh, whose vertices states move
window.uhView = live;

const container = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.setClearColor(0x15181d);
container.appendChild(renderer.domElement);

const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 0.001, 100);
camera.up.set(0, 0, 1);  // the scenes are z-up
camera.position.set(0.25, -0.3, 0.2);
const controls = new OrbitControls(camera, renderer.domElement);
scene.add(new THREE.HemisphereLight(0xe5e9f0, 0x3b4252, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(1, -1, 2);
scene.add(sun);
const grid = new THREE.GridHelper(0.4, 20, 0x4c566a, 0x2e3440);
grid.rotation.x = Math.PI / 2;
scene.add(grid);

const objectsGroup = new THREE.Group();
scene.add(objectsGroup);
const toolMaterial = new THREE.MeshStandardMaterial({ color: 0x88c0d0, metalness: 0.2, roughness: 0.5 });
// the tool and what is drawn about it (its handle, the force), hidden together by `uhView.showTool`
const toolMarks = new THREE.Group();
scene.add(toolMarks);
let tool = new THREE.Group();  // replaced by the tool's mesh once it arrived
toolMarks.add(tool);
// where the device's handle holds the tool: apart from it when the 6-DOF proxy keeps the tool on a
// surface the handle has pushed into
const handleMarker = new THREE.Mesh(new THREE.SphereGeometry(0.002, 12, 8),
                                    new THREE.MeshBasicMaterial({ color: 0xbf616a, wireframe: true }));
handleMarker.visible = false;
toolMarks.add(handleMarker);
const forceArrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.0001, 0xff2a55);
forceArrow.visible = false;
// drawn over the meshes: the force often points along the tool, which would hide it
for (const part of [forceArrow.line, forceArrow.cone]) {
  part.material.depthTest = false;
  part.renderOrder = 1;
}
toolMarks.add(forceArrow);

const $ = (id) => document.getElementById(id);
function setStatus(text, kind) {
  $('status').textContent = text;
  $('status').className = kind;
}

function meshFrom(reply, material) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(reply.vertices, 3));
  geometry.setIndex(reply.triangles);
  geometry.computeVertexNormals();
  return new THREE.Mesh(geometry, material);
}

function applyPose(object3d, pose) {
  object3d.position.fromArray(pose.position);
  const [w, x, y, z] = pose.rotation;
  object3d.quaternion.set(x, y, z, w);
}

let socket = null;
let nextId = 1;
const pending = new Map();
function request(message) {
  const id = nextId++;
  socket.send(JSON.stringify({ ...message, id }));
  return new Promise((resolve, reject) => pending.set(id, { resolve, reject }));
}

let loading = 0;
async function loadScene() {
  const generation = ++loading;
  const reply = await request({ type: 'get_scene' });
  if (generation !== loading) return;
  const description = reply.scene;
  live.scene = description.name;
  $('scene').textContent = description.name;
  objectsGroup.clear();
  softMeshes.clear();
  live.meshes = 0;
  const box = new THREE.Box3();
  for (const object of description.objects) {
    if (!object.has_mesh) continue;
    const geometry = await request({ type: 'get_mesh', object: object.name });
    if (generation !== loading) return;
    const color = object.watched ? 0xd8dee9 : 0x81a1c1;
    const mesh = meshFrom(geometry, new THREE.MeshStandardMaterial({ color, roughness: 0.8 }));
    applyPose(mesh, object.pose);
    if (geometry.soft) softMeshes.set(object.name, mesh);
    objectsGroup.add(mesh);
    box.expandByObject(mesh);
    live.meshes++;
  }
  if (description.tool.has_mesh) {
    const geometry = await request({ type: 'get_mesh', object: description.tool.name });
    if (generation !== loading) return;
    toolMarks.remove(tool);
    tool = meshFrom(geometry, toolMaterial);
    toolMarks.add(tool);
    live.meshes++;
  }
  if (!box.isEmpty()) {
    const center = box.getCenter(new THREE.Vector3());
    const size = box.getSize(new THREE.Vector3()).length();
    controls.target.copy(center);
    camera.position.copy(center).add(new THREE.Vector3(1.1, -1.5, 0.9).multiplyScalar(size));
    camera.near = size / 100;
    camera.far = size * 100;
    camera.updateProjectionMatrix();
  }
}

// a soft object's vertices as its newest simulation step left them (integers of unit_m, object frame)
function showDeformed(entries) {
  for (const entry of entries) {
    const mesh = softMeshes.get(entry.object);
    if (!mesh) continue;
    const position = mesh.geometry.getAttribute('position');
    if (position.array.length !== entry.vertices.length) continue;
    for (let i = 0; i < entry.vertices.length; i++) position.array[i] = entry.vertices[i] * entry.unit_m;
    position.needsUpdate = true;
    mesh.geometry.computeVertexNormals();
    mesh.geometry.computeBoundingSphere();
    live.deformed++;
  }
}

function showState(s) {
  live.states++;
  if (s.deformed) showDeformed(s.deformed);
  live.toolPosition = s.tool.position;
  applyPose(tool, { position: s.tool.position, rotation: s.tool.orientation });
  if (s.handle) {
    handleMarker.position.fromArray(s.handle.position);
    handleMarker.visible = handleMarker.position.distanceTo(new THREE.Vector3().fromArray(s.tool.position)) > 5e-4;
    live.handlePosition = s.handle.position;
  }
  const force = new THREE.Vector3().fromArray(s.force);
  const newtons = force.length();
  live.forceN = newtons;
  forceArrow.visible = newtons > 1e-3;
  if (forceArrow.visible) {
    forceArrow.position.fromArray(s.tool.position);
    forceArrow.setDirection(force.clone().normalize());
    forceArrow.setLength(newtons * kForceArrowMetersPerNewton, 0.015, 0.01);
  }
  toolMaterial.color.set(s.contact_pairs > 0 ? 0xebcb8b : 0x88c0d0);
  $('time').textContent = `${s.time_s.toFixed(2)} s`;
  $('haptic').textContent = `${s.haptic.rate_hz.toFixed(0)} Hz`;
  $('collision').textContent = `${s.collision.rate_hz.toFixed(0)} Hz`;
  $('force').textContent = `${newtons.toFixed(2)} N`;
  $('pairs').textContent = String(s.contact_pairs);
  $('missed').textContent = String(s.haptic.missed_deadlines);
}

function onMessage(message) {
  if (message.id !== undefined && pending.has(message.id)) {
    const { resolve, reject } = pending.get(message.id);
    pending.delete(message.id);
    if (message.type === 'error') reject(new Error(message.message));
    else resolve(message);
    return;
  }
  switch (message.type) {
    case 'state':
      showState(message);
      break;
    case 'session':
      if (message.status === 'closed') {
        objectsGroup.clear();
        live.scene = null;
        $('scene').textContent = '-';
        setStatus('connected, no session', 'wait');
      } else {
        setStatus(`session ${message.status}`, message.status === 'started' ? 'ok' : 'wait');
        if (message.status === 'opened' || message.status === 'edited') loadScene().catch(showError);
      }
      break;
    case 'contact':
      live.lastContact = message;
      $('contact').textContent = `${message.event} ${message.object} @ ${message.time_s.toFixed(2)} s`;
      break;
    case 'error':
      showError(new Error(message.message));
      break;
    default:
      break;
  }
}

function showError(error) {
  setStatus(error.message, 'bad');
}

function connect() {
  const token = new URLSearchParams(location.search).get('token');
  socket = new WebSocket(`${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`);
  socket.onopen = async () => {
    try {
      const welcome = await request({ type: 'hello', protocol: 1, ...(token ? { token } : {}) });
      live.connected = true;
      setStatus(welcome.session ? `session ${welcome.session.status}` : 'connected, no session', 'ok');
      await request({ type: 'subscribe', rate_hz: kStateRateHz });
      if (welcome.session) await loadScene();
    } catch (error) {
      showError(error);
    }
  };
  socket.onmessage = (event) => onMessage(JSON.parse(event.data));
  socket.onclose = () => {
    live.connected = false;
    for (const { reject } of pending.values()) reject(new Error('connection closed'));
    pending.clear();
    setStatus('disconnected, retrying', 'bad');
    setTimeout(connect, 1000);
  };
}

const projected = new THREE.Vector3();
function frame() {
  controls.update();
  renderer.render(scene, camera);
  tool.getWorldPosition(projected).project(camera);
  live.toolDrawn = [(projected.x + 1) * 0.5 * renderer.domElement.width, (1 - projected.y) * 0.5 * renderer.domElement.height];
  requestAnimationFrame(frame);
}

// For the browser test of soft objects (web/tests/soft_view_test.mjs), which sees them only here:
// `softVertices(name)`: the vertices of the mesh drawn for soft object `name` (its geometry's
// positions) in the world frame, flat [x0, y0, z0, ...] [m] (null if no such object is drawn);
// `showTool(visible)`: show or hide the tool, its handle and the force arrow, so that two frames
// differ only by what the objects' meshes do.
live.softVertices = (name) => {
  const mesh = softMeshes.get(name);
  if (!mesh || mesh.parent !== objectsGroup) return null;
  mesh.updateMatrixWorld();
  const position = mesh.geometry.getAttribute('position');
  const vertex = new THREE.Vector3();
  const out = [];
  for (let i = 0; i < position.count; i++) {
    vertex.fromBufferAttribute(position, i).applyMatrix4(mesh.matrixWorld);
    out.push(vertex.x, vertex.y, vertex.z);
  }
  return out;
};
live.showTool = (visible) => { toolMarks.visible = visible; };

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

connect();
frame();
