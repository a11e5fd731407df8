// `rigc render --executor slurm`: one scene's render split over a Slurm cluster, a task per shot.
// Each task renders its shot with `rigc render --shots N` into a part folder of its own
// (RUN/.slurm-shots/shot_N/), so every folder and manifest keeps one writer; this process then
// merges the parts' files and manifest records into RUN and runs the run loop there, which finds
// every shot done and writes the ground truth, as a local render would.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "run/backend.h"
#include "run/run_loop.h"

namespace rigc::sweep {

struct SplitRender {
  std::filesystem::path rigc;       // the rigc the tasks run
  std::string scene_path, backend;  // as `rigc render` was given them
  std::vector<std::string> sbatch_args;
  double poll_seconds = 0.5;
};

// Renders options.shots (all when empty) of `scene` through Slurm into options.output_dir.
// Returns 0, 1 (sbatch refused the job) or 2 (a task failed: each is named with its job and log).
int render_on_slurm(const ir::Scene& scene, run::Backend& backend, const run::RunOptions& options,
                    const SplitRender& split, std::ostream& log);

}  // namespace rigc::sweep
