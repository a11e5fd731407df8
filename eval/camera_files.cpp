#include "eval/camera_files.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "io/bounded_file.h"
#include "run/camera_csv.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The camera file at `path` as a stream, read whole and bounded (io/bounded_file.h); nullopt with
// `error` naming it and why.
std::optional<std::istringstream> open_camera_file(const fs::path& path, std::string* error) {
  std::string why;
  auto file = read_bounded_file(path, kMostCameraFileBytes, &why);
  if (!file) {
    *error = fmt::format("{}: cannot read it: it {}", path.string(), why);
    return std::nullopt;
  }
  return std::istringstream(std::move(file->bytes));
}

// Little-endian binary reader over a whole file; `ok` turns false on a short read.
class BinaryReader {
 public:
  BinaryReader(const fs::path& path, std::string* error) {
    if (auto in = open_camera_file(path, error)) in_ = std::move(*in);
    opened_ = error->empty();
  }
  bool opened() const { return opened_; }
  template <typename T>
  T read() {
    T value{};
    if (!in_.read(reinterpret_cast<char*>(&value), sizeof(T))) ok = false;
    return value;
  }
  std::string read_name() {
    std::string name;
    char c = 0;
    while (in_.get(c) && c != '\0') name.push_back(c);
    if (!in_) ok = false;
    return name;
  }
  void skip(std::uint64_t bytes) {
    if (!in_.seekg(static_cast<std::streamoff>(bytes), std::ios::cur)) ok = false;
  }
  bool ok = true;

 private:
  std::istringstream in_;
  bool opened_ = false;
};

// The parameter count of a COLMAP camera model id (colmap/sensor/models.h).
struct ModelInfo {
  const char* name;
  int params;
};
std::optional<ModelInfo> colmap_model(int id) {
  static const ModelInfo models[] = {{"SIMPLE_PINHOLE", 3},
                                     {"PINHOLE", 4},
                                     {"SIMPLE_RADIAL", 4},
                                     {"RADIAL", 5},
                                     {"OPENCV", 8},
                                     {"OPENCV_FISHEYE", 8},
                                     {"FULL_OPENCV", 12},
                                     {"FOV", 5},
                                     {"SIMPLE_RADIAL_FISHEYE", 4},
                                     {"RADIAL_FISHEYE", 5},
                                     {"THIN_PRISM_FISHEYE", 12}};
  if (id < 0 || id >= static_cast<int>(std::size(models))) return std::nullopt;
  return models[id];
}

bool bad_file(const fs::path& path, const std::string& why, std::string* error) {
  *error = fmt::format("{}: {}", path.string(), why);
  return false;
}

ir::Mat4 pose_from(const Eigen::Matrix3d& r, const ir::Vec3& t) {
  ir::Mat4 m = ir::Mat4::Identity();
  m.topLeftCorner<3, 3>() = r;
  m.topRightCorner<3, 1>() = t;
  return m;
}

std::string file_name_of(const std::string& path_text) {
  const std::string name = fs::path(path_text).filename().string();
  return name.empty() ? path_text : name;
}

// A number of a Meshroom file: written as a string ("0.5"), or a plain JSON number.
bool json_number(const json& j, double* value) {
  try {
    *value = j.is_string() ? std::stod(j.get<std::string>()) : j.get<double>();
  } catch (const std::exception&) {
    return false;
  }
  return std::isfinite(*value);
}

std::string json_id(const json& j) {
  return j.is_string() ? j.get<std::string>() : j.dump();
}

std::optional<fs::path> bundler_list(const fs::path& out_path) {
  const fs::path dir = out_path.parent_path();
  const std::string stem = out_path.stem().string();
  for (const fs::path& candidate : {dir / (stem + ".list.txt"), dir / (stem + "_list.txt"),
                                    dir / "list.txt", dir / "bundle.list.txt"}) {
    if (fs::is_regular_file(candidate)) return candidate;
  }
  return std::nullopt;
}

// The rotation nearest to `m` (a file's matrix written with few digits), or nullopt when `m` is
// further than `tolerance` from any rotation (entry-wise on m^T m - I) or a reflection.
std::optional<Eigen::Matrix3d> nearest_rotation(const Eigen::Matrix3d& m, double tolerance) {
  if (!m.allFinite() || m.determinant() <= 0 ||
      (m.transpose() * m - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > tolerance) {
    return std::nullopt;
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  return Eigen::Matrix3d(svd.matrixU() * svd.matrixV().transpose());
}

constexpr double kRotationTolerance = 1e-3;

// The lines of a text file that hold something: comments ('#') and blank lines skipped, each
// with its line number.
std::vector<std::pair<int, std::string>> content_lines(std::istream& in) {
  std::vector<std::pair<int, std::string>> lines;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    lines.emplace_back(number, line);
  }
  return lines;
}

// One line of a Middlebury _par.txt: name, K (9), R (9), t (3).
bool read_par_line(const std::string& line, run::ColmapImage* image, run::ColmapCamera* camera,
                   std::string* why) {
  std::istringstream words(line);
  std::string name;
  double v[21];
  words >> name;
  for (double& x : v) words >> x;
  if (!words ||
      !std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); })) {
    *why = "expected an image name and 21 numbers (K, R, t)";
    return false;
  }
  std::string extra;
  if (words >> extra) {
    *why = "more than an image name and 21 numbers (K, R, t)";
    return false;
  }
  if (v[6] != 0 || v[7] != 0 || !(v[8] > 0) || !(v[0] > 0) || !(v[4] > 0)) {
    *why = "K is not a camera matrix (positive focal lengths, last row 0 0 k33 with k33 > 0)";
    return false;
  }
  Eigen::Matrix3d r;
  r << v[9], v[10], v[11], v[12], v[13], v[14], v[15], v[16], v[17];
  const auto rotation = nearest_rotation(r, kRotationTolerance);
  if (!rotation) {
    *why = "R is not a rotation";
    return false;
  }
  image->name = file_name_of(name);
  image->camera_from_world = pose_from(*rotation, ir::Vec3(v[18], v[19], v[20]));
  // Skew (k12) is left out: COLMAP's models have none.
  camera->model = "PINHOLE";
  camera->params = {v[0] / v[8], v[4] / v[8], v[2] / v[8], v[5] / v[8]};
  return true;
}

}  // namespace

std::optional<std::vector<run::ColmapCamera>> read_colmap_cameras_bin(const fs::path& path,
                                                                      std::string* error) {
  error->clear();
  BinaryReader in(path, error);
  if (!in.opened()) return std::nullopt;
  std::vector<run::ColmapCamera> cameras;
  const auto count = in.read<std::uint64_t>();
  for (std::uint64_t i = 0; in.ok && i < count; ++i) {
    run::ColmapCamera c;
    c.camera_id = static_cast<int>(in.read<std::uint32_t>());
    const auto info = colmap_model(in.read<std::int32_t>());
    c.width = static_cast<int>(in.read<std::uint64_t>());
    c.height = static_cast<int>(in.read<std::uint64_t>());
    if (!in.ok || !info) return bad_file(path, "unknown camera model", error), std::nullopt;
    c.model = info->name;
    for (int p = 0; p < info->params; ++p) c.params.push_back(in.read<double>());
    cameras.push_back(std::move(c));
  }
  if (!in.ok) return bad_file(path, "ends early (not a COLMAP cameras.bin)", error), std::nullopt;
  return cameras;
}

std::optional<std::vector<run::ColmapImage>> read_colmap_images_bin(const fs::path& path,
                                                                    std::string* error) {
  error->clear();
  BinaryReader in(path, error);
  if (!in.opened()) return std::nullopt;
  std::vector<run::ColmapImage> images;
  const auto count = in.read<std::uint64_t>();
  for (std::uint64_t i = 0; in.ok && i < count; ++i) {
    run::ColmapImage im;
    im.image_id = static_cast<int>(in.read<std::uint32_t>());
    double v[7];
    for (double& x : v) x = in.read<double>();
    im.camera_id = static_cast<int>(in.read<std::uint32_t>());
    im.name = in.read_name();
    const auto points2d = in.read<std::uint64_t>();
    in.skip(points2d * (2 * sizeof(double) + sizeof(std::uint64_t)));
    Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
    if (!in.ok) break;
    if (!(q.norm() > 0) || !std::isfinite(q.norm())) {
      return bad_file(path, fmt::format("image '{}' has no valid rotation", im.name), error),
             std::nullopt;
    }
    im.camera_from_world = pose_from(q.normalized().toRotationMatrix(), ir::Vec3(v[4], v[5], v[6]));
    images.push_back(std::move(im));
  }
  if (!in.ok) return bad_file(path, "ends early (not a COLMAP images.bin)", error), std::nullopt;
  return images;
}

std::optional<std::vector<run::ColmapImage>> read_bundler(const fs::path& out_path,
                                                          const fs::path& list_path,
                                                          std::string* error) {
  auto opened_out = open_camera_file(out_path, error);
  if (!opened_out) return std::nullopt;
  auto opened_list = open_camera_file(list_path, error);
  if (!opened_list) return std::nullopt;
  std::istream& out = *opened_out;
  std::istream& list = *opened_list;
  std::string header;
  std::getline(out, header);
  if (!header.starts_with("# Bundle file")) {
    return bad_file(out_path, "does not start with '# Bundle file' (not a Bundler .out)", error),
           std::nullopt;
  }
  long cameras = -1, points = -1;
  out >> cameras >> points;
  if (!out || cameras < 0 || points < 0) {
    return bad_file(out_path, "expected the camera and point counts", error), std::nullopt;
  }
  std::vector<std::string> names;
  for (std::string line; std::getline(list, line);) {
    std::istringstream words(line);
    std::string first;
    if (words >> first) names.push_back(first);
  }
  if (static_cast<long>(names.size()) != cameras) {
    return bad_file(list_path,
                    fmt::format("lists {} images but {} has {} cameras", names.size(),
                                out_path.string(), cameras),
                    error),
           std::nullopt;
  }
  // Bundler's camera looks down -Z with +Y up: OpenCV's axes are its Y and Z negated.
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  std::vector<run::ColmapImage> images;
  for (long i = 0; i < cameras; ++i) {
    double v[15];
    for (double& x : v) out >> x;
    if (!out) {
      return bad_file(out_path, fmt::format("camera {} is incomplete", i), error), std::nullopt;
    }
    if (!std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); })) {
      return bad_file(out_path, fmt::format("camera {} holds a non-finite number", i), error),
             std::nullopt;
    }
    if (v[0] == 0) continue;  // not registered
    Eigen::Matrix3d r;
    r << v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11];
    run::ColmapImage im;
    im.image_id = static_cast<int>(i + 1);
    im.camera_id = 1;
    im.name = file_name_of(names[i]);
    im.camera_from_world = pose_from(flip * r, flip * ir::Vec3(v[12], v[13], v[14]));
    images.push_back(std::move(im));
  }
  return images;
}

std::optional<std::vector<run::ColmapImage>> read_meshroom_sfm(const fs::path& path,
                                                               std::string* error) {
  auto in = open_camera_file(path, error);
  if (!in) return std::nullopt;
  const json doc = json::parse(*in, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("views") || !doc.contains("poses") ||
      !doc["views"].is_array() || !doc["poses"].is_array()) {
    return bad_file(path, "is not a Meshroom SfMData JSON (views and poses)", error), std::nullopt;
  }
  std::map<std::string, ir::Mat4> pose_by_id;
  for (const json& p : doc["poses"]) {
    const json* transform = p.is_object() && p.contains("pose") && p["pose"].is_object() &&
                                    p["pose"].contains("transform")
                                ? &p["pose"]["transform"]
                                : nullptr;
    if (!transform || !p.contains("poseId") || !transform->contains("rotation") ||
        !transform->contains("center") || (*transform)["rotation"].size() != 9 ||
        (*transform)["center"].size() != 3) {
      return bad_file(path, "a pose lacks poseId, rotation (9) or center (3)", error), std::nullopt;
    }
    Eigen::Matrix3d r;
    ir::Vec3 c;
    bool good = true;
    for (int k = 0; k < 9; ++k) good = good && json_number((*transform)["rotation"][k], &r(k));
    for (int k = 0; k < 3; ++k) good = good && json_number((*transform)["center"][k], &c(k));
    if (!good) return bad_file(path, "a pose holds a value that is no number", error), std::nullopt;
    pose_by_id[json_id(p["poseId"])] = pose_from(r, -r * c);
  }
  std::vector<run::ColmapImage> images;
  int id = 0;
  for (const json& v : doc["views"]) {
    if (!v.is_object() || !v.contains("path") || !v["path"].is_string() || !v.contains("poseId")) {
      return bad_file(path, "a view lacks its path or poseId", error), std::nullopt;
    }
    const auto pose = pose_by_id.find(json_id(v["poseId"]));
    if (pose == pose_by_id.end()) continue;  // a view Meshroom did not reconstruct
    run::ColmapImage im;
    im.image_id = ++id;
    im.camera_id = 1;
    im.name = file_name_of(v["path"].get<std::string>());
    im.camera_from_world = pose->second;
    images.push_back(std::move(im));
  }
  return images;
}

std::optional<CameraFile> read_middlebury_par(const fs::path& path, std::string* error) {
  auto in = open_camera_file(path, error);
  if (!in) return std::nullopt;
  const auto lines = content_lines(*in);
  long count = -1;
  if (lines.empty() || !(std::istringstream(lines.front().second) >> count) || count < 1) {
    return bad_file(path, "does not start with the number of images (not a Middlebury _par.txt)",
                    error),
           std::nullopt;
  }
  if (static_cast<long>(lines.size()) - 1 != count) {
    return bad_file(
               path,
               fmt::format("says {} images but has {} lines of cameras", count, lines.size() - 1),
               error),
           std::nullopt;
  }
  CameraFile file;
  file.format = "Middlebury";
  file.path = path;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    run::ColmapImage image;
    run::ColmapCamera camera;
    std::string why;
    if (!read_par_line(lines[i].second, &image, &camera, &why)) {
      return bad_file(path, fmt::format("line {}: {}", lines[i].first, why), error), std::nullopt;
    }
    image.image_id = image.camera_id = camera.camera_id = static_cast<int>(i);
    image.line = lines[i].first;
    file.images.push_back(std::move(image));
    file.cameras.push_back(std::move(camera));
  }
  return file;
}

std::optional<std::vector<run::ColmapImage>> read_rigc_camera_csv(const fs::path& path,
                                                                  std::string* error) {
  auto in = open_camera_file(path, error);
  if (!in) return std::nullopt;
  const auto lines = content_lines(*in);
  if (lines.empty() || lines.front().second.rfind("label,x,y,z,omega,phi,kappa", 0) != 0) {
    return bad_file(path, "has no header 'label,x,y,z,omega,phi,kappa' (not RigC's cameras.csv)",
                    error),
           std::nullopt;
  }
  std::vector<run::ColmapImage> images;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    std::string text = lines[i].second;
    const auto comma = text.find(',');
    std::replace(text.begin(), text.end(), ',', ' ');
    std::istringstream words(comma == std::string::npos ? std::string() : text.substr(comma + 1));
    double v[6];
    for (double& x : v) words >> x;
    if (comma == 0 || !words ||
        !std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); })) {
      return bad_file(path,
                      fmt::format("line {}: expected a name and six numbers (x, y, z, omega, "
                                  "phi, kappa)",
                                  lines[i].first),
                      error),
             std::nullopt;
    }
    const ir::Vec3 angles = ir::Vec3(v[3], v[4], v[5]) * (M_PI / 180);
    const Eigen::Matrix3d r = run::rotation_from_omega_phi_kappa(angles);
    run::ColmapImage image;
    image.image_id = static_cast<int>(i);
    image.camera_id = 1;
    image.name = file_name_of(lines[i].second.substr(0, comma));
    image.camera_from_world = pose_from(r, -r * ir::Vec3(v[0], v[1], v[2]));
    image.line = lines[i].first;
    images.push_back(std::move(image));
  }
  return images;
}

KnownCameras known_cameras(const CameraFile& file) {
  std::map<int, const run::ColmapCamera*> by_id;
  for (const auto& c : file.cameras) by_id[c.camera_id] = &c;
  KnownCameras known;
  for (const auto& im : file.images) {
    KnownCamera& k = known[im.name];
    k.camera_from_world = im.camera_from_world;
    if (const auto it = by_id.find(im.camera_id); it != by_id.end()) k.intrinsics = *it->second;
  }
  return known;
}

std::optional<CameraFile> read_camera_file(const fs::path& path, std::string* error) {
  CameraFile file;
  file.path = path;
  std::error_code ec;
  if (!fs::exists(path, ec)) {
    *error = fmt::format("{} does not exist", path.string());
    return std::nullopt;
  }
  const fs::path dir = fs::is_directory(path, ec) ? path : path.parent_path();
  const std::string ext = path.extension().string();
  std::optional<std::vector<run::ColmapImage>> images;
  if (fs::is_directory(path, ec) || path.filename() == "images.txt" ||
      path.filename() == "images.bin") {
    if (fs::exists(dir / "images.txt")) {
      file.format = "COLMAP text";
      images = run::read_colmap_images(dir / "images.txt", error);
      if (!images) return std::nullopt;
      auto cameras = run::read_colmap_cameras(dir / "cameras.txt", error);
      if (!cameras || !run::check_camera_ids(*images, *cameras, dir / "images.txt", error)) {
        return std::nullopt;
      }
      file.cameras = std::move(*cameras);
    } else if (fs::exists(dir / "images.bin")) {
      file.format = "COLMAP binary";
      images = read_colmap_images_bin(dir / "images.bin", error);
      if (!images) return std::nullopt;
      auto cameras = read_colmap_cameras_bin(dir / "cameras.bin", error);
      if (!cameras || !run::check_camera_ids(*images, *cameras, dir / "images.bin", error)) {
        return std::nullopt;
      }
      file.cameras = std::move(*cameras);
    } else {
      *error = fmt::format("{} holds no COLMAP model (images.txt or images.bin)", dir.string());
      return std::nullopt;
    }
    if (images) {
      for (auto& im : *images) im.name = file_name_of(im.name);
    }
  } else if (ext == ".out") {
    file.format = "Bundler";
    const auto list = bundler_list(path);
    if (!list) {
      *error = fmt::format("{}: no image list beside it ({}.list.txt, {}_list.txt or list.txt)",
                           path.string(), path.stem().string(), path.stem().string());
      return std::nullopt;
    }
    file.list = *list;
    images = read_bundler(path, *list, error);
  } else if (ext == ".txt") {
    return read_middlebury_par(path, error);
  } else if (ext == ".csv") {
    file.format = "RigC cameras.csv";
    images = read_rigc_camera_csv(path, error);
  } else if (ext == ".sfm" || ext == ".json") {
    file.format = "Meshroom SfMData";
    images = read_meshroom_sfm(path, error);
  } else {
    *error = fmt::format(
        "{}: unknown camera file (a COLMAP model folder, a Bundler .out, a Meshroom .sfm/.json, a "
        "Middlebury _par.txt or RigC's cameras.csv)",
        path.string());
    return std::nullopt;
  }
  if (!images) return std::nullopt;
  file.images = std::move(*images);
  return file;
}

}  // namespace rigc::eval
