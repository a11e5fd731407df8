// The one run loop: every backend's `rigc render` goes through run_backend. It prepares and locks
// the run folder, skips the shots the manifest says are done with the same inputs, renders the
// others through the backend, develops each through the DSLR model, writes the image and mask
// while the next shot renders, records each shot in the manifest, and writes the ground truth.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "run/backend.h"

namespace rigc::run {

struct RunOptions {
  std::filesystem::path output_dir;  // the run folder
  std::vector<int> shots;            // indices to render (all when empty)
  RenderSettings settings;
  bool progress_bar = false;  // redraw one line on a terminal instead of a line per shot
  // Delete another scene's shots and files no manifest lists from the run folder instead of
  // refusing to render into it.
  bool force = false;
};

struct ShotTiming {
  // The backend's stages, the DSLR model's, and "write", in milliseconds: the manifest's stage_ms.
  std::map<std::string, double> stage_ms;
  double total_ms = 0;
  int subframes = 1;
  bool skipped = false;  // already in the manifest with the same inputs
  bool failed = false;
};

// Runs the backend over the selected shots. Returns the exit code: 0, 1 (user error: bad
// options, folder taken by another rigc) or 2 (a shot or the ground truth failed; each failure is
// named in `log` with its log file). Progress and errors go to `log`.
int run_backend(const ir::Scene& scene, Backend& backend, const RunOptions& options,
                std::ostream& log, std::vector<ShotTiming>* timings = nullptr);

// A rendered shot through the DSLR model, as the run loop develops it. `keep_linear` keeps the
// linear image in the result (tests); a run writing files does without. Adds the model's stages
// to `stage_ms` when given.
// (Seven parameters, the last optional: the shot, its render and the settings it was made
// with.)
dslr::DevelopResult develop_shot(const ir::Scene& scene, const ir::Shot& shot,
                                 RenderedShot&& rendered, const RenderSettings& settings,
                                 bool keep_linear, std::string* error,
                                 std::map<std::string, double>* stage_ms = nullptr);

}  // namespace rigc::run
