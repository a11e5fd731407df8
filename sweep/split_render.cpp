#include "sweep/split_render.h"

#include <fmt/format.h>

#include <chrono>
#include <ostream>
#include <thread>

#include "io/atomic_file.h"
#include "run/backend.h"
#include "run/manifest.h"
#include "sweep/slurm_executor.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;

constexpr const char* kShotScript =
    "#!/bin/sh\n"
    "# rigc render, one shot per array task. Arguments (given to sbatch after this script): rigc,\n"
    "# the scene file, the parts folder, then render's own options.\n"
    "rigc=$1; scene=$2; parts=$3; shift 3\n"
    "exec \"$rigc\" render \"$scene\" --shots \"$SLURM_ARRAY_TASK_ID\" "
    "-o \"$parts/shot_$SLURM_ARRAY_TASK_ID\" \"$@\"\n";

// sbatch for the shots; the array job's id, or "" after an error printed to `log`.
std::string submit_shots(const fs::path& parts, const std::vector<int>& shots,
                         const run::RunOptions& options, const SplitRender& split,
                         std::ostream& log) {
  std::string error;
  if (!write_file_atomically(parts / "render.sh", kShotScript, &error)) {
    log << "rigc: error: " << error << '\n';
    return "";
  }
  std::vector<std::string> argv = {"sbatch", "--parsable", "--job-name=rigc-render",
                                   "--array=" + array_list(shots),
                                   "--output=" + (parts / "slurm" / "%A_%a.log").string()};
  argv.insert(argv.end(), split.sbatch_args.begin(), split.sbatch_args.end());
  argv.insert(argv.end(), {(parts / "render.sh").string(), fs::absolute(split.rigc).string(),
                           fs::absolute(split.scene_path).string(), parts.string(), "--backend",
                           split.backend, "--scale", fmt::format("{}", options.settings.scale),
                           "--samples", run::samples_text(options.settings.samples), "--seed",
                           std::to_string(options.settings.seed)});
  std::string output;
  const int status = run_slurm_tool(parts, argv, &output);
  const std::string job = output.substr(0, output.find_first_not_of("0123456789"));
  if (status != 0 || job.empty()) {
    log << fmt::format("rigc: error: sbatch refused the job array (exit {}):\n{}", status, output);
    return "";
  }
  log << fmt::format("rigc render: submitted job array {} ({} shots)\n", job, shots.size());
  return job;
}

void wait_for_job(const fs::path& parts, const std::string& job, std::size_t total,
                  double poll_seconds, std::ostream& log) {
  std::size_t last = total + 1;
  while (true) {
    std::size_t active = 0;
    for (const auto& [id, state] : queued_tasks(parts)) active += id.starts_with(job + "_");
    if (active != last) {
      log << fmt::format("rigc render: {}/{} shots done\n", total - active, total);
      last = active;
    }
    if (active == 0) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_seconds));
  }
}

// Copies a part's files and manifest records into the run folder; false when it has no record
// for `shot_name`.
bool merge_part(const fs::path& part, const fs::path& run_dir, const std::string& shot_name,
                run::Manifest& manifest) {
  const run::Manifest part_manifest = run::Manifest::load(part / "manifest.json");
  const run::ShotRecord* record = part_manifest.find(shot_name);
  if (!record) return false;
  for (const std::string& file : record->files) {
    std::error_code ec;
    fs::create_directories((run_dir / file).parent_path(), ec);
    const bool copied = write_atomically(
        run_dir / file,
        [&](const fs::path& temporary, std::string* reason) {
          std::error_code copy_ec;
          fs::copy_file(part / file, temporary, fs::copy_options::overwrite_existing, copy_ec);
          if (copy_ec) *reason = copy_ec.message();
          return !copy_ec;
        },
        nullptr);
    if (!copied) return false;
  }
  manifest.set_inputs(part_manifest.inputs());
  manifest.set_backend(part_manifest.backend());
  manifest.record(*record);
  return true;
}

}  // namespace

int render_on_slurm(const ir::Scene& scene, run::Backend& backend, const run::RunOptions& options,
                    const SplitRender& split, std::ostream& log) {
  std::vector<int> shots = options.shots;
  if (shots.empty()) {
    for (int i = 0; i < static_cast<int>(scene.shots.size()); ++i) shots.push_back(i);
  }
  const fs::path run_dir = fs::absolute(options.output_dir);
  const fs::path parts = run_dir / ".slurm-shots";
  std::error_code ec;
  fs::create_directories(parts / "slurm", ec);
  const std::string job = submit_shots(parts, shots, options, split, log);
  if (job.empty()) return 1;
  wait_for_job(parts, job, shots.size(), split.poll_seconds, log);
  run::Manifest manifest = run::Manifest::load(run_dir / "manifest.json");
  int failed = 0;
  for (const int i : shots) {
    const std::string& name = scene.shots[i].name;
    if (merge_part(parts / fmt::format("shot_{}", i), run_dir, name, manifest)) continue;
    const std::string task = fmt::format("{}_{}", job, i);
    const std::string state = finished_state(parts, task);
    log << fmt::format("rigc render: {} failed ({}job {}, log {})\n", name,
                       state.empty() ? "" : "Slurm: " + state + ", ", task,
                       (parts / "slurm" / (task + ".log")).string());
    ++failed;
  }
  std::string error;
  if (!manifest.save(run_dir / "manifest.json", &error)) {
    log << "rigc: error: " << error << '\n';
    return 2;
  }
  if (failed) return 2;
  // The run loop finds every shot done and writes the ground truth.
  return run::run_backend(scene, backend, options, log);
}

}  // namespace rigc::sweep
