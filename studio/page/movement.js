// Moving the camera: orbit by dragging the live view, distance by the wheel, walking by the keys.
import { $, post, showStatus } from 'studio/api.js';
import { capture } from 'studio/coverage.js';
import { showFrame } from 'studio/live_view.js';
import { fillView, refreshState } from 'studio/panels.js';
import { FULL_WIDTH, MOVING_WIDTH, page } from 'studio/state.js';

function viewPose() {
  const { azimuth: a, elevation: e, distance: d, target: t } = page.orbit;
  const position = [t[0] + d * Math.cos(e) * Math.cos(a), t[1] + d * Math.cos(e) * Math.sin(a),
    t[2] + d * Math.sin(e)];
  return { position, look_at: t, turntable_deg: Number($('turntable').value) };
}

// Sends the view and draws its frame: one at a time, the latest pose wins; a `released` move
// (the end of a drag) gets the full-size frame.
export async function moveView(released) {
  const view = page.view;
  view.pending = released;
  if (view.busy) return;
  view.busy = true;
  while (view.pending !== null) {
    const fullFrame = view.pending;
    view.pending = null;
    const started = performance.now();
    if (await post('api/view', viewPose())) {
      showStatus('');
      await showFrame(fullFrame ? FULL_WIDTH : MOVING_WIDTH);
      performance.measure('rigc:drag', { start: started });
    }
  }
  view.busy = false;
  await refreshState();
  fillView();
}

const WALK_STEP = 0.05;  // metres a key press

// The camera and its aim moved together, as a first-person camera walks; false for other keys.
function walk(code) {
  const orbit = page.orbit, t = orbit.target;
  const forward = [-Math.cos(orbit.azimuth), -Math.sin(orbit.azimuth)];
  const right = [-forward[1], forward[0]];
  const moves = { KeyW: [forward, WALK_STEP], ArrowUp: [forward, WALK_STEP],
    KeyS: [forward, -WALK_STEP], ArrowDown: [forward, -WALK_STEP], KeyD: [right, -WALK_STEP],
    ArrowRight: [right, -WALK_STEP], KeyA: [right, WALK_STEP], ArrowLeft: [right, WALK_STEP] };
  if (moves[code]) {
    const [dir, s] = moves[code];
    orbit.target = [t[0] + s * dir[0], t[1] + s * dir[1], t[2]];
  } else if (code === 'KeyQ' || code === 'KeyE') {
    orbit.target = [t[0], t[1], t[2] + (code === 'KeyE' ? WALK_STEP : -WALK_STEP)];
  } else {
    return false;
  }
  return true;
}

export function bindMovement() {
  const canvas = $('view');
  const orbit = page.orbit;
  let dragging = null;
  canvas.addEventListener('pointerdown', (e) => {
    dragging = { x: e.clientX, y: e.clientY };
    canvas.setPointerCapture(e.pointerId);
  });
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
    if (!walk(e.code)) return;
    e.preventDefault();
    moveView(true);
  });
}
