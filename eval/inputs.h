// The first stage of `rigc eval`: find the images, read their headers, load the ground truth
// (mesh, and a run's planned cameras) and refuse inputs COLMAP cannot use, before anything is
// written.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <ostream>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "eval/camera_files.h"
#include "eval/eval.h"
#include "ir/ir.h"
#include "run/colmap_text.h"

namespace rigc::eval {

// The images to reconstruct and what their headers say.
struct ImageSet {
  std::filesystem::path dir;
  std::vector<std::string> names;                   // sorted
  std::map<std::string, std::pair<int, int>> size;  // width, height by image name
  std::set<std::string> wider_than_eight_bit;       // COLMAP 3.8 reads 8-bit images only
  bool one_size() const;
};

// The ground truth: a triangle mesh in the frame of the ground-truth cameras (the object frame
// for a run), and the run's planned cameras when it has them. Photos may come without a mesh
// (no triangles): then registration and the reference cameras are what is measured.
struct GroundTruth {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::string description;
  std::map<std::string, ir::Mat4> poses;    // camera_from_world by image name (sparse/images.txt)
  std::optional<run::ColmapCamera> camera;  // sparse/cameras.txt's first camera
  std::optional<ir::Vec3> backdrop_color;   // the scene's green screen (linear RGB), for keying
  // The scene's camera centres in the object frame, in shot order (from --scene or the run's
  // scene): photos taken as planned register from them.
  std::vector<ir::Vec3> planned_eyes;
};

// Everything evaluate() reads, checked.
struct EvalInputs {
  bool photos = false;            // a folder of photos, not a run folder
  std::filesystem::path run_dir;  // the run folder or the photos folder
  std::filesystem::path out;      // the output folder (created)
  ImageSet images;
  GroundTruth truth;
  // Photos: --reference-cameras, one for each photo (intrinsics' sizes filled from the photos).
  KnownCameras reference;
  std::string reference_description;  // "FILE (FORMAT)"; empty without reference cameras
  bool has_mesh() const { return !truth.triangles.empty(); }
};

// True when every image has a planned pose: the neighbours matcher can choose its pairs.
bool every_image_planned(const std::vector<std::string>& image_names,
                         const std::map<std::string, ir::Mat4>& planned_poses);

// The scene's camera centres in the object frame, in shot order (GroundTruth::planned_eyes).
std::vector<ir::Vec3> planned_eyes(const ir::Scene& scene);

// Checks the inputs and creates the output folder (only once they pass: a refused input leaves
// nothing behind). Errors go to `log`; nullopt means a user error (exit 1). Sets summary.images
// once the images are read and summary.output_dir once the folder exists.
std::optional<EvalInputs> gather_inputs(const EvalOptions& options, std::ostream& log,
                                        EvalSummary& summary);

}  // namespace rigc::eval
