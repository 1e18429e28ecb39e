// plslam map viewer: draws /api/scene with three.js and keeps it up to date while a run goes on.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { SceneLayers, LAYER_NAMES, sceneBounds } from './scene_layers.js';
import { CameraViews } from './camera_views.js';
import { SceneClient } from './scene_client.js';
import { showScene, showError, showLayerContent } from './panel.js';

const container = document.getElementById('view');
// preserveDrawingBuffer: tests (and screenshots) read the canvas back after the frame.
const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setClearColor(0x15181d);
container.appendChild(renderer.domElement);

const scene = new THREE.Scene();
const root = new THREE.Group();
root.rotation.x = Math.PI;          // world y points down: turn it so that up is up on screen
scene.add(root);

const camera = new THREE.PerspectiveCamera(55, 1, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = true;
controls.dampingFactor = 0.15;
const views = new CameraViews(camera, controls);
const layers = new SceneLayers(root);

// Render only when something changed, and ask for animation frames only then: a page that
// requests a frame on every vsync keeps the browser's compositor (and, without a GPU, its
// software renderer) busy 60 times a second even when it draws nothing.
let needsRender = true;
let frameRequested = false;
function scheduleFrame() {
  if (frameRequested) return;
  frameRequested = true;
  requestAnimationFrame(animate);
}
const requestRender = () => { needsRender = true; scheduleFrame(); };

// Software renderers (no GPU: SwiftShader, some remote desktops) draw 100k points at 10-25
// frames per second on 2 cores (bench/viewer_load.sh). Once frames of a moving view come slower than SLOW_FRAME_MS three times
// in a row, points and lines are thinned while the view moves; the still view is always full.
const SLOW_FRAME_MS = 34;           // slower than ~30 fps (a frame every other 60 Hz vsync)
const MOVING_MS = 200;              // the view counts as moving this long after its last change
let lastChange = -Infinity;
let thinWhileMoving = false;
let slowFrames = 0;
let previousFrame = null;           // time of the previous animation frame, if it rendered
controls.addEventListener('change', () => { lastChange = performance.now(); requestRender(); });
controls.addEventListener('start', scheduleFrame);   // a drag or a wheel turn begins

function render(coarse = false) {
  layers.setCoarse(coarse);
  renderer.render(scene, camera);
  needsRender = false;
  hook.rendered++;
}

function animate(now) {
  frameRequested = false;
  controls.update();                // damping keeps the view gliding ('change') after the mouse stops
  const moving = now - lastChange < MOVING_MS;
  if (!moving && layers.coarse) needsRender = true;      // show the full map once still
  if (needsRender) {
    if (moving && previousFrame !== null) {
      slowFrames = now - previousFrame > SLOW_FRAME_MS ? slowFrames + 1 : 0;
      if (slowFrames >= 3) thinWhileMoving = hook.thinWhileMoving = true;
    }
    render(moving && thinWhileMoving);
    previousFrame = now;
  } else {
    previousFrame = null;
  }
  // Go on while the view moves (each 'change' renews lastChange) or the full map is still to be
  // shown once it stops.
  if (moving || layers.coarse) scheduleFrame();
}

function resize() {
  const width = Math.max(1, container.clientWidth), height = Math.max(1, container.clientHeight);
  renderer.setSize(width, height, false);
  camera.aspect = width / height;
  camera.updateProjectionMatrix();
  requestRender();
}
new ResizeObserver(resize).observe(container);
resize();

// ---- layers and colours, shared by the panel's controls and the test hook ----

function setLayer(name, on) {
  if (!LAYER_NAMES.includes(name)) throw new Error(`unknown layer ${name}`);
  layers.setVisible(name, Boolean(on));
  hook.layers[name] = Boolean(on);
  document.getElementById(`layer-${name}`).checked = Boolean(on);
  requestRender();
}

function setPointColour(mode) {
  layers.setPointColour(mode);
  document.getElementById('point-colour').value = layers.pointColour;
  requestRender();
}

for (const name of LAYER_NAMES) {
  const box = document.getElementById(`layer-${name}`);
  box.checked = layers.isVisible(name);
  box.addEventListener('change', () => setLayer(name, box.checked));
}
document.getElementById('point-colour').addEventListener('change', (event) => setPointColour(event.target.value));

const followBox = document.getElementById('follow-camera');
followBox.addEventListener('change', () => { if (followBox.checked) views.follow(lastCamera); });
document.getElementById('view-fit').addEventListener('click', () => { followBox.checked = false; views.fit(); });
document.getElementById('view-top').addEventListener('click', () => { followBox.checked = false; views.top(); });

// ---- data ----

let lastCamera = null;

function onScene(doc) {
  const bounds = sceneBounds(doc);
  layers.update(doc, bounds);
  views.setBounds(bounds);
  lastCamera = doc.camera ?? null;
  if (!hook.ready) views.fit();     // later documents keep the user's view
  else if (followBox.checked) views.follow(lastCamera);
  showScene(doc);
  showLayerContent(layers.drawn);
  hook.revision = doc.revision ?? null;
  hook.counts = doc.counts;
  hook.drawn = { ...layers.drawn };
  hook.final = Boolean(doc.final);
  render();
  if (!hook.ready) hook.loadMs = performance.now();   // from navigation start
  hook.ready = true;
}

// Test hook (tests/web/viewer_page.mjs). Beyond ready/revision/counts/layers and the three
// functions, the test reads: final, loadMs (navigation start to first frame), drawn (what
// each layer holds), rendered (frames so far), thinWhileMoving (this renderer was found slow)
// and orbit() (a scripted orbit step). render() always draws the full map.
const hook = {
  ready: false,
  revision: null,
  counts: null,
  final: false,
  loadMs: null,
  layers: Object.fromEntries(LAYER_NAMES.map((name) => [name, layers.isVisible(name)])),
  drawn: {},
  rendered: 0,
  thinWhileMoving: false,
  setLayer,
  setPointColour,
  render: () => render(false),
  orbit(radians) {
    const offset = camera.position.clone().sub(controls.target);
    offset.applyAxisAngle(new THREE.Vector3(0, 1, 0), radians);
    camera.position.copy(controls.target).add(offset);
    controls.update();
  },
};
window.plslamViewer = hook;

new SceneClient({ onScene, onError: showError }).start();
scheduleFrame();
