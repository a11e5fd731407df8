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
#include "io/input_files.h"
#include "io/output_paths.h"
#include "run/bundler.h"
#include "run/camera_csv.h"
#include "run/colmap_text.h"
#include "run/ground_truth_points.h"
#include "run/transforms_json.h"

namespace rigc::run {

namespace fs = std::filesystem;

// Surface samples tested against the shots for points3D.txt and bundle.out.
constexpr int kGroundTruthSamples = 20000;

std::string time_left_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {} s", s / 60, s % 60);
  return fmt::format("{} h {} min", s / 3600, s % 3600 / 60);
}

std::string progress_line(int done, int total, const std::string& name, double seconds,
                          double seconds_left) {
  constexpr int kWidth = 30;
  const int filled = total > 0 ? done * kWidth / total : kWidth;
  const std::string left =
      done < total ? fmt::format(", about {} left", time_left_text(seconds_left)) : "";
  // Trailing spaces wipe a longer line drawn before.
  return fmt::format("\r[{}{}] {}/{} {} {:.2f} s{}    ", std::string(filled, '#'),
                     std::string(kWidth - filled, ' '), done, total, name, seconds, left);
}

bool prepare_run_folder(const fs::path& run_dir, const std::vector<fs::path>& extra,
                        std::ostream& log) {
  std::vector<fs::path> folders = {run_dir / "images", run_dir / "masks", run_dir / "sparse"};
  folders.insert(folders.end(), extra.begin(), extra.end());
  std::string error;
  if (!make_output_folder(run_dir, &error)) {
    log << fmt::format("rigc: error: {}\n", error);
    return false;
  }
  for (const fs::path& dir : folders) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir, ec)) {
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

int remove_stale_temporaries(const fs::path& run_dir) {
  int removed = 0;
  std::error_code ec;
  auto sweep = [&](const fs::path& dir) {
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      std::error_code file_ec;
      if (it->is_regular_file(file_ec) && is_temporary_name(it->path().filename().string()) &&
          fs::remove(it->path(), file_ec)) {
        ++removed;
      }
    }
  };
  // Only the folders a run writes: `rigc eval` writes into run_dir/eval without the lock.
  for (const fs::path& dir :
       {run_dir, run_dir / "images", run_dir / "masks", run_dir / "sparse", run_dir / "render"}) {
    std::error_code dir_ec;
    if (!fs::is_symlink(fs::symlink_status(dir, dir_ec)) && fs::is_directory(dir, dir_ec)) {
      sweep(dir);
    }
    ec.clear();
  }
  return removed;
}

namespace {

// "shot_000" or "shot_000 and 17 more".
std::string some_names(const std::vector<std::string>& names) {
  if (names.size() == 1) return names.front();
  return fmt::format("{} and {} more", names.front(), names.size() - 1);
}

// Deletes run_dir/relative when it is a regular file in images/ or masks/ (a manifest is only
// data: nothing outside those folders is touched). True when it is gone.
bool remove_output_file(const fs::path& run_dir, const std::string& relative) {
  const fs::path file(relative);
  const auto first = file.begin();
  if (file.is_absolute() || first == file.end() || (*first != "images" && *first != "masks")) {
    return false;
  }
  if (std::any_of(file.begin(), file.end(),
                  [](const fs::path& part) { return part == ".." || part == "."; })) {
    return false;
  }
  std::error_code ec;
  if (protected_input_at(run_dir / file)) return false;
  const fs::file_status status = fs::symlink_status(run_dir / file, ec);
  return (fs::is_regular_file(status) || fs::is_symlink(status)) && fs::remove(run_dir / file, ec);
}

}  // namespace

bool claim_run_folder(Manifest& manifest, const ir::Scene& scene, const fs::path& run_dir,
                      bool force, std::ostream& log) {
  const auto recorded = manifest.inputs().find("scene");
  if (manifest.shots().empty() || recorded == manifest.inputs().end() || !recorded->is_string() ||
      recorded->get<std::string>() == scene.name) {
    return true;
  }
  const std::string other = recorded->get<std::string>();
  if (!force) {
    log << fmt::format(
        "rigc: error: the run folder '{}' holds {} shot{} of the scene '{}', not '{}'; choose "
        "another folder with -o, or pass --force to delete them\n",
        run_dir.string(), manifest.shots().size(), manifest.shots().size() == 1 ? "" : "s", other,
        scene.name);
    return false;
  }
  int removed = 0;
  for (const auto& [name, record] : manifest.shots()) {
    for (const auto& file : record.files) removed += remove_output_file(run_dir, file);
  }
  log << fmt::format("rigc: --force: deleted {} file{} of the scene '{}' from '{}'\n", removed,
                     removed == 1 ? "" : "s", other, run_dir.string());
  manifest = Manifest();
  return true;
}

bool remove_unrecorded_outputs(const Manifest& manifest, const ir::Scene& scene,
                               const fs::path& run_dir, bool force, std::ostream& log) {
  std::set<std::string> listed, ours;
  for (const auto& [name, record] : manifest.shots())
    listed.insert(record.files.begin(), record.files.end());
  for (const auto& shot : scene.shots) {
    ours.insert(image_relative_path(scene.camera, shot));
    ours.insert(mask_relative_path(shot));
  }
  std::vector<std::string> unrecorded, foreign;
  for (const char* folder : {"images", "masks"}) {
    std::error_code ec;
    for (fs::directory_iterator it(run_dir / folder, ec), end; !ec && it != end; it.increment(ec)) {
      std::error_code entry_ec;
      if (it->is_directory(entry_ec) && !it->is_symlink(entry_ec)) continue;
      const std::string name = it->path().filename().string();
      const std::string relative = std::string(folder) + "/" + name;
      if (name.starts_with(".") || listed.count(relative)) continue;
      (ours.count(relative) ? unrecorded : foreign).push_back(relative);
    }
  }
  if (!foreign.empty() && !force) {
    log << fmt::format(
        "rigc: warning: the run folder '{}' holds {} file{} that no shot of '{}' writes and its "
        "manifest does not list ({}); `rigc eval` would use them: move them, or pass --force to "
        "delete them\n",
        run_dir.string(), foreign.size(), foreign.size() == 1 ? "" : "s", scene.name,
        some_names(foreign));
    foreign.clear();
  }
  unrecorded.insert(unrecorded.end(), foreign.begin(), foreign.end());
  int removed = 0;
  for (const auto& file : unrecorded) removed += remove_output_file(run_dir, file);
  if (removed > 0) {
    log << fmt::format(
        "rigc: deleted {} file{} in '{}' that the manifest does not list ({}), left by an "
        "interrupted run or another scene\n",
        removed, removed == 1 ? "" : "s", run_dir.string(), some_names(unrecorded));
  }
  return true;
}

bool check_one_scale(const Manifest& manifest, const ir::Scene& scene,
                     const std::vector<int>& selected, double scale, std::ostream& log) {
  std::set<std::string> rendering;
  for (const int index : selected) rendering.insert(scene.shots[index].name);
  std::vector<std::string> others;
  double other_scale = 0;
  for (const auto& [name, record] : manifest.shots()) {
    if (rendering.count(name) || !record.scale || *record.scale == scale) continue;
    others.push_back(name);
    other_scale = *record.scale;
  }
  if (others.empty()) return true;
  log << fmt::format(
      "rigc: error: this run folder holds {} rendered at --scale {:g}, and a run folder holds "
      "one image size: render every shot at --scale {:g} (leave out --shots), or choose another "
      "folder with -o\n",
      some_names(others), other_scale, scale);
  return false;
}

namespace {

// bundle.out for a camera Bundler can describe; for another (fx != fy, a principal point off the
// centre: a real camera's intrinsics) none, and an earlier one removed, rather than a wrong one.
// (Seven parameters: write_bundler's, with the log.)
bool write_bundler_if_it_fits(const fs::path& run_dir, const ir::Scene& scene,
                              const std::vector<int>& present, double scale,
                              const GroundTruthPoints& points, std::ostream& log,
                              std::string* error) {
  const std::string problem = bundler_camera_problem(scene.camera, scale);
  if (problem.empty()) {
    return write_bundler(run_dir / "bundle.out", run_dir / "bundle.list.txt", scene, present, scale,
                         points, error);
  }
  std::error_code ignored;
  fs::remove(run_dir / "bundle.out", ignored);
  fs::remove(run_dir / "bundle.list.txt", ignored);
  log << fmt::format("rigc: note: no bundle.out: {}; sparse/ and transforms.json state it\n",
                     problem);
  return true;
}

}  // namespace

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
      !write_bundler_if_it_fits(run_dir, scene, present, scale, points, log, &error) ||
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
