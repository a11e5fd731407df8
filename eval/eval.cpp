#include "eval/eval.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <regex>
#include <set>
#include <sstream>

#include "assets/mesh_io.h"
#include "compiler/frontend.h"
#include "eval/colmap.h"
#include "eval/geometry.h"
#include "eval/metrics.h"
#include "io/files.h"
#include "run/colmap_text.h"
#include "run/manifest.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

bool is_image_file(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".jpg" || ext == ".jpeg" || ext == ".png" || ext == ".tif" || ext == ".tiff";
}

std::vector<std::string> list_images(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.is_regular_file() && is_image_file(e.path())) names.push_back(e.path().filename());
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The ground truth: a triangle mesh in the frame of the ground-truth cameras.
struct GroundTruth {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::string description;
};

// `warning` is set when the run's images were rendered from another version of the scene.
std::optional<GroundTruth> load_ground_truth(const EvalOptions& o, const fs::path& run_dir,
                                             bool photos, std::string* error,
                                             std::string* warning) {
  GroundTruth gt;
  if (!o.ground_truth.empty()) {
    auto model = load_model(o.ground_truth, error);
    if (!model) return std::nullopt;
    gt.positions = std::move(model->mesh.positions);
    gt.triangles = std::move(model->mesh.triangles);
    gt.description = fmt::format("{} (its own frame)", o.ground_truth);
  } else {
    std::string scene_path = o.scene;
    const fs::path manifest = run_dir / "manifest.json";
    const json run_manifest = photos ? json() : json::parse(read_text(manifest), nullptr, false);
    const json& m = run_manifest;
    if (scene_path.empty()) {
      if (!fs::exists(manifest)) {
        *error = fmt::format(
            "no ground truth: {} has no manifest.json naming its scene; pass --ground-truth MESH "
            "or --scene FILE",
            run_dir.string());
        return std::nullopt;
      }
      if (m.is_discarded()) {
        *error = fmt::format(
            "no ground truth: {} is not valid JSON; pass --ground-truth MESH or --scene FILE",
            manifest.string());
        return std::nullopt;
      }
      if (!m.is_object() || !m.contains("inputs") || !m["inputs"].is_object() ||
          !m["inputs"].contains("source_file") || !m["inputs"]["source_file"].is_string()) {
        *error = fmt::format(
            "no ground truth: {} has no inputs.source_file; pass --ground-truth MESH or --scene "
            "FILE",
            manifest.string());
        return std::nullopt;
      }
      scene_path = m["inputs"]["source_file"].get<std::string>();
      if (fs::path(scene_path).is_relative() && !fs::exists(scene_path)) {
        *error = fmt::format(
            "no ground truth: the run's scene '{}' (manifest.json, relative to where it was "
            "rendered) is not found from here; pass --scene FILE or --ground-truth MESH",
            scene_path);
        return std::nullopt;
      }
    }
    DiagnosticEngine diag;
    std::string messages;
    diag.set_handler([&](const Diagnostic& d, const std::string& text) {
      if (d.severity == Severity::kError) messages += text;
    });
    auto scene = compile_scene_file(scene_path, diag);
    if (!scene) {
      *error = fmt::format("cannot compile the scene {} for its ground truth:\n{}", scene_path,
                           messages);
      return std::nullopt;
    }
    gt.positions = ir::object_frame_positions(scene->object);
    gt.triangles = scene->object.mesh.triangles;
    gt.description = fmt::format("{} object ({}), object frame", scene_path, scene->object.source);
    // A run measured against an object it was not rendered from gives numbers without meaning
    // (another object: F-score 0, and no word of why). Runs record the object's surface.
    if (m.is_object() && m.contains("inputs") && m["inputs"].is_object() &&
        m["inputs"].contains("object_sha256") && m["inputs"]["object_sha256"].is_string() &&
        m["inputs"]["object_sha256"].get<std::string>() != run::object_geometry_hash(*scene)) {
      *warning = fmt::format(
          "the object of {} is not the one the run in {} was rendered with (its surface differs "
          "from manifest.json's object_sha256): the numbers measure against another object",
          scene_path, run_dir.string());
    }
  }
  if (gt.triangles.empty()) {
    *error = "the ground-truth mesh has no triangles";
    return std::nullopt;
  }
  return gt;
}

ViewCamera view_camera(const run::ColmapCamera& cam, const ir::Mat4& camera_from_world) {
  ViewCamera v;
  v.camera_from_world = camera_from_world;
  v.width = cam.width;
  v.height = cam.height;
  const auto& p = cam.params;
  if (cam.model == "SIMPLE_PINHOLE" || cam.model == "SIMPLE_RADIAL" || cam.model == "RADIAL") {
    v.fx = v.fy = p.at(0);
    v.cx = p.at(1);
    v.cy = p.at(2);
  } else {
    v.fx = p.at(0);
    v.fy = p.at(1);
    v.cx = p.at(2);
    v.cy = p.at(3);
  }
  return v;
}

ir::Vec3 camera_centre(const ir::Mat4& camera_from_world) {
  return -camera_from_world.topLeftCorner<3, 3>().transpose() *
         camera_from_world.topRightCorner<3, 1>();
}

double rotation_angle_deg(const Eigen::Matrix3d& r) {
  const double c = std::clamp((r.trace() - 1) / 2, -1.0, 1.0);
  return std::acos(c) * 180 / M_PI;
}

json stats_json(const DistanceStats& s) {
  return {{"count", s.count},   {"mean", s.mean},       {"std", s.stddev},
          {"median", s.median}, {"p90_abs", s.p90_abs}, {"mean_abs", s.mean_abs},
          {"rms", s.rms},       {"min", s.min},         {"max", s.max}};
}

json similarity_json(const Similarity& s) {
  json m = json::array();
  const Mat4 x = s.matrix();
  for (int r = 0; r < 4; ++r) m.push_back({x(r, 0), x(r, 1), x(r, 2), x(r, 3)});
  return {{"scale", s.scale}, {"matrix", m}};
}

// Mean "Features: N" of COLMAP's feature_extractor log (3.8 prints one per image).
std::optional<double> mean_features(const fs::path& log) {
  std::ifstream in(log);
  std::string line;
  static const std::regex re(R"(^\s*Features:\s*(\d+))");
  double sum = 0;
  int n = 0;
  std::smatch m;
  while (std::getline(in, line)) {
    if (std::regex_search(line, m, re)) {
      sum += std::stod(m[1]);
      ++n;
    }
  }
  if (n == 0) return std::nullopt;
  return sum / n;
}

struct ColmapRun {
  bool ok = false;
  int exit_code = 0;  // 0 ok, 2 failure
  std::string failure;
  json steps = json::array();
  double seconds = 0;
  fs::path model_txt;
  json prior;
  json matching = json::object();  // which matcher, how many pairs and how they were chosen
  bool reused = false;             // --reuse-colmap found a model: the times are the earlier run's
};

// True when every image has a planned pose (the run's sparse/images.txt): the neighbours matcher
// can choose its pairs.
bool every_image_planned(const std::vector<std::string>& image_names,
                         const std::map<std::string, ir::Mat4>& planned_poses) {
  return std::all_of(image_names.begin(), image_names.end(),
                     [&](const std::string& name) { return planned_poses.count(name) > 0; });
}

// Features, matches, mapper, text export of the largest model.
// What the image headers said, read once before COLMAP runs.
struct ImageSet {
  std::map<std::string, std::pair<int, int>> size;  // width, height by image name
  std::set<std::string> wider_than_eight_bit;       // COLMAP 3.8 reads 8-bit images only
  bool one_size() const {
    return std::all_of(size.begin(), size.end(),
                       [&](const auto& entry) { return entry.second == size.begin()->second; });
  }
};

// Puts every image of `from` into `to` under the same name, 8 bits a channel: COLMAP 3.8 cannot
// read the 16-bit PNG and TIFF that a camera's `output: {format: png16}` writes (its matcher then
// aborted), and its SIFT works on 8-bit grey anyway. 8-bit files are copied as they are (a JPEG
// is not encoded twice). False with `error` when an image's pixels cannot be read (its header
// could: the input is at fault) or a copy cannot be written.
bool write_eight_bit_copies(const fs::path& from, const fs::path& to, const ImageSet& set,
                            bool* input_fault, std::string* error) {
  std::error_code ec;
  fs::create_directories(to, ec);
  for (const auto& [name, size] : set.size) {
    if (!set.wider_than_eight_bit.count(name)) {
      fs::copy_file(from / name, to / name, fs::copy_options::overwrite_existing, ec);
      if (ec) {
        *error = fmt::format("cannot copy {} for COLMAP: {}", (from / name).string(), ec.message());
        return false;
      }
      continue;
    }
    OIIO::ImageBuf image((from / name).string());
    if (!image.read(0, 0, true, OIIO::TypeDesc::UINT8)) {
      *input_fault = true;
      *error =
          fmt::format("cannot read the pixels of {}: {}", (from / name).string(), image.geterror());
      return false;
    }
    if (!image.write((to / name).string(), OIIO::TypeDesc::UINT8)) {
      *error = fmt::format("cannot write an 8-bit copy of {} for COLMAP: {}",
                           (from / name).string(), image.geterror());
      return false;
    }
  }
  return true;
}

ColmapRun run_colmap(const EvalOptions& o, const fs::path& given_images_dir, const ImageSet& set,
                     const fs::path& run_dir, const fs::path& out,
                     const std::vector<std::string>& image_names,
                     const std::map<std::string, ir::Mat4>& planned_poses, std::ostream& log) {
  ColmapRun r;
  const int image_count = static_cast<int>(image_names.size());
  const fs::path work = out / "colmap";
  const fs::path logs = out / "logs";
  const fs::path txt = work / "model_txt";
  std::error_code ec;
  if (o.reuse_colmap && fs::exists(txt / "points3D.txt")) {
    r.ok = true;
    r.reused = true;
    r.model_txt = txt;
    json previous = json::parse(read_text(out / "eval.json"), nullptr, false);
    if (!previous.is_discarded() && previous.contains("colmap") && previous["colmap"].is_object()) {
      r.steps = previous["colmap"].value("steps", json::array());
      r.seconds = previous["colmap"].value("seconds", 0.0);
      r.prior = previous["colmap"].value("intrinsics_prior", json());
      r.matching = previous["colmap"].value("matching", json::object());
      if (!r.matching.is_object()) r.matching = json::object();
    }
    if (!o.quiet) log << "rigc eval: reusing the COLMAP model in " << txt.string() << "\n";
    return r;
  }
  fs::remove_all(work, ec);
  fs::create_directories(work / "sparse", ec);
  fs::create_directories(logs, ec);
  std::string error;
  fs::path images_dir = given_images_dir;
  if (!set.wider_than_eight_bit.empty()) {
    images_dir = work / "images_8bit";
    if (!o.quiet)
      log << "rigc eval: 8-bit copies of the images for COLMAP in " << images_dir.string() << "\n";
    bool input_fault = false;
    if (!write_eight_bit_copies(given_images_dir, images_dir, set, &input_fault, &error)) {
      r.exit_code = input_fault ? 1 : 2;
      r.failure = error;
      return r;
    }
  }
  auto flags = probe_colmap(o.colmap, logs, &error);
  if (!flags) {
    r.exit_code = 2;
    r.failure = error;
    return r;
  }
  const fs::path db = work / "database.db";
  std::vector<std::string> fe = {o.colmap, "feature_extractor", "--database_path", db.string(),
                                 "--image_path", images_dir.string(), "--ImageReader.single_camera",
                                 // One camera for photos of one size; COLMAP refuses a single
                                 // camera over images of different sizes.
                                 set.one_size() ? "1" : "0"};
  if (!flags->extraction_gpu.empty()) {
    fe.push_back(flags->extraction_gpu);
    fe.push_back("0");
  }
  // The intrinsics prior: the run's ground-truth camera (exact), else COLMAP reads EXIF.
  bool exact_prior = false;
  std::string why;
  auto cams = run::read_colmap_cameras(run_dir / "sparse" / "cameras.txt", &why);
  if (cams && !cams->empty()) {
    const auto& c = cams->front();
    std::string params;
    for (double v : c.params) params += (params.empty() ? "" : ",") + fmt::format("{:.17g}", v);
    fe.insert(fe.end(),
              {"--ImageReader.camera_model", c.model, "--ImageReader.camera_params", params});
    exact_prior = true;
    r.prior = {{"source", (run_dir / "sparse" / "cameras.txt").string()},
               {"model", c.model},
               {"params", c.params},
               {"refined_by_colmap", o.refine_intrinsics}};
  } else {
    fe.insert(fe.end(), {"--ImageReader.camera_model", "OPENCV"});
    r.prior = {{"source", "EXIF focal length, read by COLMAP"},
               {"model", "OPENCV"},
               {"refined_by_colmap", true}};
  }
  const fs::path masks = run_dir / "masks";
  if (o.use_masks && fs::is_directory(masks)) {
    // COLMAP wants masks/<image name>.png; zero pixels are ignored.
    const fs::path mask_dir = work / "masks";
    fs::create_directories(mask_dir, ec);
    int linked = 0;
    for (const auto& name : list_images(images_dir)) {
      const fs::path src = masks / (fs::path(name).stem().string() + ".png");
      if (!fs::exists(src)) continue;
      fs::create_symlink(fs::absolute(src), mask_dir / (name + ".png"), ec);
      if (!ec) ++linked;
    }
    if (linked > 0) {
      fe.insert(fe.end(), {"--ImageReader.mask_path", mask_dir.string()});
      r.prior["masks"] = masks.string();
    }
  }
  // Matching costs about features^2 per pair on the CPU: with a capture plan, match only the
  // views that can overlap.
  std::string matcher = o.matcher;
  const bool planned = every_image_planned(image_names, planned_poses);
  if (matcher == "auto") {
    matcher = planned && flags->imports_pair_lists ? "neighbours"
              : image_count > 100                  ? "sequential"
                                                   : "exhaustive";
  }
  const long all_pairs = static_cast<long>(image_count) * (image_count - 1) / 2;
  r.matching = {{"matcher", matcher}, {"all_pairs", all_pairs}};
  std::vector<std::string> match;
  if (matcher == "neighbours") {
    if (!flags->imports_pair_lists) {
      r.exit_code = 2;
      r.failure = fmt::format(
          "this COLMAP's matches_importer takes no pair list (see {}); use --matcher exhaustive",
          (logs / "colmap_probe.log").string());
      return r;
    }
    NeighbourPairOptions rule;
    rule.max_angle_deg = o.neighbour_angle_deg;
    std::vector<ir::Vec3> axes;
    for (const auto& name : image_names) {
      // The optical axis (camera +Z) in the world: the third row of camera_from_world's rotation.
      axes.push_back(planned_poses.at(name).block<1, 3>(2, 0).transpose());
    }
    const auto pairs = neighbour_pairs(axes, rule);
    const fs::path pair_list = work / "pairs.txt";
    if (!write_pair_list(pair_list, image_names, pairs, &error)) {
      r.exit_code = 2;
      r.failure = error;
      return r;
    }
    match = {o.colmap,
             "matches_importer",
             "--database_path",
             db.string(),
             "--match_list_path",
             pair_list.string(),
             "--match_type",
             "pairs"};
    r.matching["pairs"] = pairs.size();
    r.matching["pair_list"] = pair_list.string();
    r.matching["rule"] = fmt::format(
        "planned poses ({}): views whose optical axes are at most {} deg apart, the nearest {} "
        "at most, the nearest {} at least",
        (run_dir / "sparse" / "images.txt").string(), rule.max_angle_deg, rule.max_per_image,
        rule.min_per_image);
  } else {
    match = {o.colmap, matcher + "_matcher", "--database_path", db.string()};
    if (matcher == "exhaustive") r.matching["pairs"] = all_pairs;
  }
  if (!flags->matching_gpu.empty()) {
    match.push_back(flags->matching_gpu);
    match.push_back("0");
  }
  std::vector<std::string> map = {o.colmap, "mapper", "--database_path", db.string(),
                                  "--image_path", images_dir.string(), "--output_path",
                                  (work / "sparse").string(),
                                  // COLMAP 3.8 drops a model of fewer than min(images, 10)
                                  // registered images: a ring with one photo lost registers in
                                  // parts, and "reconstructed nothing" though it had built 5 of 9.
                                  "--Mapper.min_model_size", "3"};
  if (exact_prior && !o.refine_intrinsics) {
    // A known camera: refining focal length and distortion from two narrow-angle views of a
    // small object is ill-conditioned and can stop the reconstruction at its first pair.
    map.insert(map.end(),
               {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point", "0",
                "--Mapper.ba_refine_extra_params", "0"});
  }
  struct Step {
    std::string name;
    std::vector<std::string> argv;
  };
  const std::vector<Step> steps = {{"feature_extractor", fe}, {match[1], match}, {"mapper", map}};
  for (const auto& step : steps) {
    const fs::path step_log = logs / (step.name + ".log");
    fs::remove(step_log, ec);
    if (!o.quiet) log << fmt::format("rigc eval: colmap {} ...\n", step.name);
    const auto t0 = Clock::now();
    double cpu_s = 0;
    const int rc = run_logged(step.argv, step_log, &error, &cpu_s);
    const double s = seconds_since(t0);
    r.seconds += s;
    r.steps.push_back({{"name", step.name},
                       {"seconds", s},
                       {"cpu_seconds", cpu_s},
                       {"exit_code", rc},
                       {"log", step_log.string()}});
    if (step.name == "feature_extractor") {
      if (const auto features = mean_features(step_log)) {
        r.matching["mean_features_per_image"] = *features;
      }
    }
    if (rc != 0 && step.name != "mapper") {
      r.exit_code = 2;
      r.failure = rc < 0 ? error
                         : fmt::format("colmap {} failed (exit {}); see {}", step.name, rc,
                                       step_log.string());
      return r;
    }
  }
  // The mapper may write several models (sparse/0, sparse/1, ...): keep the largest.
  fs::path best;
  std::size_t best_images = 0;
  const auto t_convert = Clock::now();
  double convert_cpu_s = 0;
  for (const auto& e : fs::directory_iterator(work / "sparse", ec)) {
    if (!e.is_directory()) continue;
    const fs::path tmp = work / ("txt_" + e.path().filename().string());
    fs::create_directories(tmp, ec);
    const fs::path conv_log = logs / "model_converter.log";
    double cpu_s = 0;
    const int rc = run_logged({o.colmap, "model_converter", "--input_path", e.path().string(),
                               "--output_path", tmp.string(), "--output_type", "TXT"},
                              conv_log, &error, &cpu_s);
    convert_cpu_s += cpu_s;
    if (rc != 0) continue;
    auto images = run::read_colmap_images(tmp / "images.txt", &why);
    if (images && images->size() > best_images) {
      best_images = images->size();
      best = tmp;
    }
  }
  const double convert_s = seconds_since(t_convert);
  r.seconds += convert_s;
  r.steps.push_back({{"name", "model_converter"},
                     {"seconds", convert_s},
                     {"cpu_seconds", convert_cpu_s},
                     {"log", (logs / "model_converter.log").string()}});
  if (best.empty()) {
    r.exit_code = 2;
    const fs::path fe_log = logs / "feature_extractor.log";
    const auto features = mean_features(fe_log);
    r.failure = fmt::format(
        "COLMAP reconstructed nothing from {} images{}: no initial image pair (too few features "
        "or matches: the object may need more texture, or the shots more overlap); see {}",
        image_count,
        features ? fmt::format(" ({:.0f} features per image on average)", *features) : "",
        (logs / "mapper.log").string());
    return r;
  }
  fs::rename(best, txt, ec);
  r.model_txt = ec ? best : txt;
  r.ok = true;
  return r;
}

}  // namespace

int evaluate(const EvalOptions& o, std::ostream& log, EvalSummary* summary) {
  const auto t_start = Clock::now();
  EvalSummary local;
  EvalSummary& sum = summary ? *summary : local;
  const bool photos = !o.photos_dir.empty();
  const fs::path run_dir = photos ? fs::path(o.photos_dir) : fs::path(o.run_dir);
  fs::path images_dir = run_dir / "images";
  if (photos && !fs::is_directory(images_dir)) images_dir = run_dir;
  std::error_code exists_ec;
  if (!fs::exists(run_dir, exists_ec)) {
    log << fmt::format("rigc eval: error: {} does not exist\n", run_dir.string());
    return 1;
  }
  if (!fs::is_directory(images_dir)) {
    log << fmt::format("rigc eval: error: {} has no images/ folder (is it a run folder?)\n",
                       run_dir.string());
    return 1;
  }
  const std::vector<std::string> image_names = list_images(images_dir);
  if (image_names.size() < 2) {
    log << fmt::format("rigc eval: error: {} has {} image(s); SfM needs at least 2\n",
                       images_dir.string(), image_names.size());
    return 1;
  }
  // Each image's header, read before COLMAP runs: its feature extractor only logs a file it
  // cannot read, and a folder with such files ended in the matcher aborting (exit 134) without a
  // word of which file it was.
  std::vector<std::string> unreadable;
  ImageSet image_set;
  for (const auto& name : image_names) {
    if (auto input = OIIO::ImageInput::open((images_dir / name).string())) {
      const OIIO::ImageSpec& spec = input->spec();
      image_set.size[name] = {spec.width, spec.height};
      if (spec.format != OIIO::TypeDesc::UINT8) image_set.wider_than_eight_bit.insert(name);
      continue;
    }
    std::string why = OIIO::geterror();
    std::replace(why.begin(), why.end(), '\n', ' ');
    unreadable.push_back(fmt::format("{}: {}", (images_dir / name).string(), why));
  }
  if (!unreadable.empty()) {
    log << fmt::format(
        "rigc eval: error: {} of the {} images cannot be read; remove or replace "
        "{}:\n",
        unreadable.size(), image_names.size(), unreadable.size() == 1 ? "it" : "them");
    constexpr std::size_t kListed = 10;
    for (std::size_t i = 0; i < std::min(kListed, unreadable.size()); ++i) {
      log << "  " << unreadable[i] << '\n';
    }
    if (unreadable.size() > kListed)
      log << fmt::format("  and {} more\n", unreadable.size() - kListed);
    return 1;
  }
  const fs::path out = o.output_dir.empty() ? run_dir / "eval" : fs::path(o.output_dir);
  sum.images = static_cast<int>(image_names.size());
  std::string error;

  // Ground truth: mesh, and camera poses when the run has them (world = object frame).
  if (photos && o.ground_truth.empty() && o.scene.empty()) {
    log << "rigc eval: error: photos need a ground truth: --ground-truth MESH or --scene FILE\n";
    return 1;
  }
  std::string gt_warning;
  auto gt = load_ground_truth(o, run_dir, photos, &error, &gt_warning);
  if (!gt) {
    log << "rigc eval: error: " << error << "\n";
    return 1;
  }
  if (!gt_warning.empty()) log << "rigc eval: warning: " << gt_warning << "\n";
  std::map<std::string, ir::Mat4> gt_poses;
  std::optional<run::ColmapCamera> gt_camera;
  if (!photos && fs::exists(run_dir / "sparse" / "images.txt")) {
    auto images = run::read_colmap_images(run_dir / "sparse" / "images.txt", &error);
    auto cams = run::read_colmap_cameras(run_dir / "sparse" / "cameras.txt", &error);
    if (!images || !cams || cams->empty()) {
      log << "rigc eval: error: " << error << "\n";
      return 1;
    }
    for (const auto& im : *images) gt_poses[im.name] = im.camera_from_world;
    gt_camera = cams->front();
    // COLMAP takes this camera as every image's intrinsics: a size that is not the images' own
    // tripped an assertion in OpenImageIO (a height of 3) or took 24 GB (a height of 547000).
    for (const auto& [name, size] : image_set.size) {
      if (size != std::pair{gt_camera->width, gt_camera->height}) {
        log << fmt::format(
            "rigc eval: error: {} is {}x{} pixels, but {} gives the camera as {}x{}\n",
            (images_dir / name).string(), size.first, size.second,
            (run_dir / "sparse" / "cameras.txt").string(), gt_camera->width, gt_camera->height);
        return 1;
      }
    }
  }
  // SIFT finds nothing in a thumbnail: two 1 x 1 photos ended in "COLMAP reconstructed
  // nothing", exit 2, as if a tool had failed.
  constexpr int kSmallestSide = 32;
  for (const auto& [name, size] : image_set.size) {
    if (std::min(size.first, size.second) < kSmallestSide) {
      log << fmt::format(
          "rigc eval: error: {} is {}x{} pixels: too small to find features in (at least {} a "
          "side)\n",
          (images_dir / name).string(), size.first, size.second, kSmallestSide);
      return 1;
    }
  }
  if (!image_set.one_size() && !o.quiet) {
    log << "rigc eval: the photos differ in size: COLMAP gets one camera per photo\n";
  }
  if (o.matcher == "neighbours" && !every_image_planned(image_names, gt_poses)) {
    log << fmt::format(
        "rigc eval: error: --matcher neighbours needs a planned pose for every image (a run "
        "folder's sparse/images.txt); {} has images without one\n",
        images_dir.string());
    return 1;
  }

  // Made only now that the inputs have passed their checks: a refused input leaves nothing
  // behind (in photos mode the folder would sit among the user's photos).
  std::error_code ec;
  fs::create_directories(out, ec);
  if (!fs::is_directory(out)) {
    log << fmt::format("rigc eval: error: cannot create the output folder {}\n", out.string());
    return 1;
  }
  sum.output_dir = out.string();

  json report;
  report["rigc_eval_version"] = 1;
  report["input"] = {{"images_dir", images_dir.string()},
                     {"images", image_names.size()},
                     {"kind", photos ? "photos" : "run"},
                     {"ground_truth", gt->description},
                     {"ground_truth_triangles", gt->triangles.size()},
                     {"ground_truth_poses", !gt_poses.empty()}};

  // 1. COLMAP.
  const double setup_s = seconds_since(t_start);  // ground truth and poses
  ColmapRun colmap = run_colmap(o, images_dir, image_set, run_dir, out, image_names, gt_poses, log);
  report["colmap"] = {{"steps", colmap.steps},
                      {"seconds", colmap.seconds},
                      {"matching", colmap.matching},
                      {"intrinsics_prior", colmap.prior}};
  sum.colmap_s = colmap.seconds;
  auto write_report = [&]() {
    std::string why;
    if (!rigc::write_file_atomically(out / "eval.json", report.dump(2) + "\n", &why)) {
      log << "rigc eval: error: " << why << "\n";
      return false;
    }
    sum.report = report;
    return true;
  };
  if (!colmap.ok) {
    sum.failure = colmap.failure;
    report["reconstruction"] = {{"status", "failed"}, {"reason", colmap.failure}};
    write_report();
    log << "rigc eval: error: " << colmap.failure << "\n";
    return colmap.exit_code ? colmap.exit_code : 2;
  }
  const auto t_rigc = Clock::now();
  auto model = read_sparse_model(colmap.model_txt, &error);
  if (!model) {
    sum.failure = error;
    report["reconstruction"] = {{"status", "failed"}, {"reason", error}};
    write_report();
    log << "rigc eval: error: " << error << "\n";
    return 2;
  }
  sum.reconstructed = true;
  sum.registered = static_cast<int>(model->images.size());
  sum.points = static_cast<long>(model->points.size());
  report["reconstruction"] = {{"status", "ok"},
                              {"model", colmap.model_txt.string()},
                              {"images", image_names.size()},
                              {"registered_images", model->images.size()},
                              {"points", model->points.size()},
                              {"mean_track_length", model->mean_track_length()},
                              {"mean_reprojection_error_px", model->mean_reprojection_error()}};
  if (!o.quiet) {
    log << fmt::format(
        "rigc eval: COLMAP: {}/{} images registered, {} points, track {:.2f}, reprojection "
        "{:.3f} px ({:.1f} s)\n",
        model->images.size(), image_names.size(), model->points.size(), model->mean_track_length(),
        model->mean_reprojection_error(), colmap.seconds);
  }
  if (model->points.size() < 3) {
    sum.failure = "the reconstruction has fewer than 3 points";
    report["reconstruction"]["status"] = "failed";
    report["reconstruction"]["reason"] = sum.failure;
    write_report();
    log << "rigc eval: error: " << sum.failure << "\n";
    return 2;
  }

  Surface surface(gt->positions, gt->triangles);
  const Eigen::AlignedBox3d box = surface.bounds();
  const double diag = box.diagonal().norm();
  std::vector<Vec3> rec_points;
  std::map<int, Vec3> rec_centre_by_image;
  for (const auto& p : model->points) rec_points.push_back(p.position);
  for (const auto& im : model->images)
    rec_centre_by_image[im.image_id] = camera_centre(im.camera_from_world);

  // 2. Alignment.
  Similarity align;
  json alignment;
  std::vector<ViewCamera> gt_views;
  if (!gt_poses.empty()) {
    std::vector<Vec3> src, dst;
    std::vector<std::string> names;
    for (const auto& im : model->images) {
      auto it = gt_poses.find(im.name);
      if (it == gt_poses.end()) continue;
      src.push_back(camera_centre(im.camera_from_world));
      dst.push_back(camera_centre(it->second));
      names.push_back(im.name);
    }
    for (const auto& [name, pose] : gt_poses) gt_views.push_back(view_camera(*gt_camera, pose));
    Vec3 centroid = Vec3::Zero();
    for (const auto& d : dst) centroid += d;
    if (!dst.empty()) centroid /= static_cast<double>(dst.size());
    double spread = 0;
    for (const auto& d : dst) spread += (d - centroid).squaredNorm();
    spread = dst.empty() ? 0 : std::sqrt(spread / static_cast<double>(dst.size()));
    auto robust = fit_similarity_ransac(src, dst, std::max(0.02 * spread, 1e-6), 2000, 1);
    if (!robust) {
      sum.failure = fmt::format(
          "cannot align: fewer than 3 registered images have a ground-truth pose ({} matched)",
          src.size());
      report["alignment"] = {{"status", "failed"}, {"reason", sum.failure}};
      write_report();
      log << "rigc eval: error: " << sum.failure << "\n";
      return 2;
    }
    align = robust->transform;
    alignment = {{"method", "Umeyama similarity in RANSAC on camera centres"},
                 {"cameras", src.size()},
                 {"inliers", robust->inliers.size()},
                 {"rms_camera_error_mm", robust->rms_inlier_error * 1000}};
  } else {
    // Photos: no poses. Scale from the spread of the clouds, then FPFH + RANSAC, then ICP with
    // scale.
    std::vector<Vec3> samples, normals;
    surface.sample(50000, 3, &samples, &normals);
    auto robust_radius = [](const std::vector<Vec3>& pts) {
      Vec3 c = Vec3::Zero();
      for (const auto& p : pts) c += p;
      c /= static_cast<double>(pts.size());
      std::vector<double> r;
      for (const auto& p : pts) r.push_back((p - c).norm());
      std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
      return std::make_pair(c, r[r.size() / 2]);
    };
    const auto [c_rec, r_rec] = robust_radius(rec_points);
    const auto [c_gt, r_gt] = robust_radius(samples);
    Similarity pre;
    pre.scale = r_gt / std::max(r_rec, 1e-12);
    pre.translation = c_gt - pre.scale * c_rec;
    std::vector<Vec3> moved;
    for (const auto& p : rec_points) moved.push_back(pre.apply(p));
    auto global = global_registration(moved, samples, diag / 40);
    if (!global) {
      sum.failure = "global registration found no alignment of the reconstruction to the mesh";
      report["alignment"] = {{"status", "failed"}, {"reason", sum.failure}};
      write_report();
      log << "rigc eval: error: " << sum.failure << "\n";
      return 2;
    }
    Similarity g = Similarity::from_matrix(*global) * pre;
    for (auto& p : moved) p = Similarity::from_matrix(*global).apply(p);
    const IcpResult scaled = icp_similarity(moved, samples, diag / 50, 60);
    align = Similarity::from_matrix(scaled.transform) * g;
    alignment = {{"method", "scale from cloud spread, FPFH + RANSAC (Open3D), ICP with scale"},
                 {"icp_with_scale_fitness", scaled.fitness}};
  }

  // Points in the ground-truth frame; keep those near the object (the rest is background).
  std::vector<Vec3> aligned;
  for (const auto& p : rec_points) aligned.push_back(align.apply(p));
  Eigen::AlignedBox3d crop = box;
  crop.extend(box.min() - Vec3::Constant(0.05 * diag));
  crop.extend(box.max() + Vec3::Constant(0.05 * diag));

  // Visible ground-truth samples (from the ground-truth cameras, else the aligned reconstructed
  // ones): Tanks and Temples' recall reference and the ICP target.
  std::vector<Vec3> samples, normals;
  surface.sample(o.ground_truth_samples, 7, &samples, &normals);
  if (gt_views.empty() && !model->cameras.empty()) {
    const auto& cam = model->cameras.front();
    const Similarity inv = align.inverse();
    for (const auto& im : model->images) {
      // camera_from_gt = camera_from_rec * rec_from_gt, made rigid (scale goes into t).
      Mat4 c = Mat4::Identity();
      c.topLeftCorner<3, 3>() = im.camera_from_world.topLeftCorner<3, 3>() * inv.rotation;
      c.topRightCorner<3, 1>() = im.camera_from_world.topLeftCorner<3, 3>() * inv.translation +
                                 im.camera_from_world.topRightCorner<3, 1>();
      c.topRightCorner<3, 1>() /= inv.scale;
      gt_views.push_back(view_camera(cam, c));
    }
  }
  std::vector<Vec3> visible_samples, visible_normals;
  for (int i : surface.visible(samples, normals, gt_views)) {
    visible_samples.push_back(samples[i]);
    visible_normals.push_back(normals[i]);
  }

  if (o.icp) {
    std::vector<Vec3> inside;
    for (const auto& p : aligned) {
      if (crop.contains(p)) inside.push_back(p);
    }
    // ICP needs no more than 100k points to settle a rigid transform.
    if (inside.size() > 100000) {
      const std::size_t stride = (inside.size() + 99999) / 100000;
      std::size_t k = 0;
      for (std::size_t i = 0; i < inside.size(); i += stride) inside[k++] = inside[i];
      inside.resize(k);
    }
    const std::vector<Vec3>& target = visible_samples.empty() ? samples : visible_samples;
    const std::vector<Vec3>& target_n = visible_samples.empty() ? normals : visible_normals;
    const IcpResult icp = icp_point_to_plane(inside, target, target_n, 0.01 * diag, 50);
    json j = {{"method", "point-to-plane ICP (Open3D) on the visible ground-truth samples"},
              {"fitness", icp.fitness},
              {"inlier_rmse_mm", icp.inlier_rmse * 1000},
              {"translation_change_mm", icp.transform.topRightCorner<3, 1>().norm() * 1000},
              {"rotation_change_deg", rotation_angle_deg(icp.transform.topLeftCorner<3, 3>())}};
    if (icp.fitness >= 0.3) {
      align = Similarity::from_matrix(icp.transform) * align;
      for (auto& p : aligned) p = Similarity::from_matrix(icp.transform).apply(p);
      j["applied"] = true;
    } else {
      j["applied"] = false;
      j["reason"] = "fewer than 30 % of the points found a correspondence";
    }
    alignment["icp"] = j;
  }
  alignment["status"] = "ok";
  alignment["reconstruction_to_ground_truth"] = similarity_json(align);
  report["alignment"] = alignment;

  std::vector<Vec3> kept;
  std::vector<std::array<int, 3>> kept_rgb;
  std::vector<Vec3> kept_view;  // mean observing camera centre, for Poisson normal orientation
  std::map<int, Vec3> centre_gt;
  for (const auto& [id, c] : rec_centre_by_image) centre_gt[id] = align.apply(c);
  for (std::size_t i = 0; i < aligned.size(); ++i) {
    if (!crop.contains(aligned[i])) continue;
    kept.push_back(aligned[i]);
    kept_rgb.push_back(model->points[i].rgb);
    Vec3 v = Vec3::Zero();
    int n = 0;
    for (int id : model->points[i].track_images) {
      auto it = centre_gt.find(id);
      if (it != centre_gt.end()) {
        v += it->second;
        ++n;
      }
    }
    kept_view.push_back(n ? Vec3(v / n) : Vec3(box.center() + Vec3(0, 0, diag)));
  }

  // 3. Distances.
  std::vector<double> d_mm;
  for (double d : surface.signed_distance(kept)) d_mm.push_back(1000 * d);
  DistanceStats stats = distance_stats(d_mm);
  json distances = stats_json(stats);
  distances["cropped_points"] = aligned.size() - kept.size();
  distances["crop"] = "ground-truth bounds grown by 5 % of their diagonal on every side";
  report["compared"] = "points";
  report["signed_distance_mm"] = distances;
  report["signed_distance_mm"]["convention"] =
      "nearest ground-truth triangle, positive on its normal's side (outside)";

  std::vector<double> truth_to_rec;
  std::vector<double> precision_d = d_mm;
  std::vector<Vec3> compared_cloud = kept;
  if (o.poisson) {
    std::string why;
    auto mesh = poisson_mesh(kept, kept_view, o.poisson_depth, &why);
    if (mesh) {
      Surface rec_surface(mesh->positions, mesh->triangles);
      std::vector<Vec3> mesh_samples, mesh_normals;
      rec_surface.sample(std::max<int>(100000, static_cast<int>(kept.size())), 11, &mesh_samples,
                         &mesh_normals);
      std::vector<double> dm;
      for (double d : surface.signed_distance(mesh_samples)) dm.push_back(1000 * d);
      const DistanceStats ms = distance_stats(dm);
      report["compared"] = "poisson_mesh";
      report["poisson_mesh"] = {{"depth", o.poisson_depth},
                                {"triangles", mesh->triangles.size()},
                                {"samples", mesh_samples.size()},
                                {"signed_distance_mm", stats_json(ms)}};
      ir::Mesh m;
      m.positions = mesh->positions;
      m.triangles = mesh->triangles;
      if (write_ply((out / "poisson_mesh.ply").string(), m, &why)) {
        report["poisson_mesh"]["file"] = (out / "poisson_mesh.ply").string();
      }
      precision_d = dm;
      compared_cloud = mesh_samples;
      stats = ms;
    } else {
      report["poisson_mesh"] = {{"status", "failed"}, {"reason", why}};
    }
  }
  truth_to_rec = nearest_distances(visible_samples, compared_cloud);
  for (auto& d : truth_to_rec) d *= 1000;
  const FScore f = f_score(precision_d, truth_to_rec, o.tau_mm);
  report["fscore"] = {{"tau_mm", f.tau},
                      {"precision", f.precision},
                      {"recall", f.recall},
                      {"fscore", f.fscore},
                      {"ground_truth_samples", samples.size()},
                      {"visible_ground_truth_samples", visible_samples.size()},
                      {"definition",
                       "Tanks and Temples: precision = share of the compared geometry within tau "
                       "of the ground-truth mesh; recall = share of visible ground-truth samples "
                       "within tau of it"}};
  sum.mean_mm = stats.mean;
  sum.std_mm = stats.stddev;
  sum.fscore = f.fscore;

  // 4. Camera errors.
  if (!gt_poses.empty()) {
    std::vector<double> pos_mm, rot_deg;
    const Similarity inv = align.inverse();
    for (const auto& im : model->images) {
      auto it = gt_poses.find(im.name);
      if (it == gt_poses.end()) continue;
      pos_mm.push_back(
          1000 *
          (align.apply(camera_centre(im.camera_from_world)) - camera_centre(it->second)).norm());
      const Eigen::Matrix3d r_rec = im.camera_from_world.topLeftCorner<3, 3>() * inv.rotation;
      rot_deg.push_back(rotation_angle_deg(it->second.topLeftCorner<3, 3>() * r_rec.transpose()));
    }
    const DistanceStats ps = distance_stats(pos_mm), rs = distance_stats(rot_deg);
    report["cameras"] = {
        {"compared", pos_mm.size()},
        {"position_error_mm", {{"mean", ps.mean}, {"median", ps.median}, {"max", ps.max}}},
        {"rotation_error_deg", {{"mean", rs.mean}, {"median", rs.median}, {"max", rs.max}}}};
  }
  const double rigc_metrics_s = seconds_since(t_rigc);

  // 5. Files.
  const double range =
      o.color_range_mm > 0 ? o.color_range_mm : std::max(1e-3, 3 * distance_stats(d_mm).rms);
  json files;
  std::string why;
  if (write_colored_ply(out / "cloud_signed_distance.ply", kept, d_mm, range, &why)) {
    files["cloud_ply"] = (out / "cloud_signed_distance.ply").string();
  } else {
    log << "rigc eval: warning: " << why << "\n";
  }
  if (write_histogram_png(out / "histogram.png", d_mm, range, distance_stats(d_mm), &why)) {
    files["histogram_png"] = (out / "histogram.png").string();
    sum.histogram_png = files["histogram_png"];
  } else {
    log << "rigc eval: warning: " << why << "\n";
  }
  if (!gt_views.empty()) {
    if (write_heatmap_png(out / "heatmap.png", surface, gt_views.front(), kept, d_mm, range, 1280,
                          &why)) {
      files["heatmap_png"] = (out / "heatmap.png").string();
      sum.heatmap_png = files["heatmap_png"];
    } else {
      log << "rigc eval: warning: " << why << "\n";
    }
  }
  files["color_range_mm"] = range;
  report["files"] = files;
  sum.rigc_s = seconds_since(t_rigc);
  // total: this call's wall time (with --reuse-colmap it holds no COLMAP time).
  const double total_s = seconds_since(t_start);
  report["timing_s"] = {
      {"colmap", colmap.seconds},     {"colmap_reused", colmap.reused},
      {"rigc_ground_truth", setup_s}, {"rigc_alignment_and_metrics", rigc_metrics_s},
      {"rigc_total", sum.rigc_s},     {"total", total_s}};
  if (!write_report()) return 2;

  if (!o.quiet) {
    log << fmt::format(
        "rigc eval: signed distance {:.3f} ± {:.3f} mm (median {:.3f}, p90 |d| {:.3f}) over {} "
        "{}; F-score {:.3f} at {} mm (P {:.3f}, R {:.3f})\n",
        stats.mean, stats.stddev, stats.median, stats.p90_abs, stats.count,
        report["compared"].get<std::string>() == "points" ? "points" : "Poisson-mesh samples",
        f.fscore, o.tau_mm, f.precision, f.recall);
    // The time split: COLMAP's steps, then RigC's own parts.
    std::string colmap_split;
    for (const auto& step : colmap.steps) {
      if (!step.is_object()) continue;
      colmap_split +=
          fmt::format(", {} {:.1f}", step.value("name", "?"), step.value("seconds", 0.0));
    }
    if (colmap.matching.contains("pairs")) {
      colmap_split += fmt::format("; {} matching, {} pairs", colmap.matching.value("matcher", "?"),
                                  colmap.matching["pairs"].dump());
    }
    log << fmt::format(
        "rigc eval: {:.1f} s in all: COLMAP {:.1f} s{}{}, RigC {:.1f} s (ground truth {:.1f}, "
        "alignment and metrics {:.1f}, files {:.1f})\n",
        total_s, colmap.seconds, colmap.reused ? " (reused: the earlier run's)" : "",
        colmap_split.empty() ? "" : " (" + colmap_split.substr(2) + ")", setup_s + sum.rigc_s,
        setup_s, rigc_metrics_s, sum.rigc_s - rigc_metrics_s);
    log << fmt::format("rigc eval: wrote {}\n", (out / "eval.json").string());
  }
  return 0;
}

}  // namespace rigc::eval
