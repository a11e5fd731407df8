#include "run/run_folder.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <map>
#include <ostream>
#include <set>
#include <system_error>

#include "io/atomic_file.h"
#include "run/bundler.h"
#include "run/camera_csv.h"
#include "run/colmap_text.h"
#include "run/ground_truth_points.h"
#include "run/transforms_json.h"

namespace rigc::run {

namespace fs = std::filesystem;

// Surface samples tested against the shots for points3D.txt and bundle.out.
constexpr int kGroundTruthSamples = 20000;

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
  // Before any shot renders: a folder named manifest.json let the whole run render, then fail.
  std::string error;
  if (file_to_replace(run_dir / "manifest.json", &error).empty()) {
    log << fmt::format("rigc: error: {}\n", error);
    return false;
  }
  return true;
}

RunFolderLock::~RunFolderLock() {
  if (fd_ >= 0) ::close(fd_);  // closing the descriptor releases its flock
}

bool RunFolderLock::acquire(const fs::path& run_dir, std::ostream& log) {
  const fs::path path = run_dir / ".rigc.lock";
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    log << fmt::format("rigc: error: cannot create {}: {}\n", path.string(),
                       std::system_category().message(errno));
    return false;
  }
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    log << fmt::format(
        "rigc: error: another rigc is writing to the run folder '{}'; wait for it "
        "or choose another folder with -o\n",
        run_dir.string());
    ::close(fd_);
    fd_ = -1;
    return false;
  }
  return true;
}

bool prune_stale_outputs(Manifest& manifest, const ir::Scene& scene, const fs::path& run_dir,
                         const fs::path& manifest_path, std::ostream& log) {
  std::map<std::string, std::set<std::string>> expected;  // per shot of the scene, its files
  for (const auto& shot : scene.shots) {
    expected[shot.name] = {image_relative_path(scene.camera, shot), mask_relative_path(shot)};
  }
  // A manifest is only data: a listed path outside images/ and masks/ is never touched.
  auto ours = [](const fs::path& relative) {
    const auto first = relative.begin();
    if (relative.is_absolute() || first == relative.end()) return false;
    if (*first != "images" && *first != "masks") return false;
    return std::none_of(relative.begin(), relative.end(),
                        [](const fs::path& part) { return part == ".." || part == "."; });
  };
  int removed = 0;
  std::vector<std::string> gone;
  for (const auto& [name, record] : manifest.shots()) {
    const auto shot = expected.find(name);
    for (const auto& file : record.files) {
      if (shot != expected.end() && shot->second.count(file)) continue;
      std::error_code ec;
      const fs::path path = run_dir / file;
      if (ours(file) && fs::is_regular_file(fs::symlink_status(path, ec)) && fs::remove(path, ec)) {
        ++removed;
      }
    }
    if (shot == expected.end()) gone.push_back(name);
  }
  for (const auto& name : gone) manifest.forget(name);
  if (!gone.empty()) {
    log << fmt::format(
        "rigc: {} shot{} of an earlier run ({}{}) {} no longer in the scene: removed "
        "from the run folder\n",
        gone.size(), gone.size() == 1 ? "" : "s", gone.front(),
        gone.size() > 1 ? fmt::format(" to {}", gone.back()) : "", gone.size() == 1 ? "is" : "are");
  }
  if (removed == 0 && gone.empty()) return true;
  std::string error;
  if (!manifest.save(manifest_path, &error)) {
    log << fmt::format("rigc: error: {}\n", error);
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
  const auto camera = output_camera(scene.camera, scale, &error);
  const GroundTruthPoints points =
      camera ? sample_ground_truth_points(scene, present, *camera, kGroundTruthSamples)
             : GroundTruthPoints{};
  if (!camera || !write_colmap_sparse(run_dir / "sparse", scene, present, scale, &error, &points) ||
      !write_transforms_json(run_dir / "transforms.json", scene, present, scale, &error) ||
      !write_bundler(run_dir / "bundle.out", run_dir / "bundle.list.txt", scene, present, scale,
                     points, &error) ||
      !write_camera_csv(run_dir / "cameras.csv", scene, present, &error)) {
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

}  // namespace rigc::run
