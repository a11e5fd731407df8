#include "eval/known_poses.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <chrono>
#include <map>

#include "eval/align.h"
#include "eval/colmap_database.h"
#include "io/atomic_file.h"
#include "io/output_paths.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

std::string cameras_text(const DatabaseContents& db, const KnownCameras& reference,
                         std::string* error) {
  std::map<int, std::pair<int, int>> size;
  for (const auto& c : db.cameras) size[c.camera_id] = {c.width, c.height};
  std::map<int, std::string> lines;
  for (const auto& im : db.images) {
    if (lines.count(im.camera_id)) continue;
    const auto ref = reference.find(im.name);
    if (ref == reference.end() || !ref->second.intrinsics ||
        ref->second.intrinsics->params.size() < 3) {
      *error = fmt::format("{} has no reference camera with intrinsics", im.name);
      return {};
    }
    const auto [w, h] = size[im.camera_id];
    const ViewCamera k = view_camera(*ref->second.intrinsics, ir::Mat4::Identity());
    lines[im.camera_id] = fmt::format("{} PINHOLE {} {} {:.17g} {:.17g} {:.17g} {:.17g}\n",
                                      im.camera_id, w, h, k.fx, k.fy, k.cx, k.cy);
  }
  std::string text = "# The reference cameras' intrinsics (rigc eval --reference-cameras)\n";
  for (const auto& [id, line] : lines) text += line;
  return text;
}

std::string images_text(const DatabaseContents& db, const KnownCameras& reference,
                        std::string* error) {
  std::string text = "# The reference cameras' poses (rigc eval --reference-cameras)\n";
  for (const auto& im : db.images) {
    const auto ref = reference.find(im.name);
    if (ref == reference.end()) {
      *error = fmt::format("{} has no reference camera", im.name);
      return {};
    }
    const ir::Mat4& pose = ref->second.camera_from_world;
    const Eigen::Quaterniond q(Eigen::Matrix3d(pose.topLeftCorner<3, 3>()));
    text += fmt::format("{} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {:.17g} {} {}\n\n",
                        im.image_id, q.w(), q.x(), q.y(), q.z(), pose(0, 3), pose(1, 3), pose(2, 3),
                        im.camera_id, im.name);
  }
  return text;
}

}  // namespace

bool write_known_model(const fs::path& database, const KnownCameras& reference,
                       const fs::path& model_dir, std::string* error) {
  const auto db = read_colmap_database(database, error);
  if (!db) return false;
  std::string why;
  const std::string cameras = cameras_text(*db, reference, &why);
  const std::string images = why.empty() ? images_text(*db, reference, &why) : "";
  if (!why.empty()) {
    *error = fmt::format("cannot hold the cameras at the reference: {}", why);
    return false;
  }
  std::error_code ec;
  fs::create_directories(model_dir, ec);
  return write_file_atomically(model_dir / "cameras.txt", cameras, error) &&
         write_file_atomically(model_dir / "images.txt", images, error) &&
         write_file_atomically(model_dir / "points3D.txt", "", error);
}

ColmapRun triangulate_known_poses(const EvalOptions& o, const EvalInputs& in, const ColmapRun& sfm,
                                  std::ostream& log) {
  ColmapRun r;
  r.images_dir = sfm.images_dir;
  const fs::path work = in.out / "colmap" / "known_poses";
  const fs::path logs = in.out / "logs";
  std::error_code ec;
  std::string error;
  if (!clear_output_folder(work, &error)) {
    r.exit_code = 1;
    r.failure = error;
    return r;
  }
  fs::create_directories(work / "model", ec);
  if (!write_known_model(in.out / "colmap" / "database.db", in.reference, work / "input", &error)) {
    r.exit_code = 1;
    r.failure = error;
    return r;
  }
  using Argv = std::vector<std::string>;
  const std::vector<std::pair<std::string, Argv>> steps = {
      {"point_triangulator",
       {o.sfm.colmap, "point_triangulator", "--database_path",
        (in.out / "colmap" / "database.db").string(), "--image_path", sfm.images_dir.string(),
        "--input_path", (work / "input").string(), "--output_path", (work / "model").string(),
        "--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
        "--Mapper.ba_refine_extra_params", "0"}},
      {"model_converter (known poses)",
       {o.sfm.colmap, "model_converter", "--input_path", (work / "model").string(), "--output_path",
        (work / "model_txt").string(), "--output_type", "TXT"}}};
  fs::create_directories(work / "model_txt", ec);
  for (const auto& [name, argv] : steps) {
    const fs::path step_log = logs / (argv[1] + "_known_poses.log");
    if (!o.quiet) log << fmt::format("rigc eval: colmap {} ...\n", name);
    const auto t0 = std::chrono::steady_clock::now();
    double cpu_s = 0;
    const int rc = run_logged(argv, step_log, &error, &cpu_s);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    r.seconds += s;
    r.steps.push_back({{"name", name},
                       {"seconds", s},
                       {"cpu_seconds", cpu_s},
                       {"exit_code", rc},
                       {"log", step_log.string()}});
    if (rc != 0) {
      r.exit_code = 2;
      r.failure = rc < 0 ? error
                         : fmt::format("colmap {} failed (exit {}); see {}", argv[1], rc,
                                       step_log.string());
      return r;
    }
  }
  r.model_txt = work / "model_txt";
  r.ok = true;
  return r;
}

}  // namespace rigc::eval
