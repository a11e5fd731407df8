// The reference check: the view by POV-Ray or Cycles beside the preview's frame of it.
import { $, api, postJson, tokenUrl } from 'studio/api.js';
import { page } from 'studio/state.js';

function showReferenceStatus(text, isError) {
  const status = $('reference-status');
  status.textContent = text;
  status.className = isError ? 'error' : '';
}

async function startReference() {
  const body = { backend: $('reference-backend').value, width: Number($('reference-width').value) };
  showReferenceStatus(`starting ${body.backend} ...`);
  const res = await postJson('api/reference', body);
  if (!res.ok) { showReferenceStatus((await res.json()).error, true); return; }
  $('reference-cancel').disabled = false;
  $('reference-start').disabled = true;
  clearInterval(page.reference.timer);
  page.reference.timer = setInterval(pollReference, 500);
}

async function pollReference() {
  const res = await api('api/reference');
  if (!res.ok) return;
  const s = page.reference.status = await res.json();
  if (s.state === 'running') {
    const share = s.progress === null ? '' : ` ${(100 * s.progress).toFixed(0)} %,`;
    showReferenceStatus(`rendering with ${s.backend}:${share} ${s.elapsed_s.toFixed(0)} s`);
    return;
  }
  clearInterval(page.reference.timer);
  $('reference-cancel').disabled = true;
  $('reference-start').disabled = false;
  if (s.state === 'done') {
    showReferenceStatus(`${s.backend}, ${s.width} x ${s.height}, ${s.elapsed_s.toFixed(1)} s`);
    const stamp = Date.now();
    $('reference-preview').src = tokenUrl(`api/reference/image?which=preview&t=${stamp}`);
    $('reference-image').src = tokenUrl(`api/reference/image?which=reference&t=${stamp}`);
    $('reference-panel').hidden = false;
  } else if (s.state === 'failed') {
    showReferenceStatus(`${s.backend} failed: ${s.message} (log: ${s.log})`, true);
  } else if (s.state === 'cancelled') {
    showReferenceStatus(`${s.backend}: cancelled`);
  }
}

// Side by side, or one place showing the preview and the reference in turn.
function setFlicker(on) {
  clearInterval(page.reference.flicker);
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
  page.reference.flicker = setInterval(show, 600);
}

export function bindReference() {
  $('reference-start').addEventListener('click', startReference);
  $('reference-cancel').addEventListener('click', async () => {
    await postJson('api/reference/cancel', {});
    pollReference();
  });
  $('reference-flicker').addEventListener('change', () => setFlicker($('reference-flicker').checked));
  $('reference-close').addEventListener('click', () => {
    setFlicker(false);
    $('reference-flicker').checked = false;
    $('reference-panel').hidden = true;
  });
}
