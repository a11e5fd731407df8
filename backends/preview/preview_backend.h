// `rigc render --backend preview`: every shot through the rasterizer and the DSLR model, written
// in the common output layout (images, masks, sparse/, transforms.json, manifest.json).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "raster/rasterizer.h"

namespace rigc::preview {

struct RenderOptions {
  std::string output_dir;  // the run folder
  std::vector<int> shots;  // indices to render (all when empty)
  double scale = 1.0;      // multiplies the sensor resolution
  std::uint64_t seed = 1;  // sensor noise
  bool progress_bar = false;
};

struct ShotTiming {
  raster::RasterTimings raster;
  dslr::StageTimings develop;
  double write_ms = 0;
  double total_ms = 0;
  int subframes = 1;
  bool skipped = false;  // already in the manifest with the same inputs
};

// A shot's time by stage in milliseconds, under the names the manifest records ("stage_ms").
std::map<std::string, double> stage_ms(const ShotTiming& timing);

// Renders one shot to developed pixels (no files). For tests and benchmarks. Without
// `keep_linear` the result's linear image is left empty (what a run that writes files does).
dslr::DevelopResult render_shot(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale, std::uint64_t seed,
                                ShotTiming* timing = nullptr,
                                dslr::LinearFrame* linear_out = nullptr, bool keep_linear = true);

// Runs the whole backend; returns the process exit code (0, 1 user error, 2 failure) and
// writes progress and errors to `log`.
int run_preview(const ir::Scene& scene, const RenderOptions& options, std::ostream& log,
                std::vector<ShotTiming>* timings = nullptr);

}  // namespace rigc::preview
