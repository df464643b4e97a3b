// detslam viewer page: the newest frame with its keypoints and dynamic masks, the map in 3-D, the
// run's counters; live (update stream from a running `detslam run --viewer`) or a finished run
// (`detslam view RUN_DIR`, a frame slider). The page's own state is kept in #page-state (JSON)
// for tests and scripts.
'use strict';

const FATES = ['matched', 'unmatched', 'mask', 'depth', 'geometric'];
const FATE_COLOURS = {
  matched: '#2ecc40', unmatched: '#ffdc00', mask: '#ff4136', depth: '#f012be',
  geometric: '#ff851b'
};
const $ = (id) => document.getElementById(id);

const page = {
  mode: null, connected: false, finished: false, webgl: false, three_js: false,
  events: 0, frames_received: 0, frame_index: -1, images_drawn: 0, image_frame: -1,
  keypoints_drawn: 0, map_updates: 0, points_drawn: 0, keyframes_drawn: 0,
  trajectory_points: 0, ground_truth_points: 0, errors: [], counters: null
};
function publishState() { $('page-state').textContent = JSON.stringify(page); }
function noteError(e) {
  page.errors.push(String(e));
  if (page.errors.length > 20) page.errors.shift();
  publishState();
}

// ---------------------------------------------------------------- counters and buttons
function showCounters(c) {
  // A control request's reply can arrive after a newer update from the stream: keep the newest.
  if (page.counters && c.seq < page.counters.seq) return;
  page.counters = c;
  page.finished = c.finished;
  const tracked = c.frames_done > 0 ? (100 * c.tracked / c.frames_done).toFixed(1) : '0.0';
  const items = [
    ['frame', (c.frame >= 0 ? c.frame : '-') + ' / ' + c.total],
    ['fps', c.mode === 'live' ? c.fps.toFixed(1) : '-'], ['state', c.state || '-'],
    ['tracked', tracked + ' %'], ['keyframes', c.keyframes], ['map points', c.points],
    ['loops', c.loops], ['maps', c.maps + (c.merges ? ' (' + c.merges + ' merged)' : '')],
    ['relocalisations', c.relocalizations]
  ];
  $('counters').innerHTML = items.map(([k, v]) => k + ' <b>' + v + '</b>').join('');
  const live = c.mode === 'live' && !c.finished;
  $('pause').disabled = !(live && c.pausable && !c.paused);
  $('step').disabled = !(live && c.pausable);
  $('resume').disabled = !(live && c.pausable && c.paused);
  const status = $('status');
  if (c.mode === 'run') { status.textContent = 'finished run'; status.className = 'status done'; }
  else if (c.finished) { status.textContent = 'run finished'; status.className = 'status done'; }
  else if (c.paused) { status.textContent = 'paused'; status.className = 'status'; }
  else { status.textContent = 'live'; status.className = 'status live'; }
  publishState();
}

async function control(action) {
  try {
    const r = await fetch('/api/control', { method: 'POST', body: action });
    if (r.ok) showCounters(await r.json());
    else noteError('control ' + action + ': ' + (await r.json()).error);
  } catch (e) { noteError(e); }
}
$('pause').onclick = () => control('pause');
$('step').onclick = () => control('step');
$('resume').onclick = () => control('resume');

// ---------------------------------------------------------------- the frame panel
const frameCanvas = $('frame');
// A software canvas (willReadFrequently): without a GPU, Chromium's accelerated 2-D canvas goes through
// software WebGL, which costs several times more CPU for the image and a thousand keypoint circles.
const frameCtx = frameCanvas.getContext('2d', { willReadFrequently: true });
let pendingFrame = null;   // newest frame state not drawn yet
let imageLoading = false;
let latestPose = null;     // pose of the newest frame (camera in the 3-D view)

function frameText(f) {
  const parts = ['frame ' + f.index, 't ' + f.stamp.toFixed(3) + ' s', f.state];
  if (f.method) parts.push(f.method);
  if (f.skipped) parts.push('skipped: ' + f.skipped);
  if (f.keyframe) parts.push('keyframe');
  parts.push(f.inliers + ' inliers', f.dynamic_instances + ' dynamic objects');
  if (f.frame_ms) parts.push(f.frame_ms.toFixed(1) + ' ms');
  if (f.keypoints === null) parts.push('(keypoints are drawn in live runs only)');
  return parts.join(' \u00b7 ');
}

function drawKeypoints(f) {
  let drawn = 0;
  if (!f.keypoints) {
    for (const fate of FATES) $('n-' + fate).textContent = '-';
    return 0;
  }
  for (const fate of FATES) {
    const xy = f.keypoints[fate] || [];
    frameCtx.strokeStyle = FATE_COLOURS[fate];
    frameCtx.lineWidth = 1.5;
    frameCtx.beginPath();
    for (let i = 0; i + 1 < xy.length; i += 2) {
      frameCtx.moveTo(xy[i] + 3, xy[i + 1]);
      frameCtx.arc(xy[i], xy[i + 1], 3, 0, 2 * Math.PI);
    }
    frameCtx.stroke();
    $('n-' + fate).textContent = xy.length / 2;
    drawn += xy.length / 2;
  }
  return drawn;
}

function drawFrame(f, img) {
  const w = f.width || 640, h = f.height || 480;
  if (frameCanvas.width !== w || frameCanvas.height !== h) {
    frameCanvas.width = w; frameCanvas.height = h;
  }
  frameCtx.fillStyle = '#000';
  frameCtx.fillRect(0, 0, w, h);
  if (img) frameCtx.drawImage(img, 0, 0, w, h);
  page.keypoints_drawn = drawKeypoints(f);
  if (img) { page.images_drawn++; page.image_frame = f.index; }
  $('frame-info').textContent = frameText(f);
  publishState();
}

// Draws the newest pending frame; frames that arrive while an image loads are skipped.
function requestImage() {
  if (imageLoading || !pendingFrame) return;
  const f = pendingFrame;
  pendingFrame = null;
  if (!f.has_image) { drawFrame(f, null); return; }
  imageLoading = true;
  const img = new Image();
  img.onload = () => { imageLoading = false; drawFrame(f, img); requestImage(); };
  img.onerror = () => { imageLoading = false; drawFrame(f, null); requestImage(); };
  img.src = '/api/frame.jpg?index=' + f.index + '&seq=' + f.seq;
}

function onFrame(f) {
  page.frames_received++;
  page.frame_index = f.index;
  if (f.pose) { latestPose = f.pose; addLivePose(f.pose); }
  pendingFrame = f;
  requestImage();
}

// ---------------------------------------------------------------- the 3-D view
const view = { renderer: null, scene: null, camera: null, target: null, yaw: 0.6, pitch: 0.5,
               dist: 4, fitted: false, objects: {}, live: [] };

function initThree() {
  if (typeof THREE === 'undefined') {
    $('map-info').textContent = 'three.js is missing (Debian: apt-get install libjs-three): no 3-D view';
    return;
  }
  page.three_js = true;
  const canvas = $('map3d');
  try {
    // No antialiasing: points and lines do not need it, and without a GPU (software WebGL) it
    // multiplies the drawing cost, on the cores the run needs.
    view.renderer = new THREE.WebGLRenderer({ canvas: canvas, antialias: false,
                                              preserveDrawingBuffer: true });
  } catch (e) {
    $('map-info').textContent = 'WebGL is not available in this browser: no 3-D view';
    noteError(e);
    return;
  }
  page.webgl = true;
  view.scene = new THREE.Scene();
  view.camera = new THREE.PerspectiveCamera(60, 1, 0.01, 1000);
  view.camera.up.set(0, -1, 0);  // the SLAM frame's y points down (camera convention)
  view.target = new THREE.Vector3(0, 0, 1);
  resize3d();
  window.addEventListener('resize', resize3d);
  let drag = null;
  canvas.addEventListener('mousedown', (e) => { drag = { x: e.clientX, y: e.clientY, pan: e.shiftKey || e.button === 2 }; });
  window.addEventListener('mouseup', () => { drag = null; });
  canvas.addEventListener('contextmenu', (e) => e.preventDefault());
  window.addEventListener('mousemove', (e) => {
    if (!drag) return;
    const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
    drag.x = e.clientX; drag.y = e.clientY;
    if (drag.pan) {
      const right = new THREE.Vector3(), up = new THREE.Vector3();
      view.camera.matrix.extractBasis(right, up, new THREE.Vector3());
      const s = view.dist * 0.002;
      view.target.addScaledVector(right, -dx * s).addScaledVector(up, dy * s);
    } else {
      view.yaw -= dx * 0.01;
      view.pitch = Math.max(-1.5, Math.min(1.5, view.pitch + dy * 0.01));
    }
    render3d();
  });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    view.dist *= Math.exp(e.deltaY * 0.001);
    render3d();
  }, { passive: false });
}

function resize3d() {
  if (!view.renderer) return;
  const canvas = $('map3d');
  const w = canvas.clientWidth || 640, h = canvas.clientHeight || 480;
  view.renderer.setSize(w, h, false);
  view.camera.aspect = w / h;
  view.camera.updateProjectionMatrix();
  render3d();
}

// Redraws on the next animation frame; a redraw for a live update (the camera moved on) waits
// until kLiveRedrawMs after the last one, so the 3-D view costs the same at any frame rate.
const kLiveRedrawMs = 200;
let renderQueued = false, lastRender = 0, liveTimer = null;
function render3d(live) {
  if (!view.renderer || renderQueued) return;
  const wait = lastRender + kLiveRedrawMs - performance.now();
  if (live && wait > 0) {
    if (!liveTimer) liveTimer = setTimeout(() => { liveTimer = null; render3d(); }, wait);
    return;
  }
  renderQueued = true;
  requestAnimationFrame(() => {
    renderQueued = false;
    lastRender = performance.now();
    const c = Math.cos(view.pitch);
    // Orbit around the target; "up" is -y, so the eye sits at negative y above the scene.
    view.camera.position.set(view.target.x + view.dist * c * Math.sin(view.yaw),
                             view.target.y - view.dist * Math.sin(view.pitch),
                             view.target.z - view.dist * c * Math.cos(view.yaw));
    view.camera.lookAt(view.target);
    view.renderer.render(view.scene, view.camera);
  });
}

function replace(name, object) {
  if (view.objects[name]) {
    view.scene.remove(view.objects[name]);
    view.objects[name].geometry.dispose();
  }
  view.objects[name] = object;
  if (object) view.scene.add(object);
}

// A path as a line with a dot at every pose (WebGL lines are one pixel wide).
function lineOf(flat, colour) {
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(flat), 3));
  const line = new THREE.Line(g, new THREE.LineBasicMaterial({ color: colour }));
  line.add(new THREE.Points(g, new THREE.PointsMaterial({ color: colour, size: 3, sizeAttenuation: false })));
  return line;
}

// Camera frustums (wire pyramids) of 3x4 world_from_cam poses, `size` metres deep.
function frustums(poses, colour, size) {
  const corners = [[0, 0, 0], [-0.6, -0.45, 1], [0.6, -0.45, 1], [0.6, 0.45, 1], [-0.6, 0.45, 1]];
  const edges = [[0, 1], [0, 2], [0, 3], [0, 4], [1, 2], [2, 3], [3, 4], [4, 1]];
  const out = [];
  for (const m of poses) {
    const w = corners.map(([x, y, z]) => [x * size, y * size, z * size]).map(([x, y, z]) => [
      m[0] * x + m[1] * y + m[2] * z + m[3], m[4] * x + m[5] * y + m[6] * z + m[7],
      m[8] * x + m[9] * y + m[10] * z + m[11]]);
    for (const [a, b] of edges) out.push(...w[a], ...w[b]);
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(new Float32Array(out), 3));
  return new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: colour }));
}

function addLivePose(pose) {
  view.live.push(pose[3], pose[7], pose[11]);
  if (!view.scene) return;
  replace('live', lineOf(view.live, 0x2ecc40));
  replace('camera', frustums([pose], 0xff3030, 0.15));
  render3d(/*live=*/true);
}

// Frames the map points (5-95 % on each axis, so stray points do not count) and the whole
// trajectory, from far enough to see them all.
function fitView(points, trajectory) {
  if (view.fitted || points.length + trajectory.length < 3) return;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let k = 0; k < 3; k++) {
    const v = [];
    for (let i = k; i < points.length; i += 3) v.push(points[i]);
    v.sort((a, b) => a - b);
    if (v.length) {
      lo[k] = v[Math.floor(0.05 * (v.length - 1))];
      hi[k] = v[Math.ceil(0.95 * (v.length - 1))];
    }
    for (let i = k; i < trajectory.length; i += 3) {
      lo[k] = Math.min(lo[k], trajectory[i]);
      hi[k] = Math.max(hi[k], trajectory[i]);
    }
  }
  view.target.set((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
  view.dist = Math.max(1.5, 1.2 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]));
  view.fitted = true;
}

let mapLoading = false, mapDirty = false;
async function fetchMap() {
  if (mapLoading) { mapDirty = true; return; }
  mapLoading = true;
  try {
    const [m, buffer] = await Promise.all([
      fetch('/api/map').then((r) => r.json()),
      fetch('/api/map_points').then((r) => r.arrayBuffer())]);
    const pts = new Float32Array(buffer);
    page.map_updates++;
    page.points_drawn = pts.length / 3;
    page.keyframes_drawn = m.keyframes.length;
    page.trajectory_points = m.trajectory.length / 3;
    page.ground_truth_points = m.ground_truth.length / 3;
    if (view.scene) {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(pts, 3));
      replace('points', new THREE.Points(g, new THREE.PointsMaterial(
        { color: 0xd0d0d0, size: 2, sizeAttenuation: false })));
      replace('keyframes', frustums(m.keyframes, 0x4aa3ff, 0.08));
      replace('trajectory', lineOf(m.trajectory, 0x2ecc40));
      replace('ground_truth', m.ground_truth.length ? lineOf(m.ground_truth, 0xff9900) : null);
      view.live = [];  // the trajectory above holds them, with their final poses
      replace('live', null);
      if (latestPose) replace('camera', frustums([latestPose], 0xff3030, 0.15));
      fitView(pts, m.trajectory);
      render3d();
    }
    $('map-info').textContent = 'map ' + m.map_id + ': ' + page.points_drawn + ' points, ' +
      m.keyframes.length + ' keyframes' + (m.ground_truth.length ? ', ground truth aligned (TUM ATE alignment)' : '') +
      ' \u00b7 drag: rotate, shift+drag: pan, wheel: zoom';
  } catch (e) { noteError(e); }
  mapLoading = false;
  publishState();
  if (mapDirty) { mapDirty = false; fetchMap(); }
}

// ---------------------------------------------------------------- live run: the update stream
function connectLive() {
  const source = new EventSource('/api/events');
  source.onopen = () => { page.connected = true; publishState(); };
  source.onerror = () => {
    page.connected = false;
    const status = $('status');
    if (page.finished) { status.textContent = 'run finished; viewer closed'; status.className = 'status done'; }
    else { status.textContent = 'disconnected'; status.className = 'status off'; }
    for (const id of ['pause', 'step', 'resume']) $(id).disabled = true;
    publishState();
  };
  source.addEventListener('counters', (e) => { page.events++; showCounters(JSON.parse(e.data)); });
  source.addEventListener('frame', (e) => { page.events++; onFrame(JSON.parse(e.data)); });
  source.addEventListener('map', () => { page.events++; fetchMap(); });
}

// ---------------------------------------------------------------- finished run: a frame slider
async function browseFrame(index) {
  $('slider-label').textContent = 'frame ' + index;
  try {
    const r = await fetch('/api/frame?index=' + index);
    if (!r.ok) { $('frame-info').textContent = 'frame ' + index + ': ' + (await r.json()).error; return; }
    const f = await r.json();
    page.frame_index = f.index;
    latestPose = f.pose;
    if (view.scene) { replace('camera', f.pose ? frustums([f.pose], 0xff3030, 0.15) : null); render3d(); }
    pendingFrame = f;
    requestImage();
  } catch (e) { noteError(e); }
}

function startRun(c) {
  $('frame-browser').hidden = false;
  const slider = $('slider');
  slider.max = Math.max(0, c.total - 1);
  let timer = null;
  slider.oninput = () => { clearTimeout(timer); timer = setTimeout(() => browseFrame(+slider.value), 60); };
  fetchMap();
  browseFrame(0);
}

async function main() {
  initThree();
  try {
    const info = await (await fetch('/api/info')).json();
    $('title').textContent = info.title;
    document.title = 'detslam viewer: ' + info.title;
    const c = await (await fetch('/api/counters')).json();
    page.mode = c.mode;
    showCounters(c);
    if (c.mode === 'live') connectLive(); else startRun(c);
  } catch (e) { noteError(e); }
  publishState();
}
main();
