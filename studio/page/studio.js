// rigc studio's page: the live view, the camera and studio panels, capture, coverage and advice.
// Every change goes to the server as an edit of the scene; the server compiles it and refuses
// what the compiler refuses (the message is shown in the status line). The modules share one
// state object (state.js); the browser tests read it as window.rigcStudio.
import { showStatus } from 'studio/api.js';
import { refreshCoverage, scheduleAnalysis, setUpCoverageView } from 'studio/coverage.js';
import { requestFrame } from 'studio/live_view.js';
import { bindMovement } from 'studio/movement.js';
import { bindPanels, refreshState } from 'studio/panels.js';
import { bindReference } from 'studio/reference.js';
import { FULL_WIDTH, page } from 'studio/state.js';

window.rigcStudio = page;

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
    const reloads = page.state && page.state.reloads;
    await refreshState();
    if (page.state && page.state.reloads !== reloads) { requestFrame(FULL_WIDTH); scheduleAnalysis(); }
  }, 1000);
}

start();
