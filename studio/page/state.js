// The page's one state object: what the server last said, the camera the user moves, and the
// requests in flight. Every module reads and writes it here, and nowhere else.
export const page = {
  state: null,  // /api/state: the scene's camera, studio, view and the camera tables
  orbit: { azimuth: 0, elevation: 0, distance: 1, target: [0, 0, 1] },
  frames: { busy: false, wanted: null },    // the live view: one frame request at a time
  view: { busy: false, pending: null },     // camera moves: one /api/view at a time
  frame: { mean: 0, clipped: 0, width: 0, count: 0 },  // the last frame drawn
  coverage: null,                           // /api/coverage: the last coverage shown
  coverageView: {},                         // the 3D coverage view (three.js)
  adviceTimer: null,
  reference: { timer: null, flicker: null, status: null },
};

export const FULL_WIDTH = 1280;   // the live view at rest
export const MOVING_WIDTH = 480;  // while a slider or the camera moves
