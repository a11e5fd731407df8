// Requests to the studio's server (with the page's token) and the status line.
const token = new URLSearchParams(location.search).get('token') || '';

export const $ = (id) => document.getElementById(id);

export function api(path, options = {}) {
  const headers = Object.assign({ 'X-Rigc-Token': token }, options.headers || {});
  return fetch(path, Object.assign({}, options, { headers }));
}

// An image's address with the token (an <img> cannot send the header).
export function tokenUrl(path) {
  return `${path}${path.includes('?') ? '&' : '?'}token=${encodeURIComponent(token)}`;
}

export async function postJson(path, body) {
  return api(path, { method: 'POST', body: JSON.stringify(body || {}),
    headers: { 'Content-Type': 'application/json' } });
}

// POSTs `body`; false after showing the server's refusal.
export async function post(path, body) {
  const res = await postJson(path, body);
  const reply = await res.json();
  if (!res.ok) showStatus(reply.error, true);
  return res.ok;
}

export function showStatus(text, isError) {
  const status = $('status');
  status.textContent = text || '';
  status.className = isError ? 'error' : '';
}

// A copy of the <template> called `id`, and its elements by their data-part names.
export function fromTemplate(id) {
  const node = $(id).content.firstElementChild.cloneNode(true);
  const parts = {};
  node.querySelectorAll('[data-part]').forEach((el) => { parts[el.dataset.part] = el; });
  return { node, parts };
}
