// The live view: one frame request in flight at a time, the latest wish wins; the histogram and
// the exposure readout under it.
import { $, api, showStatus } from 'studio/api.js';
import { shutterText } from 'studio/format.js';
import { MOVING_WIDTH, page } from 'studio/state.js';

export function requestFrame(width, onShown) {
  page.frames.wanted = { width, onShown };
  if (!page.frames.busy) pumpFrames();
}

async function pumpFrames() {
  const frames = page.frames;
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

export async function showFrame(width) {
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
  page.frame = { mean: Number(res.headers.get('X-Rigc-Mean')), clipped, width: bitmap.width,
    count: page.frame.count + 1 };
  drawHistogram(bins, clipped);
  showExposure(clipped);
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
}

function showExposure(clipped) {
  const c = page.state ? page.state.camera : null;
  $('exposure-readout').textContent = c ? `EV₁₀₀ ${c.ev100.toFixed(2)} · ` +
    `f/${c.aperture} · ${shutterText(c.shutter_s)} · ISO ${c.iso} · ` +
    `${c.focal_length_mm.toFixed(0)} mm · clipped ${(100 * clipped).toFixed(2)} %` : '';
}
