// edgeslam live viewer: draws the snapshot streamed by /api/events (see docs/viewer.md) on a 2D
// canvas with a small perspective camera of its own. No libraries.
'use strict';

const canvas = document.getElementById('view');
const ctx = canvas.getContext('2d');
const COLORS = {
  point: 'rgba(200, 205, 215, 0.55)',
  trajectory: '#5ad17a',
  truth: '#f0a53c',
  keyframe: '#5a9cff',
  camera: '#ff5a5a',
};

let snapshot = null;
// Orbit view around `target` (display frame: y up).
const view = { yaw: 0.6, pitch: 0.5, distance: 5, target: [0, 0, 0], fov: 1.0 };
let follow = true;
let needsDraw = false;

// SLAM poses use the camera convention (x right, y down, z forward): turn it y-up for display.
function toDisplay(x, y, z) {
  return [x, -y, -z];
}

function rotate(q, v) {
  // q = [x, y, z, w]; v' = q v q*
  const [qx, qy, qz, qw] = q;
  const tx = 2 * (qy * v[2] - qz * v[1]);
  const ty = 2 * (qz * v[0] - qx * v[2]);
  const tz = 2 * (qx * v[1] - qy * v[0]);
  return [v[0] + qw * tx + (qy * tz - qz * ty), v[1] + qw * ty + (qz * tx - qx * tz),
    v[2] + qw * tz + (qx * ty - qy * tx)];
}

function eye() {
  const c = Math.cos(view.pitch);
  return [view.target[0] + view.distance * c * Math.sin(view.yaw),
    view.target[1] + view.distance * Math.sin(view.pitch),
    view.target[2] + view.distance * c * Math.cos(view.yaw)];
}

// Camera basis for the current view: right, up, back (from target towards the eye).
function basis() {
  const e = eye();
  let back = [e[0] - view.target[0], e[1] - view.target[1], e[2] - view.target[2]];
  const n = Math.hypot(...back) || 1;
  back = back.map((v) => v / n);
  let right = [back[2], 0, -back[0]];  // world up x back
  const rn = Math.hypot(...right);
  right = rn < 1e-6 ? [1, 0, 0] : right.map((v) => v / rn);
  const up = [back[1] * right[2] - back[2] * right[1], back[2] * right[0] - back[0] * right[2],
    back[0] * right[1] - back[1] * right[0]];
  return { e, right, up, back };
}

function projector() {
  const { e, right, up, back } = basis();
  const w = canvas.width, h = canvas.height;
  const f = 0.5 * h / Math.tan(view.fov / 2);
  return (p) => {
    const d = [p[0] - e[0], p[1] - e[1], p[2] - e[2]];
    const z = -(d[0] * back[0] + d[1] * back[1] + d[2] * back[2]);
    if (z < 1e-3) return null;
    return [w / 2 + f * (d[0] * right[0] + d[1] * right[1] + d[2] * right[2]) / z,
      h / 2 - f * (d[0] * up[0] + d[1] * up[1] + d[2] * up[2]) / z];
  };
}

function flatToDisplay(flat) {
  const out = [];
  for (let i = 0; i + 2 < flat.length; i += 3) out.push(toDisplay(flat[i], flat[i + 1], flat[i + 2]));
  return out;
}

function sceneExtent() {
  const traj = snapshot ? flatToDisplay(snapshot.trajectory) : [];
  if (traj.length < 2) return 1;
  const min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
  for (const p of traj) for (let k = 0; k < 3; ++k) { min[k] = Math.min(min[k], p[k]); max[k] = Math.max(max[k], p[k]); }
  return Math.max(1, Math.hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]));
}

function drawPolyline(project, points, color, width) {
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.beginPath();
  let pen = false;
  for (const p of points) {
    const s = project(p);
    if (!s) { pen = false; continue; }
    if (pen) ctx.lineTo(s[0], s[1]); else ctx.moveTo(s[0], s[1]);
    pen = true;
  }
  ctx.stroke();
}

// A camera as a small pyramid: apex at the centre, base ahead along the viewing direction.
function drawFrustum(project, pose, size, color, width) {
  const c = pose.position;
  const q = pose.orientation;
  const corner = (x, y) => {
    const v = rotate(q, [x * size, y * size, size]);
    return project(toDisplay(c[0] + v[0], c[1] + v[1], c[2] + v[2]));
  };
  const apex = project(toDisplay(c[0], c[1], c[2]));
  const k = [corner(-0.6, -0.45), corner(0.6, -0.45), corner(0.6, 0.45), corner(-0.6, 0.45)];
  if (!apex || k.some((s) => !s)) return;
  ctx.strokeStyle = color;
  ctx.lineWidth = width;
  ctx.beginPath();
  for (const s of k) { ctx.moveTo(apex[0], apex[1]); ctx.lineTo(s[0], s[1]); }
  ctx.moveTo(k[3][0], k[3][1]);
  for (const s of k) ctx.lineTo(s[0], s[1]);
  ctx.stroke();
}

function draw() {
  needsDraw = false;
  const dpr = window.devicePixelRatio || 1;
  const w = Math.floor(canvas.clientWidth * dpr), h = Math.floor(canvas.clientHeight * dpr);
  if (canvas.width !== w || canvas.height !== h) { canvas.width = w; canvas.height = h; }
  ctx.fillStyle = '#111418';
  ctx.fillRect(0, 0, w, h);
  if (!snapshot) return;
  if (follow && snapshot.camera) {
    const p = snapshot.camera.position;
    view.target = toDisplay(p[0], p[1], p[2]);
  }
  const project = projector();
  ctx.fillStyle = COLORS.point;
  const dot = Math.max(1, Math.round(1.5 * dpr));
  const pts = snapshot.points;
  for (let i = 0; i + 2 < pts.length; i += 3) {
    const s = project(toDisplay(pts[i], pts[i + 1], pts[i + 2]));
    if (s) ctx.fillRect(s[0], s[1], dot, dot);
  }
  const size = 0.02 * sceneExtent();
  if (snapshot.ground_truth.length) drawPolyline(project, flatToDisplay(snapshot.ground_truth), COLORS.truth, 1.5 * dpr);
  for (const kf of snapshot.keyframes) drawFrustum(project, kf, size, COLORS.keyframe, 1 * dpr);
  drawPolyline(project, flatToDisplay(snapshot.trajectory), COLORS.trajectory, 2 * dpr);
  if (snapshot.camera) drawFrustum(project, snapshot.camera, 2 * size, COLORS.camera, 2.5 * dpr);
}

function requestDraw() {
  if (needsDraw) return;
  needsDraw = true;
  requestAnimationFrame(draw);
}

function formatBytes(n) {
  if (n >= 1e6) return (n / 1e6).toFixed(2) + ' MB';
  if (n >= 1e3) return (n / 1e3).toFixed(1) + ' KB';
  return n + ' B';
}

function showStats(s) {
  const set = (id, text) => { document.getElementById(id).textContent = text; };
  set('frame', `${s.frame} / ${s.frames_total}${s.finished ? ' (done)' : ''}`);
  set('fps', s.fps.toFixed(1));
  set('state', s.state);
  set('tracked', s.tracked_points);
  set('keyframes', s.keyframes);
  set('points', s.map_points);
  set('client-ms', s.client_ms.toFixed(2));
  set('uplink', formatBytes(s.uplink_bytes));
  set('downlink', formatBytes(s.downlink_bytes));
  set('mode', `${s.mode} / ${s.sensor}`);
}

function fitView() {
  view.distance = 1.5 * sceneExtent();
  const traj = snapshot ? flatToDisplay(snapshot.trajectory) : [];
  if (traj.length) {
    const mean = [0, 0, 0];
    for (const p of traj) for (let k = 0; k < 3; ++k) mean[k] += p[k] / traj.length;
    view.target = mean;
  }
  requestDraw();
}

function setConnection(ok, text) {
  const el = document.getElementById('connection');
  el.className = ok ? 'ok' : 'bad';
  el.textContent = text;
}

let events = null;
function connect() {
  events = new EventSource('api/events');
  events.onopen = () => setConnection(true, 'live');
  events.onmessage = (message) => {
    const first = snapshot === null;
    snapshot = JSON.parse(message.data);
    showStats(snapshot.status);
    if (snapshot.status.finished) setConnection(true, 'run finished');
    if (first) fitView();
    requestDraw();
  };
  events.onerror = () => {
    setConnection(false, 'disconnected - reconnecting\u2026');
    // The browser retries by itself unless it gave up (CLOSED): then start over.
    if (events.readyState === EventSource.CLOSED) {
      events.close();
      setTimeout(connect, 2000);
    }
  };
}

let drag = null;
canvas.addEventListener('mousedown', (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey }; });
window.addEventListener('mouseup', () => { drag = null; });
window.addEventListener('mousemove', (e) => {
  if (!drag) return;
  const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
  drag.x = e.clientX;
  drag.y = e.clientY;
  if (drag.pan) {
    const { right, up } = basis();
    const scale = view.distance / canvas.clientHeight;
    for (let k = 0; k < 3; ++k) view.target[k] += scale * (-dx * right[k] + dy * up[k]);
    setFollow(false);
  } else {
    view.yaw -= dx * 0.01;
    view.pitch = Math.max(-1.55, Math.min(1.55, view.pitch + dy * 0.01));
  }
  requestDraw();
});
canvas.addEventListener('wheel', (e) => {
  e.preventDefault();
  view.distance = Math.max(0.05, view.distance * Math.exp(e.deltaY * 0.001));
  requestDraw();
}, { passive: false });

function setFollow(on) {
  follow = on;
  document.getElementById('follow').checked = on;
}
document.getElementById('follow').addEventListener('change', (e) => { follow = e.target.checked; requestDraw(); });
document.getElementById('top-view').addEventListener('click', () => { view.pitch = 1.55; view.yaw = 0; requestDraw(); });
document.getElementById('fit').addEventListener('click', () => { setFollow(false); fitView(); });
window.addEventListener('resize', requestDraw);

connect();
requestDraw();
