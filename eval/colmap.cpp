#include "eval/colmap.h"

#include <OpenImageIO/imagebuf.h>
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>
#include <regex>
#include <sstream>

#include "dslr/image_io.h"
#include "io/child_processes.h"
#include "io/files.h"
#include "io/output_paths.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

int run_logged(const std::vector<std::string>& argv, const fs::path& log, std::string* error,
               double* cpu_seconds) {
  if (argv.empty()) {
    *error = "no program to run";
    return -1;
  }
  {
    std::ofstream header(log, std::ios::app);
    if (!header) {
      *error = fmt::format("cannot write the log {}", log.string());
      return -1;
    }
    header << "$";
    for (const auto& a : argv) header << " " << a;
    header << "\n";
  }
  // COLMAP's Qt needs no display to extract and match.
  const rigc::ChildResult child = rigc::run_child({argv, log, {}, {"QT_QPA_PLATFORM=offscreen"}});
  if (!child.started || child.exit_code < 0) {
    *error = child.error;
    return -1;
  }
  if (cpu_seconds) *cpu_seconds = child.cpu_seconds;
  return child.exit_code;
}

namespace {

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::optional<ColmapFlags> probe_colmap(const std::string& executable, const fs::path& log_dir,
                                        std::string* error) {
  ColmapFlags flags;
  const fs::path log = log_dir / "colmap_probe.log";
  std::error_code ec;
  fs::remove(log, ec);
  std::string why;
  int rc = run_logged({executable, "feature_extractor", "-h"}, log, &why);
  if (rc < 0) {
    *error = fmt::format(
        "COLMAP is not available ({}); install Debian's colmap package "
        "(scripts/setup.sh) or pass --colmap PATH",
        why);
    return std::nullopt;
  }
  std::string text = read_all(log);
  if (text.find("SiftExtraction.use_gpu") != std::string::npos) {
    flags.extraction_gpu = "--SiftExtraction.use_gpu";
  } else if (text.find("FeatureExtraction.use_gpu") != std::string::npos) {
    flags.extraction_gpu = "--FeatureExtraction.use_gpu";
  } else if (text.find("ImageReader") == std::string::npos) {
    *error = fmt::format("`{} feature_extractor -h` does not look like COLMAP (exit {}); see {}",
                         executable, rc, log.string());
    return std::nullopt;
  }
  fs::remove(log, ec);
  rc = run_logged({executable, "exhaustive_matcher", "-h"}, log, &why);
  text = read_all(log);
  if (text.find("SiftMatching.use_gpu") != std::string::npos) {
    flags.matching_gpu = "--SiftMatching.use_gpu";
  } else if (text.find("FeatureMatching.use_gpu") != std::string::npos) {
    flags.matching_gpu = "--FeatureMatching.use_gpu";
  }
  fs::remove(log, ec);
  run_logged({executable, "matches_importer", "-h"}, log, &why);
  text = read_all(log);
  flags.imports_pair_lists = text.find("match_list_path") != std::string::npos &&
                             text.find("match_type") != std::string::npos;
  fs::remove(log, ec);
  run_logged({executable, "-h"}, log, &why);
  std::istringstream lines(read_all(log));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("COLMAP", 0) == 0) {
      flags.version = line;
      break;
    }
  }
  return flags;
}

std::vector<std::pair<int, int>> neighbour_pairs(const std::vector<ir::Vec3>& optical_axes,
                                                 const NeighbourPairOptions& options) {
  const int n = static_cast<int>(optical_axes.size());
  // A thousandth of a degree of slack: 3 x 15 deg read back from text is not exactly 45.
  const double max_angle = (options.max_angle_deg + 1e-3) * M_PI / 180;
  std::vector<std::pair<int, int>> pairs;
  std::vector<double> angle(n);
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) {
    const ir::Vec3 a = optical_axes[i].normalized();
    for (int j = 0; j < n; ++j) {
      const ir::Vec3 b = optical_axes[j].normalized();
      angle[j] = std::atan2(a.cross(b).norm(), a.dot(b));  // accurate for small angles too
    }
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return angle[x] < angle[y]; });
    int taken = 0;
    for (int j : order) {
      if (j == i) continue;
      const bool near = angle[j] <= max_angle && taken < options.max_per_image;
      if (!near && taken >= options.min_per_image) break;
      pairs.emplace_back(std::min(i, j), std::max(i, j));
      ++taken;
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

bool write_pair_list(const fs::path& path, const std::vector<std::string>& names,
                     const std::vector<std::pair<int, int>>& pairs, std::string* error) {
  std::string text;
  for (const auto& [i, j] : pairs) text += names.at(i) + " " + names.at(j) + "\n";
  return rigc::write_file_atomically(path, text, error);
}

std::vector<std::pair<int, int>> sequential_ring_pairs(int n, int overlap) {
  std::vector<std::pair<int, int>> pairs;
  for (int i = 0; i < n; ++i) {
    for (int d = 1; d <= overlap && d < n; ++d) {
      const int j = (i + d) % n;
      pairs.emplace_back(std::min(i, j), std::max(i, j));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

const run::ColmapCamera* SparseModel::camera_of(const run::ColmapImage& image) const {
  const auto it = std::find_if(cameras.begin(), cameras.end(), [&](const run::ColmapCamera& c) {
    return c.camera_id == image.camera_id;
  });
  return it == cameras.end() ? nullptr : &*it;
}

double SparseModel::mean_track_length() const {
  if (points.empty()) return 0;
  double sum = 0;
  for (const auto& p : points) sum += static_cast<double>(p.track_images.size());
  return sum / static_cast<double>(points.size());
}

double SparseModel::mean_reprojection_error() const {
  double sum = 0, weight = 0;
  for (const auto& p : points) {
    const double w = static_cast<double>(p.track_images.size());
    sum += p.error * w;
    weight += w;
  }
  return weight > 0 ? sum / weight : 0;
}

std::optional<std::vector<Point3D>> read_colmap_points(const fs::path& path, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = fmt::format("{}: cannot read", path.string());
    return std::nullopt;
  }
  std::vector<Point3D> points;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Point3D p;
    if (!(s >> p.id >> p.position.x() >> p.position.y() >> p.position.z() >> p.rgb[0] >> p.rgb[1] >>
          p.rgb[2] >> p.error)) {
      *error = fmt::format("{}:{}: malformed point line", path.string(), number);
      return std::nullopt;
    }
    int image = 0, index = 0;
    while (s >> image >> index) p.track_images.push_back(image);
    points.push_back(std::move(p));
  }
  return points;
}

std::optional<SparseModel> read_sparse_model(const fs::path& dir, std::string* error) {
  SparseModel model;
  auto cameras = run::read_colmap_cameras(dir / "cameras.txt", error);
  if (!cameras) return std::nullopt;
  auto images = run::read_colmap_images(dir / "images.txt", error);
  if (!images || !run::check_camera_ids(*images, *cameras, dir / "images.txt", error)) {
    return std::nullopt;
  }
  auto points = read_colmap_points(dir / "points3D.txt", error);
  if (!points) return std::nullopt;
  model.cameras = std::move(*cameras);
  model.images = std::move(*images);
  model.points = std::move(*points);
  return model;
}

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
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

// Puts every image of `set` into `to` under the same name, 8 bits a channel: COLMAP 3.8 cannot
// read 16-bit PNG and TIFF (what a camera's `output: {format: png16}` writes), and its SIFT works
// on 8-bit grey anyway. 8-bit files are copied as they are (a JPEG is not encoded twice). False
// with `error` when an image's pixels cannot be read (its header could: the input is at fault) or
// a copy cannot be written.
bool write_eight_bit_copies(const ImageSet& set, const fs::path& to, bool* input_fault,
                            std::string* error) {
  const fs::path& from = set.dir;
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
    if (!dslr::write_image_buffer(to / name, image, error)) return false;
  }
  return true;
}

using Argv = std::vector<std::string>;

// One run_colmap: its folders, the probed COLMAP, and the ColmapRun it fills in step by step.
class ColmapPipeline {
 public:
  ColmapPipeline(const EvalOptions& o, const EvalInputs& in, std::ostream& log,
                 const PhotoSetup* photos)
      : o_(o),
        in_(in),
        photos_(photos),
        log_(log),
        work_(in.out / "colmap"),
        logs_(in.out / "logs"),
        txt_(work_ / "model_txt"),
        db_(work_ / "database.db"),
        images_dir_(in.images.dir) {}

  ColmapRun run() {
    if (o_.sfm.reuse_colmap && fs::exists(txt_ / "points3D.txt")) {
      reuse_earlier_model();
      return r_;
    }
    std::error_code ec;
    std::string error;
    if (!clear_output_folder(work_, &error)) {
      fail(1, error);
      return r_;
    }
    fs::create_directories(work_ / "sparse", ec);
    fs::create_directories(logs_, ec);
    if (!prepare_images() || !probe()) return r_;
    r_.images_dir = images_dir_;
    std::vector<Step> steps = extraction_steps();
    if (steps.empty()) return r_;
    std::optional<Argv> match = matcher_args();
    if (!match) return r_;
    steps.push_back({(*match)[1], *match});
    steps.push_back({"mapper", mapper_args()});
    if (run_steps(steps)) keep_largest_model();
    return r_;
  }

 private:
  struct Step {
    std::string name;
    Argv argv;
  };

  void fail(int exit_code, std::string why) {
    r_.exit_code = exit_code;
    r_.failure = std::move(why);
  }

  // --reuse-colmap: the model in the output folder, with the steps and times of the eval.json
  // that made it.
  void reuse_earlier_model() {
    r_.ok = true;
    r_.reused = true;
    r_.model_txt = txt_;
    r_.images_dir = in_.images.wider_than_eight_bit.empty() ? images_dir_ : work_ / "images_8bit";
    const json previous =
        json::parse(std::ifstream(in_.out / "eval.json", std::ios::binary), nullptr, false);
    if (!previous.is_discarded() && previous.contains("colmap") && previous["colmap"].is_object()) {
      r_.steps = previous["colmap"].value("steps", json::array());
      r_.seconds = previous["colmap"].value("seconds", 0.0);
      r_.prior = previous["colmap"].value("intrinsics_prior", json());
      r_.matching = previous["colmap"].value("matching", json::object());
      if (!r_.matching.is_object()) r_.matching = json::object();
    }
    if (!o_.quiet) log_ << "rigc eval: reusing the COLMAP model in " << txt_.string() << "\n";
  }

  // 8-bit copies of the images when some are wider.
  bool prepare_images() {
    if (in_.images.wider_than_eight_bit.empty()) return true;
    images_dir_ = work_ / "images_8bit";
    if (!o_.quiet) {
      log_ << "rigc eval: 8-bit copies of the images for COLMAP in " << images_dir_.string()
           << "\n";
    }
    bool input_fault = false;
    std::string error;
    if (write_eight_bit_copies(in_.images, images_dir_, &input_fault, &error)) return true;
    fail(input_fault ? 1 : 2, error);
    return false;
  }

  bool probe() {
    std::string error;
    auto flags = probe_colmap(o_.sfm.colmap, logs_, &error);
    if (!flags) {
      fail(2, error);
      return false;
    }
    flags_ = *flags;
    return true;
  }

  Argv feature_extractor_args(bool one_camera) {
    Argv argv = {o_.sfm.colmap, "feature_extractor", "--database_path", db_.string(),
                 "--image_path", images_dir_.string(), "--ImageReader.single_camera",
                 // One camera for photos of one size; COLMAP refuses a single camera over
                 // images of different sizes.
                 one_camera ? "1" : "0"};
    if (!flags_.extraction_gpu.empty()) {
      argv.push_back(flags_.extraction_gpu);
      argv.push_back("0");
    }
    return argv;
  }

  // One feature extraction for a run folder; for photos one per camera (each over its list of
  // photos, with its own prior), so that each body, zoom setting and size gets a camera.
  std::vector<Step> extraction_steps() {
    if (!photos_ || photos_->cameras.empty()) {
      Argv argv = feature_extractor_args(in_.images.one_size());
      add_intrinsics_prior(argv);
      add_masks(argv);
      return {{"feature_extractor", argv}};
    }
    std::vector<Step> steps;
    r_.prior = {{"source", "the photos' cameras"}, {"cameras", json::array()}};
    for (std::size_t k = 0; k < photos_->cameras.size(); ++k) {
      const PhotoCamera& camera = photos_->cameras[k];
      const fs::path list = work_ / fmt::format("images_camera_{}.txt", k + 1);
      std::string text, error;
      for (const auto& name : camera.images) text += name + "\n";
      if (!rigc::write_file_atomically(list, text, &error)) {
        fail(2, error);
        return {};
      }
      Argv argv = feature_extractor_args(true);
      argv.insert(argv.end(), {"--image_list_path", list.string()});
      add_photo_prior(argv, camera);
      add_masks(argv);
      steps.push_back(
          {k == 0 ? "feature_extractor" : fmt::format("feature_extractor_{}", k + 1), argv});
    }
    return steps;
  }

  // A photo camera's prior: SIMPLE_RADIAL (one focal length, the centre, k1), its focal length
  // from the body preset's sensor when known, else COLMAP's guess from EXIF.
  void add_photo_prior(Argv& argv, const PhotoCamera& camera) {
    argv.insert(argv.end(), {"--ImageReader.camera_model", "SIMPLE_RADIAL"});
    json entry = camera.to_json();
    if (camera.focal_px > 0) {
      const std::string params = fmt::format("{:.17g},{:.17g},{:.17g},0", camera.focal_px,
                                             camera.width / 2.0, camera.height / 2.0);
      argv.insert(argv.end(), {"--ImageReader.camera_params", params});
      entry["params"] = params;
    }
    if (!camera.sensor_known) photo_focal_unknown_ = true;
    r_.prior["model"] = "SIMPLE_RADIAL";
    r_.prior["cameras"].push_back(entry);
    r_.prior["refined_by_colmap"] = photo_focal_unknown_ || o_.sfm.refine_intrinsics
                                        ? "focal length and k1"
                                        : "nothing (the focal length from the sensor is kept, "
                                          "k1 held at 0; --refine-intrinsics refines both)";
  }

  // The intrinsics prior: the run's ground-truth camera (exact), else COLMAP reads EXIF.
  void add_intrinsics_prior(Argv& argv) {
    const fs::path cameras_txt = in_.run_dir / "sparse" / "cameras.txt";
    std::string why;
    auto cams = run::read_colmap_cameras(cameras_txt, &why);
    if (cams && !cams->empty()) {
      const auto& c = cams->front();
      std::string params;
      for (double v : c.params) params += (params.empty() ? "" : ",") + fmt::format("{:.17g}", v);
      argv.insert(argv.end(),
                  {"--ImageReader.camera_model", c.model, "--ImageReader.camera_params", params});
      exact_prior_ = true;
      r_.prior = {{"source", cameras_txt.string()},
                  {"model", c.model},
                  {"params", c.params},
                  {"refined_by_colmap", o_.sfm.refine_intrinsics}};
    } else {
      argv.insert(argv.end(), {"--ImageReader.camera_model", "OPENCV"});
      r_.prior = {{"source", "EXIF focal length, read by COLMAP"},
                  {"model", "OPENCV"},
                  {"refined_by_colmap", true}};
    }
  }

  // The object masks (the run's, or the photos' from eval/photo_masks.h): COLMAP wants
  // masks/<image name>.png and ignores zero pixels.
  void add_masks(Argv& argv) {
    const fs::path masks = photos_ ? photos_->masks.dir : in_.run_dir / "masks";
    if (masks.empty() || (!photos_ && !o_.sfm.use_masks) || !fs::is_directory(masks)) return;
    if (mask_dir_ready_) {
      argv.insert(argv.end(), {"--ImageReader.mask_path", (work_ / "masks").string()});
      return;
    }
    const fs::path mask_dir = work_ / "masks";
    std::error_code ec;
    fs::create_directories(mask_dir, ec);
    int linked = 0;
    for (const auto& name : in_.images.names) {
      const fs::path src = masks / (fs::path(name).stem().string() + ".png");
      if (!fs::exists(src)) continue;
      fs::create_symlink(fs::absolute(src), mask_dir / (name + ".png"), ec);
      if (!ec) ++linked;
    }
    if (linked > 0) {
      mask_dir_ready_ = true;
      argv.insert(argv.end(), {"--ImageReader.mask_path", mask_dir.string()});
      r_.prior["masks"] = masks.string();
    }
  }

  // Matching costs about features^2 per pair on the CPU: with a capture plan, match only the
  // views that can overlap. nullopt when the neighbours matcher cannot run.
  std::optional<Argv> matcher_args() {
    const int image_count = static_cast<int>(in_.images.names.size());
    Matcher matcher = o_.sfm.matcher;
    if (matcher == Matcher::automatic && photos_) {
      matcher = image_count <= kExhaustivePhotos || !flags_.imports_pair_lists
                    ? Matcher::exhaustive
                    : Matcher::sequential;
    } else if (matcher == Matcher::automatic) {
      const bool planned = every_image_planned(in_.images.names, in_.truth.poses);
      matcher = planned && flags_.imports_pair_lists ? Matcher::neighbours
                : image_count > 100                  ? Matcher::sequential
                                                     : Matcher::exhaustive;
    }
    const long all_pairs = static_cast<long>(image_count) * (image_count - 1) / 2;
    r_.matching = {{"matcher", matcher_name(matcher)}, {"all_pairs", all_pairs}};
    Argv argv;
    if (matcher == Matcher::sequential && photos_ && flags_.imports_pair_lists) {
      auto importer = sequential_photo_matching_args();
      if (!importer) return std::nullopt;
      argv = std::move(*importer);
    } else if (matcher == Matcher::neighbours) {
      auto importer = neighbour_matching_args();
      if (!importer) return std::nullopt;
      argv = std::move(*importer);
    } else {
      argv = {o_.sfm.colmap, matcher_name(matcher) + "_matcher", "--database_path", db_.string()};
      if (matcher == Matcher::exhaustive) r_.matching["pairs"] = all_pairs;
    }
    if (!flags_.matching_gpu.empty()) {
      argv.push_back(flags_.matching_gpu);
      argv.push_back("0");
    }
    return argv;
  }

  // matches_importer on the pairs of views whose planned optical axes are close.
  std::optional<Argv> neighbour_matching_args() {
    if (!flags_.imports_pair_lists) {
      fail(2,
           fmt::format("this COLMAP's matches_importer takes no pair list (see {}); use --matcher "
                       "exhaustive",
                       (logs_ / "colmap_probe.log").string()));
      return std::nullopt;
    }
    NeighbourPairOptions rule;
    rule.max_angle_deg = o_.sfm.neighbour_angle_deg;
    std::vector<ir::Vec3> axes;
    for (const auto& name : in_.images.names) {
      // The optical axis (camera +Z) in the world: the third row of camera_from_world's rotation.
      axes.push_back(in_.truth.poses.at(name).block<1, 3>(2, 0).transpose());
    }
    const auto pairs = neighbour_pairs(axes, rule);
    const fs::path pair_list = work_ / "pairs.txt";
    std::string error;
    if (!write_pair_list(pair_list, in_.images.names, pairs, &error)) {
      fail(2, error);
      return std::nullopt;
    }
    r_.matching["pairs"] = pairs.size();
    r_.matching["pair_list"] = pair_list.string();
    r_.matching["rule"] = fmt::format(
        "planned poses ({}): views whose optical axes are at most {} deg apart, the nearest {} "
        "at most, the nearest {} at least",
        (in_.run_dir / "sparse" / "images.txt").string(), rule.max_angle_deg, rule.max_per_image,
        rule.min_per_image);
    return Argv{o_.sfm.colmap,       "matches_importer", "--database_path", db_.string(),
                "--match_list_path", pair_list.string(), "--match_type",    "pairs"};
  }

  // matches_importer on the photos in capture order, each with the next kOverlap and the loop
  // closed (a turntable comes back to its first view).
  std::optional<Argv> sequential_photo_matching_args() {
    const auto pairs = sequential_ring_pairs(static_cast<int>(photos_->order.size()), kOverlap);
    const fs::path pair_list = work_ / "pairs.txt";
    std::string error;
    if (!write_pair_list(pair_list, photos_->order, pairs, &error)) {
      fail(2, error);
      return std::nullopt;
    }
    r_.matching["pairs"] = pairs.size();
    r_.matching["pair_list"] = pair_list.string();
    r_.matching["rule"] = fmt::format(
        "capture order ({}): each photo with the next {}, the last with the first (loop closure)",
        photos_->order_basis, kOverlap);
    return Argv{o_.sfm.colmap,       "matches_importer", "--database_path", db_.string(),
                "--match_list_path", pair_list.string(), "--match_type",    "pairs"};
  }

  Argv mapper_args() const {
    Argv argv = {o_.sfm.colmap, "mapper", "--database_path", db_.string(), "--image_path",
                 images_dir_.string(), "--output_path", (work_ / "sparse").string(),
                 // COLMAP 3.8 drops a model of fewer than min(images, 10) registered images: a
                 // ring with one photo lost registers in parts, which would be reported as
                 // nothing reconstructed.
                 "--Mapper.min_model_size", "3"};
    if (photos_ && !photo_focal_unknown_ && !o_.sfm.refine_intrinsics) {
      // Focal lengths from the bodies' sensors: refining them from a turntable's narrow views
      // is ill-conditioned. So is k1 for a small object near the frame's centre: refined, it
      // drifts, and the mapper restarts from pair after pair and can register nothing.
      argv.insert(argv.end(),
                  {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_extra_params", "0"});
    }
    if (exact_prior_ && !o_.sfm.refine_intrinsics) {
      // A known camera: refining focal length and distortion from two narrow-angle views of a
      // small object is ill-conditioned and can stop the reconstruction at its first pair.
      argv.insert(argv.end(),
                  {"--Mapper.ba_refine_focal_length", "0", "--Mapper.ba_refine_principal_point",
                   "0", "--Mapper.ba_refine_extra_params", "0"});
    }
    return argv;
  }

  // Runs the steps in order, each logged to OUT/logs/<step>.log and timed; false when one fails
  // (a mapper that finds nothing is reported by keep_largest_model).
  bool run_steps(const std::vector<Step>& steps) {
    std::error_code ec;
    for (const auto& step : steps) {
      const fs::path step_log = logs_ / (step.name + ".log");
      fs::remove(step_log, ec);
      if (!o_.quiet) log_ << fmt::format("rigc eval: colmap {} ...\n", step.name);
      const auto t0 = Clock::now();
      double cpu_s = 0;
      std::string error;
      const int rc = run_logged(step.argv, step_log, &error, &cpu_s);
      const double s = seconds_since(t0);
      r_.seconds += s;
      r_.steps.push_back({{"name", step.name},
                          {"seconds", s},
                          {"cpu_seconds", cpu_s},
                          {"exit_code", rc},
                          {"log", step_log.string()}});
      if (step.name == "feature_extractor") {
        if (const auto features = mean_features(step_log)) {
          r_.matching["mean_features_per_image"] = *features;
        }
      }
      if (rc != 0 && step.name != "mapper") {
        fail(2, rc < 0 ? error
                       : fmt::format("colmap {} failed (exit {}); see {}", step.name, rc,
                                     step_log.string()));
        return false;
      }
    }
    return true;
  }

  // The mapper may write several models (sparse/0, sparse/1, ...): converts each to text and
  // keeps the one with the most images as OUT/colmap/model_txt.
  void keep_largest_model() {
    fs::path best;
    std::size_t best_images = 0;
    const auto t_convert = Clock::now();
    double convert_cpu_s = 0;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(work_ / "sparse", ec)) {
      if (!e.is_directory()) continue;
      const fs::path tmp = work_ / ("txt_" + e.path().filename().string());
      fs::create_directories(tmp, ec);
      double cpu_s = 0;
      std::string error;
      const int rc =
          run_logged({o_.sfm.colmap, "model_converter", "--input_path", e.path().string(),
                      "--output_path", tmp.string(), "--output_type", "TXT"},
                     logs_ / "model_converter.log", &error, &cpu_s);
      convert_cpu_s += cpu_s;
      if (rc != 0) continue;
      auto images = run::read_colmap_images(tmp / "images.txt", &error);
      if (images && images->size() > best_images) {
        best_images = images->size();
        best = tmp;
      }
    }
    const double convert_s = seconds_since(t_convert);
    r_.seconds += convert_s;
    r_.steps.push_back({{"name", "model_converter"},
                        {"seconds", convert_s},
                        {"cpu_seconds", convert_cpu_s},
                        {"log", (logs_ / "model_converter.log").string()}});
    if (best.empty()) {
      fail(2, nothing_reconstructed());
      return;
    }
    fs::rename(best, txt_, ec);
    r_.model_txt = ec ? best : txt_;
    r_.ok = true;
  }

  std::string nothing_reconstructed() const {
    const auto features = mean_features(logs_ / "feature_extractor.log");
    return fmt::format(
        "COLMAP reconstructed nothing from {} images{}: no initial image pair (too few features "
        "or matches: the object may need more texture, or the shots more overlap); see {}",
        in_.images.names.size(),
        features ? fmt::format(" ({:.0f} features per image on average)", *features) : "",
        (logs_ / "mapper.log").string());
  }

  const EvalOptions& o_;
  const EvalInputs& in_;
  const PhotoSetup* photos_;  // null for a run folder
  std::ostream& log_;
  const fs::path work_, logs_, txt_, db_;
  fs::path images_dir_;  // the images COLMAP reads: the inputs, or their 8-bit copies
  ColmapFlags flags_;
  bool exact_prior_ = false;          // the run's own camera is the intrinsics prior
  bool photo_focal_unknown_ = false;  // a photo camera's focal length is COLMAP's guess
  bool mask_dir_ready_ = false;       // OUT/colmap/masks holds the links
  // Photos: up to this many are matched exhaustively; more in capture order, with this overlap.
  static constexpr int kExhaustivePhotos = 10;
  static constexpr int kOverlap = 3;
  ColmapRun r_;
};

}  // namespace

ColmapRun run_colmap(const EvalOptions& options, const EvalInputs& inputs, std::ostream& log,
                     const PhotoSetup* photos) {
  return ColmapPipeline(options, inputs, log, photos).run();
}

}  // namespace rigc::eval
