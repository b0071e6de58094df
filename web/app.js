// edgeslam live viewer: the snapshot streamed by /api/events (docs/viewer.md) in a three.js scene
// with orbit controls, the figures in a table and a uPlot chart. One page for both views:
//   mobile (`run --viewer`): the client's camera image with its features and mask, its map, its
//                            pose and figures;
//   edge (`server --viewer`): every session's map, trajectory and live position, per-client
//                            figures, sessions joining and leaving, loop closures.
import * as THREE from 'three';
import { OrbitControls } from './lib/OrbitControls.js';

const COLORS = {
  point: 0xc8cdd7,
  trajectory: 0x5ad17a,
  truth: 0xf0a53c,
  keyframe: 0x5a9cff,
  camera: 0xff5a5a,
};
// One colour per edge session, by session id.
const CLIENT_COLORS = [0x5ad17a, 0x5a9cff, 0xf0a53c, 0xd36bff, 0x3fd0d4, 0xff7a9c, 0xc8d14a];
// Sessions keep the colour of the order they were first seen in.
const sessionColorIndex = new Map();
const clientNumber = (id) => {
  if (!sessionColorIndex.has(id)) sessionColorIndex.set(id, sessionColorIndex.size);
  return sessionColorIndex.get(id) + 1;
};
const clientColor = (id) => CLIENT_COLORS[(clientNumber(id) - 1) % CLIENT_COLORS.length];
const css = (hex) => '#' + hex.toString(16).padStart(6, '0');

// What the browser test reads (tests/browser/viewer_test.mjs).
const progress = { messages: 0, view: null, connected: false, reconnects: 0, points: 0,
  frames_loaded: 0, sessions: 0, last_version: 0 };
window.edgeslamViewer = progress;

// --- the 3D scene ---------------------------------------------------------------------------

const container = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio || 1);
renderer.setClearColor(0x111418);
container.appendChild(renderer.domElement);
const scene = new THREE.Scene();
const camera3d = new THREE.PerspectiveCamera(55, 1, 0.01, 5000);
camera3d.position.set(3, 3, 3);
const controls = new OrbitControls(camera3d, renderer.domElement);
controls.enableDamping = true;
scene.add(new THREE.GridHelper(20, 20, 0x2c333d, 0x1c2129));

// SLAM poses use the camera convention (x right, y down, z forward): display is y up.
const toDisplay = (x, y, z) => new THREE.Vector3(x, -y, -z);

function flatToDisplay(flat, out = new Float32Array(flat.length)) {
  for (let i = 0; i + 2 < flat.length; i += 3) {
    out[i] = flat[i];
    out[i + 1] = -flat[i + 1];
    out[i + 2] = -flat[i + 2];
  }
  return out;
}

// A BufferGeometry whose buffer grows as needed and is otherwise reused.
function dynamicGeometry() {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * 1024), 3));
  geometry.setDrawRange(0, 0);
  return geometry;
}

function setPositions(geometry, flat) {
  let attribute = geometry.getAttribute('position');
  if (attribute.array.length < flat.length) {
    attribute = new THREE.BufferAttribute(new Float32Array(Math.max(flat.length, 2 * attribute.array.length)), 3);
    geometry.setAttribute('position', attribute);
  }
  flatToDisplay(flat, attribute.array);
  attribute.needsUpdate = true;
  geometry.setDrawRange(0, flat.length / 3);
  geometry.computeBoundingSphere();
}

const pointCloud = new THREE.Points(dynamicGeometry(),
  new THREE.PointsMaterial({ color: COLORS.point, size: 2, sizeAttenuation: false, transparent: true, opacity: 0.7 }));
scene.add(pointCloud);
const truthLine = new THREE.Line(dynamicGeometry(), new THREE.LineBasicMaterial({ color: COLORS.truth }));
scene.add(truthLine);
const keyframeLines = new THREE.LineSegments(dynamicGeometry(), new THREE.LineBasicMaterial({ color: COLORS.keyframe }));
scene.add(keyframeLines);
const trajectoryGroup = new THREE.Group();  // one line per trajectory (per client on the edge)
scene.add(trajectoryGroup);
const cameraGroup = new THREE.Group();  // live camera(s)
scene.add(cameraGroup);

// A camera as a pyramid: apex at its centre, base `size` ahead; 16 line-segment ends (SLAM frame).
const FRUSTUM = [[-0.6, -0.45], [0.6, -0.45], [0.6, 0.45], [-0.6, 0.45]];
function frustumSegments(pose, size, out) {
  const q = new THREE.Quaternion(...pose.orientation);
  const c = new THREE.Vector3(...pose.position);
  const corners = FRUSTUM.map(([x, y]) => new THREE.Vector3(x * size, y * size, size).applyQuaternion(q).add(c));
  for (let k = 0; k < 4; ++k) {
    out.push(c.x, c.y, c.z, corners[k].x, corners[k].y, corners[k].z);
    const n = corners[(k + 1) % 4];
    out.push(corners[k].x, corners[k].y, corners[k].z, n.x, n.y, n.z);
  }
}

function cameraMesh(pose, size, color) {
  const flat = [];
  frustumSegments(pose, size, flat);
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(flatToDisplay(flat), 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color }));
}

function clearGroup(group) {
  for (const child of [...group.children]) {
    child.geometry.dispose();
    child.material.dispose();
    group.remove(child);
  }
}

function addTrajectory(flat, color) {
  const geometry = dynamicGeometry();
  setPositions(geometry, flat);
  trajectoryGroup.add(new THREE.Line(geometry, new THREE.LineBasicMaterial({ color })));
}

function extentOf(flat) {
  if (flat.length < 6) return { size: 1, center: new THREE.Vector3() };
  const box = new THREE.Box3();
  for (let i = 0; i + 2 < flat.length; i += 3) box.expandByPoint(toDisplay(flat[i], flat[i + 1], flat[i + 2]));
  return { size: Math.max(1, box.getSize(new THREE.Vector3()).length()), center: box.getCenter(new THREE.Vector3()) };
}

let sceneSize = 1;
let follow = true;
let followTarget = null;
// Drawn only when something changed (new data, the view moved): an idle page costs nothing, and a
// software-rendered page (no GPU) leaves the CPU to tracking.
let needsRender = true;
function requestRender() {
  needsRender = true;
}

function resize() {
  const w = container.clientWidth, h = container.clientHeight;
  renderer.setSize(w, h, false);
  renderer.domElement.style.width = w + 'px';
  renderer.domElement.style.height = h + 'px';
  camera3d.aspect = w / Math.max(1, h);
  camera3d.updateProjectionMatrix();
  needsRender = true;
}
window.addEventListener('resize', resize);
resize();

controls.addEventListener('change', requestRender);
function animate() {
  if (follow && followTarget) {
    const shift = followTarget.clone().sub(controls.target);
    if (shift.lengthSq() > 0) {
      controls.target.add(shift);
      camera3d.position.add(shift);
      needsRender = true;
    }
  }
  if (controls.update()) needsRender = true;
  if (needsRender) {
    needsRender = false;
    renderer.render(scene, camera3d);
  }
  requestAnimationFrame(animate);
}
requestAnimationFrame(animate);

function fitView(flat) {
  const { size, center } = extentOf(flat);
  sceneSize = size;
  controls.target.copy(center);
  camera3d.position.copy(center).add(new THREE.Vector3(0.6, 0.7, 0.9).multiplyScalar(size));
  camera3d.far = 100 * size;
  camera3d.updateProjectionMatrix();
  requestRender();
}

// --- the panel --------------------------------------------------------------------------------

const statsTable = document.getElementById('stats');
function showRows(rows) {
  // rows: [label, value] or [label] for a heading row; rebuilt only when the labels change.
  const key = rows.map((r) => r[0]).join('|');
  if (statsTable.dataset.key !== key) {
    statsTable.dataset.key = key;
    statsTable.innerHTML = '';
    for (const row of rows) {
      const tr = statsTable.insertRow();
      const th = document.createElement('th');
      th.textContent = row[0];
      tr.appendChild(th);
      if (row.length === 1) {
        tr.className = 'client';
        th.colSpan = 2;
      } else {
        tr.insertCell();
      }
    }
  }
  rows.forEach((row, i) => {
    if (row.length > 1) statsTable.rows[i].cells[1].textContent = row[1];
  });
}

function formatBytes(n) {
  if (n >= 1e6) return (n / 1e6).toFixed(2) + ' MB';
  if (n >= 1e3) return (n / 1e3).toFixed(1) + ' KB';
  return n + ' B';
}

function formatPosition(pose) {
  return pose ? pose.position.map((v) => v.toFixed(2)).join(', ') : '-';
}

function setConnection(ok, text) {
  const el = document.getElementById('connection');
  el.className = ok ? 'ok' : 'bad';
  el.textContent = text;
}

function setLegend(items) {
  document.getElementById('legend').innerHTML = items
    .map(([color, label]) => `<span class="swatch" style="background:${css(color)}"></span>${label}`).join(' ');
}

// --- the chart (uPlot, a global from lib/uPlot.iife.min.js) -----------------------------------

const CHART_POINTS = 600;
let chart = null;
let chartData = null;
function makeChart(title, series, xLabel = 'frame') {
  const el = document.getElementById('chart');
  el.innerHTML = '';
  chartData = [[], ...series.map(() => [])];
  chart = new uPlot({
    title, width: el.clientWidth || 300, height: 150,
    scales: { x: { time: false } },
    axes: [{ stroke: '#8b95a3', grid: { stroke: '#232931' } },
      { stroke: '#8b95a3', grid: { stroke: '#232931' }, size: 40 }],
    series: [{ label: xLabel }, ...series.map(([label, color]) => ({ label, stroke: css(color), width: 1.5 }))],
  }, chartData, el);
}

function addChartSample(x, values) {
  if (!chart) return;
  if (chartData[0].length && x <= chartData[0][chartData[0].length - 1]) return;
  chartData[0].push(x);
  values.forEach((v, i) => chartData[i + 1].push(v));
  if (chartData[0].length > CHART_POINTS) chartData.forEach((column) => column.shift());
  chart.setData(chartData);
}

// --- the mobile view: one client's run ---------------------------------------------------------

const frameImage = document.getElementById('frame');
let frameTimer = null;
// The camera image is fetched one at a time, at most 4 a second: the server draws it only then.
function pollFrame() {
  if (frameTimer) return;
  const next = () => { frameTimer = setTimeout(() => { frameTimer = null; pollFrame(); }, 250); };
  const image = new Image();
  image.onload = () => {
    frameImage.src = image.src;
    document.getElementById('camera-image').hidden = false;
    progress.frames_loaded++;
    next();
  };
  image.onerror = next;
  frameTimer = true;
  image.src = 'api/frame.jpg?t=' + Date.now();
}

function showMobile(snapshot, first) {
  const s = snapshot.status;
  if (first) {
    document.getElementById('view-name').textContent = '\u00b7 mobile';
    makeChart('client / end-to-end ms', [['client ms', COLORS.camera], ['e2e ms', COLORS.keyframe]]);
    setLegend([[COLORS.camera, 'camera'], [COLORS.trajectory, 'trajectory'],
      [COLORS.keyframe, 'keyframes'], [COLORS.truth, 'ground truth']]);
    pollFrame();
  }
  const rows = [
    ['frame', `${s.frame} / ${s.frames_total}${s.finished ? ' (done)' : ''}`],
    ['fps', s.fps.toFixed(1)],
    ['state', s.state],
    ['tracked', s.tracked_points],
    ['keyframes', s.keyframes],
    ['map points', s.map_points],
    ['client ms', s.client_ms.toFixed(2)],
    ['e2e ms', (s.e2e_ms ?? 0).toFixed(2)],
    ['position', formatPosition(snapshot.camera)],
    ['bytes up', formatBytes(s.uplink_bytes)],
    ['bytes down', formatBytes(s.downlink_bytes)],
    ['mode', `${s.mode} / ${s.sensor}`],
    ['link', s.link || '-'],
    ['adaptation row', s.adaptation_row >= 0 ? s.adaptation_row + 1 : '-'],
  ];
  if (s.instruction) rows.push(['instruction', s.instruction]);
  showRows(rows);
  addChartSample(s.frame, [s.client_ms, s.e2e_ms ?? null]);

  setPositions(pointCloud.geometry, snapshot.points);
  setPositions(truthLine.geometry, snapshot.ground_truth);
  const flat = [];
  const size = 0.02 * sceneSize;
  for (const kf of snapshot.keyframes) frustumSegments(kf, size, flat);
  setPositions(keyframeLines.geometry, flat);
  clearGroup(trajectoryGroup);
  addTrajectory(snapshot.trajectory, COLORS.trajectory);
  clearGroup(cameraGroup);
  if (snapshot.camera) {
    cameraGroup.add(cameraMesh(snapshot.camera, 2 * size, COLORS.camera));
    followTarget = toDisplay(...snapshot.camera.position);
  }
  if (first) fitView(snapshot.trajectory);
  progress.points = snapshot.points.length / 3;
  requestRender();
}

// --- the edge view: every session the server holds ---------------------------------------------

const sessionSelect = document.getElementById('session');
let chosenSession = 'all';
sessionSelect.addEventListener('change', () => { chosenSession = sessionSelect.value; fitPending = true; });
let fitPending = true;

function showEdge(snapshot, first) {
  if (first) {
    document.getElementById('view-name').textContent = '\u00b7 edge';
    document.getElementById('session-picker').hidden = false;
    document.getElementById('events').hidden = false;
    makeChart('keyframes per client', CLIENT_COLORS.slice(0, 4).map((c, i) => [`client ${i + 1}`, c]), 'update');
    setLegend([[COLORS.keyframe, 'keyframes'], [COLORS.camera, 'live position'], [COLORS.point, 'map points']]);
    setFollow(false);
  }
  const sessions = snapshot.sessions;
  // The picker: "all" and one entry per session, kept in step with the server's list.
  const options = ['all', ...sessions.map((s) => String(s.session_id))];
  if ([...sessionSelect.options].map((o) => o.value).join() !== options.join()) {
    sessionSelect.innerHTML = '';
    for (const value of options) {
      const s = sessions.find((x) => String(x.session_id) === value);
      sessionSelect.add(new Option(s ? `client ${clientNumber(value)} \u00b7 ${s.client_name}` : 'all maps', value));
    }
    if (!options.includes(chosenSession)) chosenSession = 'all';
    sessionSelect.value = chosenSession;
  }
  const shown = sessions.filter((s) => chosenSession === 'all' || String(s.session_id) === chosenSession);

  const rows = [['sessions', `${sessions.length} (${snapshot.status.sessions_opened} opened)`],
    ['loop closures', snapshot.status.loops]];
  for (const s of sessions) {
    rows.push([`\u25cf client ${clientNumber(s.session_id)} \u00b7 ${s.client_name} (${s.sensor})`]);
    rows.push(['keyframes / points', `${s.keyframe_count} / ${s.map_points}`]);
    rows.push(['loops closed', s.loops]);
    rows.push(['bytes up / down', `${formatBytes(s.uplink_bytes)} / ${formatBytes(s.downlink_bytes)}`]);
    rows.push(['position', formatPosition(s.camera)]);
  }
  showRows(rows);
  // Colour the session headings like their trajectories.
  let heading = 0;
  for (const tr of statsTable.rows) {
    if (tr.className === 'client') tr.cells[0].style.color = css(clientColor(sessions[heading++].session_id));
  }
  // Client k of the chart is the k-th session seen (its colour).
  const byOrder = [];
  for (const s of sessions) byOrder[[...sessionColorIndex.keys()].indexOf(s.session_id)] = s.keyframe_count;
  addChartSample(snapshot.version, [0, 1, 2, 3].map((i) => byOrder[i] ?? null));

  const events = document.getElementById('events');
  events.innerHTML = '';
  for (const e of snapshot.events.slice(-12).reverse()) {
    const li = document.createElement('li');
    li.textContent = `${e.time} ${e.text}`;
    events.appendChild(li);
  }

  const points = [], keyframes = [], all = [];
  const size = 0.02 * sceneSize;
  clearGroup(trajectoryGroup);
  clearGroup(cameraGroup);
  for (const s of shown) {
    points.push(...s.points);
    for (const kf of s.keyframes) frustumSegments(kf, size, keyframes);
    addTrajectory(s.trajectory, clientColor(s.session_id));
    all.push(...s.trajectory);
    if (s.camera) cameraGroup.add(cameraMesh(s.camera, 2.5 * size, clientColor(s.session_id)));
  }
  setPositions(pointCloud.geometry, points);
  setPositions(keyframeLines.geometry, keyframes);
  setPositions(truthLine.geometry, []);
  if (fitPending && all.length >= 6) {
    fitView(all);
    fitPending = false;
  }
  progress.points = points.length / 3;
  progress.sessions = sessions.length;
  requestRender();
}

// --- the stream ----------------------------------------------------------------------------------

let latest = null;
let events = null;
function connect() {
  events = new EventSource('api/events');
  events.onopen = () => {
    progress.connected = true;
    setConnection(true, 'live');
  };
  events.onmessage = (message) => {
    const snapshot = JSON.parse(message.data);
    const first = latest === null;
    latest = snapshot;
    progress.view = snapshot.view || 'mobile';
    progress.messages++;
    progress.last_version = snapshot.version;
    if (progress.view === 'edge') {
      showEdge(snapshot, first);
    } else {
      showMobile(snapshot, first);
      if (snapshot.status.finished) setConnection(true, 'run finished');
    }
  };
  events.onerror = () => {
    if (progress.connected) progress.reconnects++;
    progress.connected = false;
    setConnection(false, 'disconnected - reconnecting\u2026');
    // The browser retries by itself unless it gave up (CLOSED): then start over.
    if (events.readyState === EventSource.CLOSED) {
      events.close();
      setTimeout(connect, 2000);
    }
  };
}

function setFollow(on) {
  follow = on;
  document.getElementById('follow').checked = on;
}
document.getElementById('follow').addEventListener('change', (e) => { follow = e.target.checked; });
document.getElementById('top-view').addEventListener('click', () => {
  const distance = camera3d.position.distanceTo(controls.target);
  camera3d.position.copy(controls.target).add(new THREE.Vector3(0, distance, 0.001));
  requestRender();
});
document.getElementById('fit').addEventListener('click', () => {
  setFollow(false);
  if (!latest) return;
  fitView(latest.view === 'edge' ? latest.sessions.flatMap((s) => s.trajectory) : latest.trajectory);
});

connect();
