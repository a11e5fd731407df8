// The parts of a backend run that do not depend on the renderer: preparing the run folder and,
// at the end, writing the ground truth for the shots whose images are there.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "ir/ir.h"
#include "run/manifest.h"

namespace rigc::run {

// Creates run_dir/{images,masks,sparse} and `extra` folders and checks that they are writable.
// False after writing a `rigc: error:` line to `log`.
bool prepare_run_folder(const std::filesystem::path& run_dir,
                        const std::vector<std::filesystem::path>& extra, std::ostream& log);

// While it lives, this process is the only rigc writing into a run folder: two renders into one
// folder at once each saved their own manifest over the other's (9 of 18 shots recorded).
// Released when it dies, or when the process ends in any way (an flock on run_dir/.rigc.lock).
class RunFolderLock {
 public:
  RunFolderLock() = default;
  RunFolderLock(const RunFolderLock&) = delete;
  RunFolderLock& operator=(const RunFolderLock&) = delete;
  ~RunFolderLock();
  // False after writing a `rigc: error:` line to `log` (another rigc holds the folder, or the
  // lock file cannot be made).
  bool acquire(const std::filesystem::path& run_dir, std::ostream& log);

 private:
  int fd_ = -1;
};

// A run folder holds one scene's shots, and `rigc eval` runs COLMAP on every image in images/:
// drops the manifest's entries for shots the scene no longer has, and deletes the files they list
// and, for the shots it has, listed files this camera no longer writes (a JPEG left beside a new
// PNG). Only images/ and masks/ files named by the manifest are deleted. Saves the manifest when
// it changed; false after writing a `rigc: error:` line to `log`.
bool prune_stale_outputs(Manifest& manifest, const ir::Scene& scene,
                         const std::filesystem::path& run_dir,
                         const std::filesystem::path& manifest_path, std::ostream& log);

// Removes the temporary files (io/atomic_file.h) that a killed or crashed writer left in run_dir
// and the folders a run writes (images, masks, sparse, render); call it holding the
// RunFolderLock. Returns how many.
int remove_stale_temporaries(const std::filesystem::path& run_dir);

// A run folder holds one scene: refuses (false after a `rigc: error:` line) when the manifest
// records shots of a scene with another name, unless `force`; then deletes those shots' files,
// says so in `log` and empties the manifest.
bool claim_run_folder(Manifest& manifest, const ir::Scene& scene,
                      const std::filesystem::path& run_dir, bool force, std::ostream& log);

// Files in images/ and masks/ that the manifest does not list, which `rigc eval` would hand to
// COLMAP: an interrupted run's last shots, another scene's shots. Those named like this scene's
// shots are deleted (said in `log`); any other only with `force`, else a warning names them.
// False after a `rigc: error:` line.
bool remove_unrecorded_outputs(const Manifest& manifest, const ir::Scene& scene,
                               const std::filesystem::path& run_dir, bool force, std::ostream& log);

// A run folder holds one image size (cameras.txt states one): false after a `rigc: error:` line
// when a shot the manifest keeps but this run does not render was rendered at another scale.
bool check_one_scale(const Manifest& manifest, const ir::Scene& scene,
                     const std::vector<int>& selected, double scale, std::ostream& log);

// "\r[#####     ] 5/18 shot_004 0.42 s, about 6 s left": the progress bar a run redraws on a
// terminal.
std::string progress_line(int done, int total, const std::string& name, double seconds,
                          double seconds_left);

// "6 s", "2 min 10 s", "1 h 5 min": a time left, as a person reads it.
std::string time_left_text(double seconds);

// Writes the ground truth for every shot that has its image in the run folder: sparse/ (with
// points on the surface the shots see, run/ground_truth_points.h), transforms.json, bundle.out
// with bundle.list.txt, and cameras.csv; then the closing line. Returns the run's exit code: 2 if
// anything failed, else 0.
// (Seven parameters: the run's summary as the run loop ends it.)
int finish_run(const ir::Scene& scene, const Manifest& manifest,
               const std::filesystem::path& run_dir, double scale, int failures, size_t shots,
               std::ostream& log);

}  // namespace rigc::run
