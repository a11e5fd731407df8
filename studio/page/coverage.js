// Capture, the planner's suggestion, the coverage (numbers and the 3D view) and the advice.
import { $, api, fromTemplate, post, postJson, showStatus } from 'studio/api.js';
import { changed, refreshState } from 'studio/panels.js';
import { page } from 'studio/state.js';

export async function capture() {
  const started = performance.now();
  if (!(await post('api/capture'))) return;
  const posted = performance.now();
  showStatus(`captured shot ${page.state ? page.state.shots + 1 : ''}`);
  const parts = await refreshCoverage(true);
  performance.measure('rigc:capture',
    { start: started, detail: Object.assign({ capture: posted - started }, parts) });
  await refreshState();
  scheduleAnalysis();
}

// The planner's next shot becomes the current view; capture takes it.
export async function suggest() {
  showStatus('planning the next shot ...');
  const res = await postJson('api/suggest', {});
  const reply = await res.json();
  if (!res.ok) { showStatus(reply.error, true); return; }
  await changed();
  showStatus(`suggested: adds ${(100 * reply.gain).toFixed(1)} %, ` +
    `${(100 * reply.reconstructable).toFixed(1)} % reconstructable with it; press Capture to take it`);
}

// The object's mesh as triangles coloured by the views that see them.
export async function setUpCoverageView() {
  const THREE = window.THREE;
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
  Object.assign(page.coverageView, { geometry, render, faces: tris.length / 3 });
  render();
}

const PAPER = [[1, 1, 1], [0.85, 0.05, 0.05], [0.05, 0.7, 0.1]];

// The faces coloured again, when one changed colour (a software WebGL takes a core for a while
// to draw the view).
function colourCoverageView(views) {
  const view = page.coverageView;
  if (!view.geometry) return;
  const drawn = view.views;
  const same = drawn && drawn.length === views.length &&
    views.every((v, f) => Math.min(2, v) === Math.min(2, drawn[f]));
  if (same) return;
  const colors = view.geometry.attributes.color;
  views.forEach((v, f) => {
    const c = PAPER[Math.min(2, v)];
    for (let k = 0; k < 3; ++k) colors.setXYZ(3 * f + k, c[0], c[1], c[2]);
  });
  colors.needsUpdate = true;
  view.views = views;
  view.render();
}

// The coverage's numbers and view; after a capture, its parts' times.
export async function refreshCoverage(afterCapture) {
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
  page.coverage = coverage;
  colourCoverageView(coverage.views);
  return { coverage: fetched - started, wait: coverage.wait_ms, analysis: coverage.analysis_ms,
    json: coverage.json_ms, draw: performance.now() - fetched };
}

function adviceItem(d) {
  const { node, parts } = fromTemplate('advice-item');
  node.className = d.severity;
  node.title = d.rendered;
  parts.where.textContent = `line ${d.line}:${d.col}`;
  parts.message.textContent = d.message;
  return node;
}

// The advice and the coverage, a moment after the last change.
export function scheduleAnalysis() {
  clearTimeout(page.adviceTimer);
  page.adviceTimer = setTimeout(async () => {
    const res = await api('api/advice');
    if (!res.ok) return;
    const advice = await res.json();
    const list = $('advice');
    if (advice.length === 0) list.replaceChildren(fromTemplate('no-advice').node);
    else list.replaceChildren(...advice.map(adviceItem));
    refreshCoverage();
  }, 400);
}
