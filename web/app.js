// edgeslam live viewer: the snapshot streamed by /api/events (docs/viewer.md) in a three.js scene
// with orbit controls, the figures in a table and a uPlot chart. One page for both views:
//   mobile (`run --viewer`): the client's camera image with its features and mask, its map, its
//                            pose and figures;
//   edge (`server --viewer`): every map the server holds (live and stored); for the chosen one
//                            its points, keyframes, each client's trajectory and live position,
//                            loops and merges, routes; per-client figures; sessions joining and
//                            leaving, loops closed and maps merged.
import * as THREE from 'three';
import { OrbitControls } from './lib/OrbitControls.js';

const COLORS = {
  point: 0xc8cdd7,
  trajectory: 0x5ad17a,
  truth: 0xf0a53c,
  keyframe: 0x5a9cff,
  camera: 0xff5a5a,
  loop: 0xffe14d,
  merge: 0xff4dd2,
  route: 0x4de3ff,
  earlier: 0x8b95a3,  // a stored map's keyframes made by clients no longer connected
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
  frames_loaded: 0, sessions: 0, last_version: 0, maps: 0, map_shown: null, map_live: null,
  map_clients: 0, stored_points: 0, loops: 0, merges: 0, route_checkpoints: 0 };
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

// Loops and merges on the edge view: a segment between the two keyframes of each (short: they see
// one place) and a large dot on each end.
const loopLines = new THREE.LineSegments(dynamicGeometry(), new THREE.LineBasicMaterial({ color: COLORS.loop }));
const mergeLines = new THREE.LineSegments(dynamicGeometry(), new THREE.LineBasicMaterial({ color: COLORS.merge }));
const loopDots = new THREE.Points(dynamicGeometry(),
  new THREE.PointsMaterial({ color: COLORS.loop, size: 12, sizeAttenuation: false }));
const mergeDots = new THREE.Points(dynamicGeometry(),
  new THREE.PointsMaterial({ color: COLORS.merge, size: 14, sizeAttenuation: false }));
scene.add(loopLines, mergeLines, loopDots, mergeDots);
// The checkpoints of routes: a line through them and a dot on each.
const routeLine = new THREE.LineSegments(dynamicGeometry(), new THREE.LineBasicMaterial({ color: COLORS.route }));
const routePoints = new THREE.Points(dynamicGeometry(),
  new THREE.PointsMaterial({ color: COLORS.route, size: 7, sizeAttenuation: false }));
const nextCheckpoint = new THREE.Points(dynamicGeometry(),
  new THREE.PointsMaterial({ color: COLORS.camera, size: 11, sizeAttenuation: false }));
scene.add(routeLine, routePoints, nextCheckpoint);

function showRoutes(routes, next = -1) {
  const segments = [], dots = [], highlight = [];
  for (const checkpoints of routes) {
    for (let i = 0; i + 5 < checkpoints.length; i += 3) segments.push(...checkpoints.slice(i, i + 6));
    dots.push(...checkpoints);
    if (next >= 0 && 3 * next + 2 < checkpoints.length) highlight.push(...checkpoints.slice(3 * next, 3 * next + 3));
  }
  setPositions(routeLine.geometry, segments);
  setPositions(routePoints.geometry, dots);
  setPositions(nextCheckpoint.geometry, highlight);
}

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
let userMoved = false;  // the user dragged or zoomed: the edge view no longer frames itself
controls.addEventListener('start', () => { userMoved = true; });
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
      [COLORS.keyframe, 'keyframes'], [COLORS.truth, 'ground truth'], [COLORS.route, 'route']]);
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
  const route = snapshot.route ?? [];
  if (route.length) rows.push(['checkpoint', s.checkpoint >= 0 ? `${s.checkpoint + 1} / ${route.length / 3}` : '-']);
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
  showRoutes(route.length ? [route] : [], s.checkpoint);
  progress.route_checkpoints = route.length / 3;
  clearGroup(cameraGroup);
  if (snapshot.camera) {
    cameraGroup.add(cameraMesh(snapshot.camera, 2 * size, COLORS.camera));
    followTarget = toDisplay(...snapshot.camera.position);
  }
  if (first) fitView(snapshot.trajectory);
  progress.points = snapshot.points.length / 3;
  requestRender();
}

// --- the edge view: every map the server holds ------------------------------------------------

const mapSelect = document.getElementById('map-choice');
let chosenMap = null;  // a map's name; null: the first live map (or the first stored one)
let fitPending = true;
let storedShown = null;  // { name, map } of the stored map on show, fetched from api/map
mapSelect.addEventListener('change', () => {
  chosenMap = mapSelect.value;
  fitPending = true;
  if (latest) showEdge(latest, false);
});

async function fetchStoredMap(name) {
  if (storedShown && storedShown.name === name) return;
  storedShown = { name, map: null };
  try {
    const response = await fetch('api/map?name=' + encodeURIComponent(name));
    if (!response.ok) throw new Error(await response.text());
    const map = await response.json();
    if (storedShown && storedShown.name === name) storedShown.map = map;
    progress.stored_points = map.points.length / 3;
  } catch (e) {
    setConnection(false, `map '${name}' could not be read: ${e.message}`);
  }
  if (latest) showEdge(latest, false);
}

function mapLabel(m) {
  if (m.live) {
    const n = m.sessions.length;
    return `${m.name} \u00b7 live, ${n} client${n === 1 ? '' : 's'}${m.localize_only ? ', localising' : ''}`;
  }
  return `${m.name} \u00b7 stored, ${m.keyframe_count} keyframes`;
}

function showEdge(snapshot, first) {
  if (first) {
    document.getElementById('view-name').textContent = '\u00b7 edge';
    document.getElementById('map-picker').hidden = false;
    document.getElementById('events').hidden = false;
    makeChart('keyframes per client', CLIENT_COLORS.slice(0, 4).map((c, i) => [`client ${i + 1}`, c]), 'update');
    setLegend([[COLORS.keyframe, 'keyframes'], [COLORS.point, 'map points'], [COLORS.loop, 'loop'],
      [COLORS.merge, 'merge'], [COLORS.route, 'route']]);
    setFollow(false);
  }
  const maps = snapshot.maps;
  const sessions = snapshot.sessions;
  // The picker: one entry per map, live ones first, kept in step with the server's list.
  const labels = maps.map(mapLabel);
  if ([...mapSelect.options].map((o) => o.text).join('|') !== labels.join('|')) {
    mapSelect.innerHTML = '';
    maps.forEach((m, i) => mapSelect.add(new Option(labels[i], m.name)));
  }
  let shownName = chosenMap;
  if (!maps.some((m) => m.name === shownName)) shownName = maps.length ? maps[0].name : null;
  mapSelect.value = shownName ?? '';
  const listed = maps.find((m) => m.name === shownName);
  let map = listed && listed.live ? listed : null;
  if (listed && !listed.live) {
    fetchStoredMap(listed.name);
    if (storedShown && storedShown.name === listed.name) map = storedShown.map;
  }

  const rows = [['maps', `${maps.length} (${maps.filter((m) => m.live).length} live)`],
    ['sessions', `${sessions.length} (${snapshot.status.sessions_opened} opened)`],
    ['loops / merges', `${snapshot.status.loops} / ${snapshot.status.merges}`]];
  if (map) {
    const stored = map.stored ? `, stored ${formatBytes(map.stored.bytes)}` : '';
    rows.push([`map ${map.name}`, `${map.keyframe_count} kf, ${map.map_points} pts${stored}`]);
  }
  for (const s of sessions) {
    rows.push([`\u25cf client ${clientNumber(s.session_id)} \u00b7 ${s.client_name} (${s.sensor})`]);
    rows.push(['map', s.map ?? '-']);
    rows.push(['keyframes', s.keyframe_count]);
    rows.push(['bytes up / down', `${formatBytes(s.uplink_bytes)} / ${formatBytes(s.downlink_bytes)}`]);
    rows.push(['position', formatPosition(s.camera)]);
  }
  showRows(rows);
  // Colour the client headings like their trajectories.
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
    if (/merged/.test(e.text)) li.className = 'merge';
    else if (/loop closed/.test(e.text)) li.className = 'loop';
    events.appendChild(li);
  }

  clearGroup(trajectoryGroup);
  clearGroup(cameraGroup);
  const size = 0.02 * sceneSize;
  const keyframes = [], loops = [], merges = [];
  // A trajectory per client: the session whose keyframes carry that id origin, or an earlier one.
  const inMap = sessions.filter((s) => map && s.map === map.name);
  for (const t of map ? map.trajectories : []) {
    const owner = inMap.find((s) => s.origin === t.origin);
    addTrajectory(t.positions, owner ? clientColor(owner.session_id) : COLORS.earlier);
  }
  for (const kf of map ? map.keyframes : []) frustumSegments(kf, size, keyframes);
  for (const l of map ? map.loops : []) (l.merge ? merges : loops).push(...l.from, ...l.to);
  for (const s of inMap) {
    if (s.camera) cameraGroup.add(cameraMesh(s.camera, 2.5 * size, clientColor(s.session_id)));
  }
  setPositions(pointCloud.geometry, map ? map.points : []);
  setPositions(keyframeLines.geometry, keyframes);
  setPositions(loopLines.geometry, loops);
  setPositions(mergeLines.geometry, merges);
  setPositions(loopDots.geometry, loops);
  setPositions(mergeDots.geometry, merges);
  setPositions(truthLine.geometry, []);
  showRoutes(map ? map.routes.map((r) => r.checkpoints) : []);
  const all = map ? map.trajectories.flatMap((t) => t.positions) : [];
  // Framed as the map grows, until the user moves the view ("fit" frames it again).
  if ((fitPending || !userMoved) && all.length >= 6) {
    fitView(all);
    fitPending = false;
  }
  progress.points = map ? map.points.length / 3 : 0;
  progress.sessions = sessions.length;
  progress.maps = maps.length;
  progress.map_shown = map ? map.name : null;
  progress.map_live = map ? map.live : null;
  progress.map_clients = map ? map.trajectories.length : 0;
  progress.loops = snapshot.status.loops;
  progress.merges = snapshot.status.merges;
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
  userMoved = true;
  const distance = camera3d.position.distanceTo(controls.target);
  camera3d.position.copy(controls.target).add(new THREE.Vector3(0, distance, 0.001));
  requestRender();
});
document.getElementById('fit').addEventListener('click', () => {
  setFollow(false);
  if (!latest) return;
  if (latest.view !== 'edge') {
    fitView(latest.trajectory);
  } else {
    userMoved = false;
    showEdge(latest, false);
  }
});

connect();
