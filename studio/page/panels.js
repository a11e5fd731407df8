// The camera and studio panels: filled from /api/state, and every change sent as an edit of the
// scene (the server compiles it and refuses what the compiler refuses).
import { $, api, fromTemplate, post, showStatus } from 'studio/api.js';
import { capture, scheduleAnalysis, suggest } from 'studio/coverage.js';
import { nearestIndex, shutterText } from 'studio/format.js';
import { requestFrame } from 'studio/live_view.js';
import { moveView } from 'studio/movement.js';
import { FULL_WIDTH, MOVING_WIDTH, page } from 'studio/state.js';

// Asks for the state; true when the scene changed (then the panels are filled again).
export async function refreshState() {
  const res = await api('api/state');
  if (!res.ok) return false;
  const previous = page.state;
  const state = page.state = await res.json();
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

function fillOptions(select, names) {
  if (select.options.length === names.length) return;
  select.replaceChildren(...names.map(([text, value]) => new Option(text, value)));
}

function fillPanels() {
  const { state } = page;
  const c = state.camera, stops = state.stops;
  fillOptions($('body'), [...state.bodies, 'custom'].map((name) => [name, name]));
  $('body').value = c.body;
  fillOptions($('lens'), [['focal length only', ''], ...state.lenses.map((l) => [l.name, l.name])]);
  $('lens').value = state.lens;
  setSlider('aperture', stops.apertures, c.aperture, `f/${c.aperture}`);
  setSlider('shutter', stops.shutters, c.shutter_s, shutterText(c.shutter_s));
  setSlider('iso', stops.isos, c.iso, `${c.iso}`);
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

// A slider over the steps of `list`, at the one nearest `value`.
function setSlider(id, list, value, text) {
  const input = $(id);
  input.min = 0; input.max = list.length - 1; input.step = 1;
  if (document.activeElement !== input) input.value = nearestIndex(list, value);
  $(`${id}-out`).textContent = text;
}

function setValue(id, value, text) {
  if (document.activeElement !== $(id)) $(id).value = value;
  $(`${id}-out`).textContent = text;
}

export function fillView() {
  const v = page.state.view, orbit = page.orbit;
  const d = v.position.map((p, i) => p - v.look_at[i]);
  orbit.distance = Math.hypot(...d);
  orbit.azimuth = Math.atan2(d[1], d[0]);
  orbit.elevation = Math.asin(d[2] / orbit.distance);
  orbit.target = v.look_at.slice();
  setValue('turntable', v.turntable_deg, `${v.turntable_deg.toFixed(0)}°`);
  setValue('distance', orbit.distance, `${orbit.distance.toFixed(2)} m`);
  $('pose-readout').textContent = 'camera at [' + v.position.map((p) => p.toFixed(2)).join(', ') +
    '] m, aimed at [' + v.look_at.map((p) => p.toFixed(2)).join(', ') + '] m';
}

function lightRow(light, i) {
  const { node, parts } = fromTemplate('light-row');
  parts.title.textContent = `${i + 1}. ${light.type}`;
  parts.line.textContent = `line ${light.line}`;
  parts.remove.dataset.remove = i;
  parts.position.value = light.position.map((p) => p.toFixed(2)).join(', ');
  parts.power.value = light.power_w;
  parts.temperature.value = light.temperature_k;
  parts.size.value = (100 * light.size_m[0]).toFixed(0);
  parts['power-row'].hidden = light.type === 'directional';
  parts['size-row'].hidden = light.type !== 'area';
  for (const input of node.querySelectorAll('input')) input.dataset.i = i;
  return node;
}

function fillLights(lights) {
  const box = $('lights');
  if (box.contains(document.activeElement)) return;
  box.replaceChildren(...lights.map(lightRow));
}

// A scene value changed: edit, then a small frame while moving and the full one on release.
async function setScene(path, value, released) {
  const started = performance.now();
  if (!(await post('api/set', { path, value }))) { await refreshState(); return; }
  showStatus('');
  // The frame and the panels' state at once.
  requestFrame(released ? FULL_WIDTH : MOVING_WIDTH, () => {
    if (released) performance.measure('rigc:slider', { start: started });
  });
  await refreshState();
  if (released) scheduleAnalysis();
}

// A lens preset with a focal length it takes: a prime's own, the current one kept in a zoom's
// range. ("focal length only" marks a scene without a preset; taking one out is an edit of the
// file.)
async function setLens(name) {
  const { state } = page;
  const lens = state.lenses.find((l) => l.name === name);
  if (!lens) { await refreshState(); return; }
  const [shortest, longest] = lens.focal_mm;
  const focal = Math.round(Math.min(longest, Math.max(shortest, state.camera.focal_length_mm)));
  const changes = [{ path: 'camera.lens.preset', value: name },
    { path: 'camera.lens.focal_length', value: `${focal}mm` }];
  if (await post('api/set', { changes })) changed(); else await refreshState();
}

// A slider over a table of the camera's steps (state.stops[table]).
function bindSlider(id, table, path, format) {
  const input = $(id);
  const send = (released) => {
    const value = page.state.stops[table][Number(input.value)];
    $(`${id}-out`).textContent = format(value);
    setScene(path, format(value), released);
  };
  input.addEventListener('input', () => send(false));
  input.addEventListener('change', () => send(true));
}

function bindRange(id, path, format) {
  const input = $(id);
  input.addEventListener('input', () => setScene(path, format(Number(input.value)), false));
  input.addEventListener('change', () => setScene(path, format(Number(input.value)), true));
}

const LIGHT_VALUES = {
  position: (v) => `[${v.split(',').map((p) => `${Number(p)}m`).join(', ')}]`,
  power: (v) => `${v}W`,
  temperature: (v) => `${v}K`,
  size: (v) => `[${v}cm, ${v}cm]`,
};

function bindLights() {
  $('lights').addEventListener('change', (e) => {
    const key = e.target.dataset.key;
    if (!LIGHT_VALUES[key]) return;
    setScene(`studio.lights.${e.target.dataset.i}.${key}`, LIGHT_VALUES[key](e.target.value.trim()),
      true);
  });
  $('lights').addEventListener('click', async (e) => {
    if (e.target.dataset.remove === undefined) return;
    if (await post('api/lights/remove', { index: Number(e.target.dataset.remove) })) changed();
  });
  $('add-light').addEventListener('click', async () => {
    const p = page.state.view.position;
    const light = { type: 'point',
      position: `[${p[0].toFixed(2)}m, ${p[1].toFixed(2)}m, ${(p[2] + 0.5).toFixed(2)}m]`,
      power: '100W' };
    if (await post('api/lights/add', light)) changed();
  });
}

export function bindPanels() {
  bindSlider('aperture', 'apertures', 'camera.exposure.aperture', (v) => `f/${v}`);
  bindSlider('shutter', 'shutters', 'camera.exposure.shutter', shutterText);
  bindSlider('iso', 'isos', 'camera.exposure.iso', (v) => `${v}`);
  bindRange('focal', 'camera.lens.focal_length', (v) => `${v}mm`);
  bindRange('focus', 'camera.focus', (v) => `${v.toFixed(2)}m`);
  bindRange('wb', 'camera.white_balance', (v) => `${v}K`);
  bindRange('table', 'studio.turntable.diameter', (v) => `${Math.round(100 * v)}cm`);
  $('body').addEventListener('change', () => setScene('camera.body', $('body').value, true));
  $('lens').addEventListener('change', () => setLens($('lens').value));
  $('focus-auto').addEventListener('change', () => setScene('camera.focus',
    $('focus-auto').checked ? 'auto' : `${page.state.view.focus_distance_m.toFixed(2)}m`, true));
  $('wb-auto').addEventListener('change', () => setScene('camera.white_balance',
    $('wb-auto').checked ? 'auto' : `${page.state.camera.white_balance_k.toFixed(0)}K`, true));
  $('green-screen').addEventListener('change', () => setScene('studio.backdrop.green_screen',
    $('green-screen').checked ? 'true' : 'false', true));
  $('turntable').addEventListener('input', () => moveView(false));
  $('turntable').addEventListener('change', () => moveView(true));
  $('distance').addEventListener('input', () => {
    page.orbit.distance = Number($('distance').value);
    moveView(false);
  });
  $('distance').addEventListener('change', () => moveView(true));
  bindLights();
  $('capture').addEventListener('click', capture);
  $('suggest').addEventListener('click', suggest);
  $('undo').addEventListener('click', async () => { if (await post('api/undo')) changed(); });
  $('save').addEventListener('click', async () => {
    if (await post('api/save')) { showStatus('saved'); await refreshState(); }
  });
}

// After a change the page made: the state, a full frame and the analyses.
export async function changed() {
  showStatus('');
  await refreshState();
  requestFrame(FULL_WIDTH);
  scheduleAnalysis();
}
