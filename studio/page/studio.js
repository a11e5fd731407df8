// rigc studio's page: the live view, the camera and studio panels, capture, coverage and advice.
// Every change goes to the server as an edit of the scene; the server compiles it and refuses
// what the compiler refuses (the message is shown in the status line).
'use strict';

const token = new URLSearchParams(location.search).get('token') || '';
const $ = (id) => document.getElementById(id);
const FULL_WIDTH = 1280;   // the live view at rest
const MOVING_WIDTH = 480;  // while a slider or the camera moves

// Timings for bench/studio_bench.py (Performance API), and the last frame's statistics.
window.rigcBench = { slider: [], capture: [], captureParts: [], dragFrames: [] };
window.rigcFrame = { mean: 0, clipped: 0, width: 0, count: 0 };

const APERTURES = [1.2, 1.4, 1.6, 1.8, 2, 2.2, 2.5, 2.8, 3.2, 3.5, 4, 4.5, 5, 5.6, 6.3, 7.1, 8, 9,
  10, 11, 13, 14, 16, 18, 20, 22, 25, 29, 32, 36, 40, 45, 51, 57, 64];
const SHUTTERS = [30, 25, 20, 15, 13, 10, 8, 6, 5, 4, 3.2, 2.5, 2, 1.6, 1.3, 1, 0.8, 0.6, 0.5, 0.4,
  0.3, 1 / 4, 1 / 5, 1 / 6, 1 / 8, 1 / 10, 1 / 13, 1 / 15, 1 / 20, 1 / 25, 1 / 30, 1 / 40, 1 / 50,
  1 / 60, 1 / 80, 1 / 100, 1 / 125, 1 / 160, 1 / 200, 1 / 250, 1 / 320, 1 / 400, 1 / 500, 1 / 640,
  1 / 800, 1 / 1000, 1 / 1250, 1 / 1600, 1 / 2000, 1 / 2500, 1 / 3200, 1 / 4000, 1 / 5000,
  1 / 6400, 1 / 8000];
const ISOS = [50, 64, 80, 100, 125, 160, 200, 250, 320, 400, 500, 640, 800, 1000, 1250, 1600, 2000,
  2500, 3200, 4000, 5000, 6400, 12800, 25600];

let state = null;
let orbit = { azimuth: 0, elevation: 0, distance: 1, target: [0, 0, 1] };
let turntableDeg = 0;

function api(path, options = {}) {
  const headers = Object.assign({ 'X-Rigc-Token': token }, options.headers || {});
  return fetch(path, Object.assign({}, options, { headers }));
}

async function post(path, body) {
  const res = await api(path, { method: 'POST', body: JSON.stringify(body || {}),
    headers: { 'Content-Type': 'application/json' } });
  const reply = await res.json();
  if (!res.ok) showStatus(reply.error, true);
  return res.ok;
}

function showStatus(text, isError) {
  const status = $('status');
  status.textContent = text || '';
  status.className = isError ? 'error' : '';
}

function shutterText(s) { return s >= 0.3 ? `${s}s` : `1/${Math.round(1 / s)}`; }
function nearestIndex(list, value) {
  let best = 0;
  list.forEach((v, i) => { if (Math.abs(Math.log(v / value)) < Math.abs(Math.log(list[best] / value))) best = i; });
  return best;
}

// ---- the live view: one frame request in flight at a time, the latest wish wins ----
const frames = { busy: false, wanted: null };

function requestFrame(width, onShown) {
  frames.wanted = { width, onShown };
  if (!frames.busy) pumpFrames();
}

async function pumpFrames() {
  frames.busy = true;
  while (frames.wanted) {
    const wish = frames.wanted;
    frames.wanted = null;
    try {
      await showFrame(wish.width);
      if (wish.onShown) wish.onShown();
    } catch (e) {
      showStatus(String(e), true);
    }
  }
  frames.busy = false;
}

async function showFrame(width) {
  // The frames while something moves are drafts (the surface point-sampled).
  const res = await api(`api/frame?width=${width}&draft=${width === MOVING_WIDTH ? 1 : 0}`);
  if (!res.ok) { showStatus((await res.json()).error, true); return; }
  const bins = res.headers.get('X-Rigc-Histogram').split(',').map(Number);
  const clipped = Number(res.headers.get('X-Rigc-Clipped'));
  const bitmap = await createImageBitmap(await res.blob());
  const canvas = $('view');
  if (canvas.width !== bitmap.width || canvas.height !== bitmap.height) {
    canvas.width = bitmap.width;
    canvas.height = bitmap.height;
  }
  canvas.getContext('2d').drawImage(bitmap, 0, 0);
  window.rigcFrame = { mean: Number(res.headers.get('X-Rigc-Mean')), clipped, width: bitmap.width,
    count: window.rigcFrame.count + 1 };
  drawHistogram(bins, clipped);
}

function drawHistogram(bins, clipped) {
  const canvas = $('histogram');
  const g = canvas.getContext('2d');
  const n = 64, w = canvas.width, h = canvas.height;
  g.fillStyle = '#111';
  g.fillRect(0, 0, w, h);
  const luma = bins.slice(3 * n, 4 * n);
  const peak = Math.max(1, ...bins);
  const bar = w / n;
  g.fillStyle = '#bbb';
  luma.forEach((c, i) => { const bh = h * Math.sqrt(c / peak); g.fillRect(i * bar, h - bh, bar, bh); });
  ['#f44', '#4f4', '#48f'].forEach((color, ch) => {
    g.strokeStyle = color;
    g.beginPath();
    bins.slice(ch * n, (ch + 1) * n).forEach((c, i) => {
      const y = h - h * Math.sqrt(c / peak);
      if (i === 0) g.moveTo(0, y); else g.lineTo((i + 0.5) * bar, y);
    });
    g.stroke();
  });
  // Clipping marks: highlights at 255 on the right, crushed shadows on the left.
  const total = luma.reduce((a, b) => a + b, 0) || 1;
  if (clipped > 0.001) { g.fillStyle = '#f00'; g.fillRect(w - 4, 0, 4, h); }
  if (luma[0] / total > 0.01) { g.fillStyle = '#06f'; g.fillRect(0, 0, 4, h); }
  const c = state ? state.camera : null;
  $('exposure-readout').innerHTML = c ? `EV<sub>100</sub> ${c.ev100.toFixed(2)} &middot; ` +
    `f/${c.aperture} &middot; ${shutterText(c.shutter_s)} &middot; ISO ${c.iso} &middot; ` +
    `${c.focal_length_mm.toFixed(0)} mm &middot; clipped ${(100 * clipped).toFixed(2)} %` : '';
}

// ---- state and panels ----
async function refreshState() {
  const res = await api('api/state');
  if (!res.ok) return;
  const previous = state;
  state = await res.json();
  const error = $('file-error');
  error.hidden = !state.file_error;
  error.textContent = state.file_error;
  $('file').textContent = state.file;
  $('unsaved').textContent = state.unsaved ? '(unsaved changes)' : '';
  $('undo').disabled = !state.can_undo;
  if (!previous || previous.revision !== state.revision) {
    fillPanels();
    return true;
  }
  return false;
}

function fillPanels() {
  const c = state.camera;
  const body = $('body');
  if (body.options.length !== state.bodies.length + 1) {
    body.innerHTML = '';
    [...state.bodies, 'custom'].forEach((name) => body.add(new Option(name, name)));
  }
  body.value = c.body;
  const lens = $('lens');
  if (lens.options.length !== state.lenses.length + 1) {
    lens.innerHTML = '';
    lens.add(new Option('focal length only', ''));
    state.lenses.forEach((l) => lens.add(new Option(l.name, l.name)));
  }
  lens.value = state.lens;
  setSlider('aperture', APERTURES.length - 1, nearestIndex(APERTURES, c.aperture), `f/${c.aperture}`);
  setSlider('shutter', SHUTTERS.length - 1, nearestIndex(SHUTTERS, c.shutter_s), shutterText(c.shutter_s));
  setSlider('iso', ISOS.length - 1, nearestIndex(ISOS, c.iso), `${c.iso}`);
  setValue('focal', c.focal_length_mm, `${c.focal_length_mm.toFixed(0)} mm`);
  $('focus-auto').checked = state.focus_auto;
  $('focus').disabled = state.focus_auto;
  setValue('focus', state.view.focus_distance_m, `${state.view.focus_distance_m.toFixed(2)} m`);
  $('wb-auto').checked = c.white_balance_auto;
  $('wb').disabled = c.white_balance_auto;
  setValue('wb', c.white_balance_k, `${c.white_balance_k.toFixed(0)} K`);
  const s = state.studio;
  $('green-screen').checked = s.green_screen;
  setValue('table', s.turntable_diameter_m, `${(100 * s.turntable_diameter_m).toFixed(0)} cm`);
  fillLights(s.lights);
  fillView();
}

function setSlider(id, max, index, text) {
  const input = $(id);
  input.min = 0; input.max = max; input.step = 1;
  if (document.activeElement !== input) input.value = index;
  $(`${id}-out`).textContent = text;
}

function setValue(id, value, text) {
  if (document.activeElement !== $(id)) $(id).value = value;
  $(`${id}-out`).textContent = text;
}

function fillView() {
  const v = state.view;
  const d = v.position.map((p, i) => p - v.look_at[i]);
  orbit.distance = Math.hypot(...d);
  orbit.azimuth = Math.atan2(d[1], d[0]);
  orbit.elevation = Math.asin(d[2] / orbit.distance);
  orbit.target = v.look_at.slice();
  turntableDeg = v.turntable_deg;
  setValue('turntable', turntableDeg, `${turntableDeg.toFixed(0)}°`);
  setValue('distance', orbit.distance, `${orbit.distance.toFixed(2)} m`);
  $('pose-readout').textContent = 'camera at [' + v.position.map((p) => p.toFixed(2)).join(', ') +
    '] m, aimed at [' + v.look_at.map((p) => p.toFixed(2)).join(', ') + '] m';
}

function fillLights(lights) {
  const box = $('lights');
  if (box.contains(document.activeElement)) return;
  box.innerHTML = '';
  lights.forEach((light, i) => {
    const row = document.createElement('div');
    row.className = 'light';
    const area = light.type === 'area';
    row.innerHTML = `<b>${i + 1}. ${light.type}</b> <small>line ${light.line}</small>
      <button data-remove="${i}">remove</button><br>
      position <input data-key="position" data-i="${i}" value="${light.position.map((p) => p.toFixed(2)).join(', ')}" size="14"> m<br>
      ${light.type === 'directional' ? '' : `power <input data-key="power" data-i="${i}" type="number" min="0" step="5" value="${light.power_w}"> W`}
      temperature <input data-key="temperature" data-i="${i}" type="number" min="1000" step="100" value="${light.temperature_k}"> K
      ${area ? `<br>size <input data-key="size" data-i="${i}" type="number" step="1" value="${(100 * light.size_m[0]).toFixed(0)}"> cm` : ''}`;
    box.appendChild(row);
  });
}

// A scene value changed: edit, then a small frame while moving and the full one on release.
async function setScene(path, value, released) {
  const started = performance.now();
  if (!(await post('api/set', { path, value }))) { await refreshState(); return; }
  showStatus('');
  // The frame and the panels' state at once.
  requestFrame(released ? FULL_WIDTH : MOVING_WIDTH, () => {
    if (released) window.rigcBench.slider.push(performance.now() - started);
  });
  await refreshState();
  if (released) scheduleAnalysis();
}

// A lens preset with a focal length it takes: a prime's own, the current one kept in a zoom's
// range. ("focal length only" marks a scene without a preset; taking one out is an edit of the
// file.)
async function setLens(name) {
  const lens = state.lenses.find((l) => l.name === name);
  if (!lens) { await refreshState(); return; }
  const [shortest, longest] = lens.focal_mm;
  const focal = Math.round(Math.min(longest, Math.max(shortest, state.camera.focal_length_mm)));
  const changes = [{ path: 'camera.lens.preset', value: name },
    { path: 'camera.lens.focal_length', value: `${focal}mm` }];
  if (await post('api/set', { changes })) changed(); else await refreshState();
}

function bindSlider(id, list, path, format) {
  const input = $(id);
  const send = (released) => {
    const value = list[Number(input.value)];
    $(`${id}-out`).textContent = format(value);
    setScene(path, format(value).replace(/^f\//, 'f/'), released);
  };
  input.addEventListener('input', () => send(false));
  input.addEventListener('change', () => send(true));
}

function bindRange(id, path, format) {
  const input = $(id);
  input.addEventListener('input', () => setScene(path, format(Number(input.value)), false));
  input.addEventListener('change', () => setScene(path, format(Number(input.value)), true));
}

function bindPanels() {
  bindSlider('aperture', APERTURES, 'camera.exposure.aperture', (v) => `f/${v}`);
  bindSlider('shutter', SHUTTERS, 'camera.exposure.shutter', shutterText);
  bindSlider('iso', ISOS, 'camera.exposure.iso', (v) => `${v}`);
  bindRange('focal', 'camera.lens.focal_length', (v) => `${v}mm`);
  bindRange('focus', 'camera.focus', (v) => `${v.toFixed(2)}m`);
  bindRange('wb', 'camera.white_balance', (v) => `${v}K`);
  bindRange('table', 'studio.turntable.diameter', (v) => `${Math.round(100 * v)}cm`);
  $('body').addEventListener('change', () => setScene('camera.body', $('body').value, true));
  $('lens').addEventListener('change', () => setLens($('lens').value));
  $('focus-auto').addEventListener('change', () => setScene('camera.focus',
    $('focus-auto').checked ? 'auto' : `${state.view.focus_distance_m.toFixed(2)}m`, true));
  $('wb-auto').addEventListener('change', () => setScene('camera.white_balance',
    $('wb-auto').checked ? 'auto' : `${state.camera.white_balance_k.toFixed(0)}K`, true));
  $('green-screen').addEventListener('change', () => setScene('studio.backdrop.green_screen',
    $('green-screen').checked ? 'true' : 'false', true));
  $('turntable').addEventListener('input', () => moveView(false));
  $('turntable').addEventListener('change', () => moveView(true));
  $('distance').addEventListener('input', () => { orbit.distance = Number($('distance').value); moveView(false); });
  $('distance').addEventListener('change', () => moveView(true));
  $('lights').addEventListener('change', (e) => {
    const key = e.target.dataset.key;
    if (!key) return;
    const v = e.target.value.trim();
    const text = { position: `[${v.split(',').map((p) => `${Number(p)}m`).join(', ')}]`,
      power: `${v}W`, temperature: `${v}K`, size: `[${v}cm, ${v}cm]` }[key];
    setScene(`studio.lights.${e.target.dataset.i}.${key}`, text, true);
  });
  $('lights').addEventListener('click', async (e) => {
    if (e.target.dataset.remove === undefined) return;
    if (await post('api/lights/remove', { index: Number(e.target.dataset.remove) })) changed();
  });
  $('add-light').addEventListener('click', async () => {
    const p = state.view.position;
    const light = { type: 'point', position: `[${p[0].toFixed(2)}m, ${p[1].toFixed(2)}m, ${(p[2] + 0.5).toFixed(2)}m]`,
      power: '100W' };
    if (await post('api/lights/add', light)) changed();
  });
  $('capture').addEventListener('click', capture);
  $('suggest').addEventListener('click', suggest);
  $('undo').addEventListener('click', async () => { if (await post('api/undo')) changed(); });
  $('save').addEventListener('click', async () => {
    if (await post('api/save')) { showStatus('saved'); await refreshState(); }
  });
}

async function changed() {
  showStatus('');
  await refreshState();
  requestFrame(FULL_WIDTH);
  scheduleAnalysis();
}

// ---- moving the camera ----
function viewPose() {
  const { azimuth: a, elevation: e, distance: d, target: t } = orbit;
  const position = [t[0] + d * Math.cos(e) * Math.cos(a), t[1] + d * Math.cos(e) * Math.sin(a),
    t[2] + d * Math.sin(e)];
  return { position, look_at: t, turntable_deg: Number($('turntable').value) };
}

let viewBusy = false, viewPending = null;
async function moveView(released) {
  viewPending = released;
  if (viewBusy) return;
  viewBusy = true;
  while (viewPending !== null) {
    const fullFrame = viewPending;
    viewPending = null;
    const started = performance.now();
    if (await post('api/view', viewPose())) {
      showStatus('');
      await showFrame(fullFrame ? FULL_WIDTH : MOVING_WIDTH);
      window.rigcBench.dragFrames.push({ at: performance.now(), ms: performance.now() - started });
    }
  }
  viewBusy = false;
  await refreshState();
  fillView();
}

function bindMovement() {
  const canvas = $('view');
  let dragging = null;
  canvas.addEventListener('pointerdown', (e) => { dragging = { x: e.clientX, y: e.clientY }; canvas.setPointerCapture(e.pointerId); });
  canvas.addEventListener('pointermove', (e) => {
    if (!dragging) return;
    orbit.azimuth -= 0.006 * (e.clientX - dragging.x);
    orbit.elevation = Math.max(-1.5, Math.min(1.5, orbit.elevation + 0.006 * (e.clientY - dragging.y)));
    dragging = { x: e.clientX, y: e.clientY };
    moveView(false);
  });
  canvas.addEventListener('pointerup', () => { if (dragging) { dragging = null; moveView(true); } });
  canvas.addEventListener('wheel', (e) => {
    e.preventDefault();
    orbit.distance *= e.deltaY > 0 ? 1.05 : 1 / 1.05;
    moveView(true);
  }, { passive: false });
  document.addEventListener('keydown', (e) => {
    if (e.target.tagName === 'INPUT' || e.target.tagName === 'SELECT') return;
    if (e.code === 'Space') { e.preventDefault(); capture(); return; }
    const step = 0.05;
    const forward = [-Math.cos(orbit.azimuth), -Math.sin(orbit.azimuth)];
    const right = [-forward[1], forward[0]];
    const moves = { KeyW: [forward, step], ArrowUp: [forward, step], KeyS: [forward, -step],
      ArrowDown: [forward, -step], KeyD: [right, -step], ArrowRight: [right, -step],
      KeyA: [right, step], ArrowLeft: [right, step] };
    if (moves[e.code]) {
      const [dir, s] = moves[e.code];
      // Walking moves the camera and its aim together, as a first-person camera does.
      orbit.target = [orbit.target[0] + s * dir[0], orbit.target[1] + s * dir[1], orbit.target[2]];
    } else if (e.code === 'KeyQ' || e.code === 'KeyE') {
      orbit.target = [orbit.target[0], orbit.target[1], orbit.target[2] + (e.code === 'KeyE' ? step : -step)];
    } else {
      return;
    }
    e.preventDefault();
    moveView(true);
  });
}

// ---- capture and the coverage view ----
async function capture() {
  const started = performance.now();
  if (!(await post('api/capture'))) return;
  const posted = performance.now();
  showStatus(`captured shot ${state ? state.shots + 1 : ''}`);
  const parts = await refreshCoverage(true);
  window.rigcBench.capture.push(performance.now() - started);
  window.rigcBench.captureParts.push(Object.assign({ capture: posted - started }, parts));
  await refreshState();
  scheduleAnalysis();
}

// The planner's next shot becomes the current view; capture takes it.
async function suggest() {
  showStatus('planning the next shot ...');
  const res = await api('api/suggest', { method: 'POST', body: '{}',
    headers: { 'Content-Type': 'application/json' } });
  const reply = await res.json();
  if (!res.ok) { showStatus(reply.error, true); return; }
  await changed();
  showStatus(`suggested: adds ${(100 * reply.gain).toFixed(1)} %, ` +
    `${(100 * reply.reconstructable).toFixed(1)} % reconstructable with it; press Capture to take it`);
}

const coverageView = {};

async function setUpCoverageView() {
  const box = $('coverage-view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setSize(box.clientWidth, box.clientHeight);
  renderer.setClearColor(0x30343a);
  box.appendChild(renderer.domElement);
  renderer.domElement.id = 'coverage-canvas';
  const scene = new THREE.Scene();
  const camera = new THREE.PerspectiveCamera(35, box.clientWidth / box.clientHeight, 0.01, 100);
  camera.up.set(0, 0, 1);
  scene.add(new THREE.AmbientLight(0xffffff, 0.55));
  const sun = new THREE.DirectionalLight(0xffffff, 0.6);
  sun.position.set(1, -2, 3);
  scene.add(sun);
  const mesh = await (await api('api/mesh')).json();
  const geometry = new THREE.BufferGeometry();
  const tris = mesh.triangles, pos = mesh.positions;
  const positions = new Float32Array(tris.length * 3);
  for (let i = 0; i < tris.length; ++i) positions.set(pos.slice(3 * tris[i], 3 * tris[i] + 3), 3 * i);
  geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(tris.length * 3).fill(1), 3));
  geometry.computeVertexNormals();
  geometry.computeBoundingSphere();
  const material = new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors || true });
  scene.add(new THREE.Mesh(geometry, material));
  const s = geometry.boundingSphere;
  camera.position.set(s.center.x, s.center.y - 3.2 * s.radius, s.center.z + 1.2 * s.radius);
  const controls = new THREE.OrbitControls(camera, renderer.domElement);
  controls.target.copy(s.center);
  controls.update();
  const render = () => renderer.render(scene, camera);
  controls.addEventListener('change', render);
  Object.assign(coverageView, { geometry, render, faces: tris.length / 3 });
  render();
}

const PAPER = [[1, 1, 1], [0.85, 0.05, 0.05], [0.05, 0.7, 0.1]];

async function refreshCoverage(afterCapture) {
  const started = performance.now();
  const res = await api(afterCapture ? 'api/coverage?capture=1' : 'api/coverage');
  if (!res.ok) return {};  // the scene changed meanwhile: the next change asks again
  const coverage = await res.json();
  const fetched = performance.now();
  $('coverage-summary').textContent = `${coverage.shots} shots: ` +
    `${(100 * coverage.reconstructable).toFixed(1)} % reconstructable, ` +
    `${(100 * coverage.seen_2).toFixed(1)} % seen twice; last shot new ${(100 * coverage.new).toFixed(1)} %, ` +
    `overlap ${(100 * coverage.overlap).toFixed(0)} %`;
  const table = $('coverage-table');
  table.textContent = coverage.table;
  table.scrollTop = table.scrollHeight;  // the latest shots
  window.rigcCoverage = coverage;
  if (!coverageView.geometry) return {};
  // The 3D view is drawn again only when a face changed colour (a software WebGL takes a core
  // for a while to draw it).
  const drawn = coverageView.views;
  const same = drawn && drawn.length === coverage.views.length &&
    coverage.views.every((views, f) => Math.min(2, views) === Math.min(2, drawn[f]));
  if (!same) {
    const colors = coverageView.geometry.attributes.color;
    coverage.views.forEach((views, f) => {
      const c = PAPER[Math.min(2, views)];
      for (let k = 0; k < 3; ++k) colors.setXYZ(3 * f + k, c[0], c[1], c[2]);
    });
    colors.needsUpdate = true;
    coverageView.views = coverage.views;
    coverageView.render();
  }
  return { coverage: fetched - started, wait: coverage.wait_ms, analysis: coverage.analysis_ms,
    json: coverage.json_ms,
    draw: performance.now() - fetched };
}

// ---- advice, a moment after the last change ----
let adviceTimer = null;
function scheduleAnalysis() {
  clearTimeout(adviceTimer);
  adviceTimer = setTimeout(async () => {
    const res = await api('api/advice');
    if (!res.ok) return;
    const advice = await res.json();
    const list = $('advice');
    list.innerHTML = '';
    if (advice.length === 0) list.innerHTML = '<li class="ok">no warnings</li>';
    advice.forEach((d) => {
      const item = document.createElement('li');
      item.className = d.severity;
      item.innerHTML = `<b>line ${d.line}:${d.col}</b> `;
      item.appendChild(document.createTextNode(d.message));
      item.title = d.rendered;
      list.appendChild(item);
    });
    refreshCoverage();
  }, 400);
}

// ---- the reference check: the view by POV-Ray or Cycles beside the preview's frame ----
const reference = { timer: null, flicker: null };

async function startReference() {
  const body = { backend: $('reference-backend').value, width: Number($('reference-width').value) };
  showReferenceStatus(`starting ${body.backend} ...`);
  const res = await api('api/reference', { method: 'POST', body: JSON.stringify(body),
    headers: { 'Content-Type': 'application/json' } });
  if (!res.ok) { showReferenceStatus((await res.json()).error, true); return; }
  $('reference-cancel').disabled = false;
  $('reference-start').disabled = true;
  clearInterval(reference.timer);
  reference.timer = setInterval(pollReference, 500);
}

function showReferenceStatus(text, isError) {
  const status = $('reference-status');
  status.textContent = text;
  status.className = isError ? 'error' : '';
}

async function pollReference() {
  const res = await api('api/reference');
  if (!res.ok) return;
  const s = await res.json();
  window.rigcReference = s;
  if (s.state === 'running') {
    const share = s.progress === null ? '' : ` ${(100 * s.progress).toFixed(0)} %,`;
    showReferenceStatus(`rendering with ${s.backend}:${share} ${s.elapsed_s.toFixed(0)} s`);
    return;
  }
  clearInterval(reference.timer);
  $('reference-cancel').disabled = true;
  $('reference-start').disabled = false;
  if (s.state === 'done') {
    showReferenceStatus(`${s.backend}, ${s.width} x ${s.height}, ${s.elapsed_s.toFixed(1)} s`);
    const stamp = Date.now();
    $('reference-preview').src = `api/reference/image?which=preview&token=${token}&t=${stamp}`;
    $('reference-image').src = `api/reference/image?which=reference&token=${token}&t=${stamp}`;
    $('reference-panel').hidden = false;
  } else if (s.state === 'failed') {
    showReferenceStatus(`${s.backend} failed: ${s.message} (log: ${s.log})`, true);
  } else if (s.state === 'cancelled') {
    showReferenceStatus(`${s.backend}: cancelled`);
  }
}

// Side by side, or one place showing the preview and the reference in turn.
function setFlicker(on) {
  clearInterval(reference.flicker);
  $('reference-panel').classList.toggle('flicker', on);
  const images = [$('reference-preview'), $('reference-image')];
  images.forEach((img) => { img.hidden = false; });
  $('reference-shown').textContent = '';
  if (!on) return;
  let k = 0;
  const show = () => {
    images.forEach((img, i) => { img.hidden = i !== k; });
    $('reference-shown').textContent = k === 0 ? 'preview' : 'reference';
    k = 1 - k;
  };
  show();
  reference.flicker = setInterval(show, 600);
}

function bindReference() {
  $('reference-start').addEventListener('click', startReference);
  $('reference-cancel').addEventListener('click', async () => {
    await api('api/reference/cancel', { method: 'POST', body: '{}',
      headers: { 'Content-Type': 'application/json' } });
    pollReference();
  });
  $('reference-flicker').addEventListener('change', () => setFlicker($('reference-flicker').checked));
  $('reference-close').addEventListener('click', () => {
    setFlicker(false);
    $('reference-flicker').checked = false;
    $('reference-panel').hidden = true;
  });
}

async function start() {
  bindPanels();
  bindReference();
  bindMovement();
  await refreshState();
  requestFrame(FULL_WIDTH);
  try { await setUpCoverageView(); } catch (e) { showStatus(`coverage view: ${e}`, true); }
  await refreshCoverage();
  scheduleAnalysis();
  // The file may change in an editor: the server reloads it when asked for the state. (The
  // page's own changes already asked for their frame and analyses.)
  setInterval(async () => {
    const reloads = state && state.reloads;
    await refreshState();
    if (state && state.reloads !== reloads) { requestFrame(FULL_WIDTH); scheduleAnalysis(); }
  }, 1000);
}

start();
