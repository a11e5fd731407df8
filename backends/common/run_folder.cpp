#include "backends/common/run_folder.h"

#include <fmt/format.h>
#include <unistd.h>

#include <ostream>

#include "backends/common/colmap_text.h"
#include "backends/common/transforms_json.h"

namespace rigc::backends {

namespace fs = std::filesystem;

std::string progress_line(int done, int total, const std::string& name, double seconds) {
  constexpr int kWidth = 30;
  const int filled = total > 0 ? done * kWidth / total : kWidth;
  return fmt::format("\r[{}{}] {}/{} {} {:.2f} s", std::string(filled, '#'),
                     std::string(kWidth - filled, ' '), done, total, name, seconds);
}

bool prepare_run_folder(const fs::path& run_dir, const std::vector<fs::path>& extra,
                        std::ostream& log) {
  std::vector<fs::path> folders = {run_dir / "images", run_dir / "masks", run_dir / "sparse"};
  folders.insert(folders.end(), extra.begin(), extra.end());
  for (const fs::path& dir : folders) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
      log << fmt::format("rigc: error: cannot create the output folder '{}': {}\n", dir.string(),
                         ec ? ec.message() : "not a folder");
      return false;
    }
  }
  if (access(run_dir.c_str(), W_OK) != 0 || access((run_dir / "images").c_str(), W_OK) != 0) {
    log << fmt::format("rigc: error: the output folder '{}' is not writable\n", run_dir.string());
    return false;
  }
  return true;
}

int finish_run(const ir::Scene& scene, const Manifest& manifest, const fs::path& run_dir,
               double scale, int failures, size_t shots, std::ostream& log) {
  // Ground truth for every shot that has its image in this run folder.
  std::vector<int> present;
  for (const auto& shot : scene.shots) {
    if (manifest.find(shot.name) && fs::exists(run_dir / image_relative_path(scene.camera, shot))) {
      present.push_back(shot.index);
    }
  }
  std::string error;
  if (!write_colmap_sparse(run_dir / "sparse", scene, present, scale, &error) ||
      !write_transforms_json(run_dir / "transforms.json", scene, present, scale, &error)) {
    log << fmt::format("rigc: error: {}\n", error);
    return 2;
  }
  if (failures) {
    log << fmt::format("rigc: {} of {} shots failed; rerun to retry them\n", failures, shots);
    return 2;
  }
  log << fmt::format("rigc: {} shots in {}\n", shots, run_dir.string());
  return 0;
}

}  // namespace rigc::backends
