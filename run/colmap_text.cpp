#include "run/colmap_text.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string_view>
#include <system_error>

#include "dslr/lens.h"
#include "io/bounded_file.h"
#include "io/files.h"
#include "run/ground_truth_points.h"

namespace rigc::run {
namespace fs = std::filesystem;

namespace {
// Adding +0 turns -0 into 0, so that files do not show "-0".
double tidy(double v) {
  return v + 0.0;
}
}  // namespace

std::string image_extension(ir::ImageFormat format) {
  switch (format) {
    case ir::ImageFormat::kJpeg:
      return ".jpg";
    case ir::ImageFormat::kPng16:
      return ".png";
    case ir::ImageFormat::kTiff16:
      return ".tif";
  }
  return ".jpg";
}

std::string image_file_name(const ir::Camera& camera, const ir::Shot& shot) {
  return shot.name + image_extension(camera.format);
}

std::string image_relative_path(const ir::Camera& camera, const ir::Shot& shot) {
  return "images/" + image_file_name(camera, shot);
}

std::string mask_relative_path(const ir::Shot& shot) {
  return "masks/" + shot.name + ".png";
}

std::vector<double> OutputCamera::params() const {
  const ir::Distortion& d = distortion;
  std::vector<double> p = {fx, fy, cx, cy, d.k1, d.k2, d.p1, d.p2};
  if (model == "FULL_OPENCV") p.insert(p.end(), {d.k3, 0, 0, 0});
  return p;
}

std::optional<OutputCamera> output_camera(const ir::Camera& camera, double scale,
                                          std::string* error) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    if (error != nullptr) *error = fmt::format("render scale {} is not a positive number", scale);
    return std::nullopt;
  }
  if (camera.width_px <= 0 || camera.height_px <= 0) {
    if (error != nullptr) {
      *error = fmt::format("camera has no pixels ({} x {})", camera.width_px, camera.height_px);
    }
    return std::nullopt;
  }
  // The grid the renderers develop onto, so the ground truth describes the written images.
  const dslr::Intrinsics sensor = dslr::sensor_intrinsics(camera, scale);
  OutputCamera out;
  out.width = sensor.width;
  out.height = sensor.height;
  out.fx = sensor.fx;
  out.fy = sensor.fy;
  out.cx = sensor.cx;
  out.cy = sensor.cy;
  if (camera.effects.distortion) out.distortion = camera.distortion;
  out.model = out.distortion.k3 != 0 ? "FULL_OPENCV" : "OPENCV";
  return out;
}

ir::Mat4 camera_from_object(const ir::Shot& shot) {
  const Eigen::Matrix3d r = shot.object_from_camera.block<3, 3>(0, 0);
  const ir::Vec3 t = shot.object_from_camera.block<3, 1>(0, 3);
  ir::Mat4 inverse = ir::Mat4::Identity();
  inverse.block<3, 3>(0, 0) = r.transpose();
  inverse.block<3, 1>(0, 3) = -(r.transpose() * t);
  return inverse;
}

namespace {

double mean_observations(const GroundTruthPoints& points) {
  std::size_t n = 0;
  for (const auto& image : points.per_image) n += image.size();
  return points.per_image.empty() ? 0.0 : static_cast<double>(n) / points.per_image.size();
}

// An image's POINTS2D line: X Y POINT3D_ID per observation, without the newline.
std::string observations_line(const GroundTruthPoints& points, std::size_t image) {
  std::string line;
  for (const auto& [p, entry] : points.per_image[image]) {
    const GroundTruthObservation& o = points.points[p].track[entry];
    line += fmt::format("{}{:.3f} {:.3f} {}", line.empty() ? "" : " ", o.x, o.y, p + 1);
  }
  return line;
}

std::string points3d_text(const std::vector<int>& shots, const GroundTruthPoints* points) {
  std::size_t observations = 0;
  if (points) {
    for (const auto& p : points->points) observations += p.track.size();
  }
  const std::size_t count = points ? points->points.size() : 0;
  std::string text = fmt::format(
      "# 3D point list with one line of data per point:\n"
      "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
      "# Number of points: {}, mean track length: {}\n",
      count, count ? tidy(static_cast<double>(observations) / count) : 0.0);
  for (std::size_t i = 0; i < count; ++i) {
    const GroundTruthPoint& p = points->points[i];
    text += fmt::format("{} {} {} {} {} {} {} 0", i + 1, tidy(p.position.x()), tidy(p.position.y()),
                        tidy(p.position.z()), p.rgb[0], p.rgb[1], p.rgb[2]);
    for (const auto& o : p.track) text += fmt::format(" {} {}", shots[o.shot] + 1, o.point2d);
    text += '\n';
  }
  return text;
}

}  // namespace

bool write_colmap_sparse(const fs::path& sparse_dir, const ir::Scene& scene,
                         const std::vector<int>& shots, double scale, std::string* error,
                         const GroundTruthPoints* points) {
  const auto camera = output_camera(scene.camera, scale, error);
  if (!camera) return false;
  std::set<int> seen;
  for (int index : shots) {
    if (index < 0 || index >= static_cast<int>(scene.shots.size()) || !seen.insert(index).second) {
      if (error != nullptr) {
        *error = fmt::format("cannot write the COLMAP model: shot index {} is {} (0..{})", index,
                             seen.count(index) ? "repeated" : "out of range",
                             static_cast<int>(scene.shots.size()) - 1);
      }
      return false;
    }
    if (!scene.shots[index].object_from_camera.allFinite()) {
      if (error != nullptr) {
        *error = fmt::format("cannot write the COLMAP model: {} has a non-finite pose",
                             scene.shots[index].name);
      }
      return false;
    }
  }
  std::error_code ec;
  fs::create_directories(sparse_dir, ec);
  if (ec) {
    if (error != nullptr)
      *error = fmt::format("cannot create {}: {}", sparse_dir.string(), ec.message());
    return false;
  }

  std::string cameras =
      "# Camera list with one line of data per camera:\n"
      "#   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
      "# Number of cameras: 1\n";
  cameras += fmt::format("1 {} {} {}", camera->model, camera->width, camera->height);
  for (double p : camera->params()) cameras += fmt::format(" {}", tidy(p));
  cameras += '\n';

  std::string images = fmt::format(
      "# Image list with two lines of data per image:\n"
      "#   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n"
      "#   POINTS2D[] as (X, Y, POINT3D_ID)\n"
      "# Number of images: {}, mean observations per image: {}\n",
      shots.size(), points ? tidy(mean_observations(*points)) : 0.0);
  for (std::size_t k = 0; k < shots.size(); ++k) {
    const int index = shots[k];
    const ir::Shot& shot = scene.shots[index];
    const ir::Mat4 pose = camera_from_object(shot);
    Eigen::Quaterniond q(Eigen::Matrix3d(pose.block<3, 3>(0, 0)));
    q.normalize();
    if (q.w() < 0) q.coeffs() *= -1;
    const ir::Vec3 t = pose.block<3, 1>(0, 3);
    images += fmt::format("{} {} {} {} {} {} {} {} 1 {}\n", index + 1, tidy(q.w()), tidy(q.x()),
                          tidy(q.y()), tidy(q.z()), tidy(t.x()), tidy(t.y()), tidy(t.z()),
                          image_file_name(scene.camera, shot));
    images += points ? observations_line(*points, k) : "";
    images += '\n';
  }

  return write_file_atomically(sparse_dir / "cameras.txt", cameras, error) &&
         write_file_atomically(sparse_dir / "images.txt", images, error) &&
         write_file_atomically(sparse_dir / "points3D.txt", points3d_text(shots, points), error);
}

namespace {

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) words.push_back(line.substr(start, i - start));
  }
  return words;
}

template <typename T>
bool parse_number(std::string_view word, T* value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), *value);
  return ec == std::errc() && end == word.data() + word.size();
}

bool is_blank_or_comment(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t\r");
  return first == std::string_view::npos || line[first] == '#';
}

// Calls `on_line(line, line_number)` for each data line; the callback returns false with an
// error message on malformed input.
template <typename OnLine>
bool read_lines(const fs::path& path, std::string* error, OnLine on_line) {
  std::string why;
  auto file = read_bounded_file(path, kMostCameraFileBytes, &why);
  if (!file) {
    if (error != nullptr) *error = fmt::format("cannot read {}: it {}", path.string(), why);
    return false;
  }
  std::istringstream in(std::move(file->bytes));
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (is_blank_or_comment(line)) continue;
    std::string message;
    if (!on_line(in, line, number, &message)) {
      if (error != nullptr) *error = fmt::format("{}:{}: {}", path.string(), number, message);
      return false;
    }
  }
  return true;
}

}  // namespace

std::optional<std::vector<ColmapImage>> read_colmap_images(const fs::path& path,
                                                           std::string* error) {
  std::vector<ColmapImage> images;
  std::set<std::string> names;
  const bool ok = read_lines(
      path, error,
      [&](std::istream& in, const std::string& line, int& number, std::string* message) {
        const auto words = split_words(line);
        ColmapImage image;
        double v[7];
        bool good = words.size() >= 10 && parse_number(words[0], &image.image_id) &&
                    parse_number(words[8], &image.camera_id);
        for (int i = 0; good && i < 7; ++i) good = parse_number(words[1 + i], &v[i]);
        if (!good) {
          *message = "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME";
          return false;
        }
        // NAME is the rest of the line (COLMAP names have no spaces; be lenient).
        const std::size_t name_start = static_cast<std::size_t>(words[9].data() - line.data());
        std::string_view name = std::string_view(line).substr(name_start);
        while (!name.empty() && std::isspace(static_cast<unsigned char>(name.back()))) {
          name.remove_suffix(1);
        }
        image.name = std::string(name);
        if (!std::all_of(std::begin(v), std::end(v), [](double x) { return std::isfinite(x); })) {
          *message = "the pose holds a number that is not finite";
          return false;
        }
        if (!names.insert(image.name).second) {
          *message = fmt::format("image '{}' is listed twice", image.name);
          return false;
        }
        Eigen::Quaterniond q(v[0], v[1], v[2], v[3]);
        if (!(std::abs(q.norm() - 1) <= kQuaternionTolerance)) {
          *message = fmt::format(
              "the quaternion QW QX QY QZ has length {:.6g}; a rotation's is 1 (within {})",
              q.norm(), kQuaternionTolerance);
          return false;
        }
        q.normalize();
        image.line = number;
        image.camera_from_world.block<3, 3>(0, 0) = q.toRotationMatrix();
        image.camera_from_world.block<3, 1>(0, 3) = ir::Vec3(v[4], v[5], v[6]);
        images.push_back(std::move(image));
        // The POINTS2D line follows (possibly empty); COLMAP reads it unconditionally.
        std::string points;
        if (std::getline(in, points)) ++number;
        return true;
      });
  if (!ok) return std::nullopt;
  return images;
}

namespace {

// What COLMAP could not use in a camera line (empty if nothing): its model with the parameter
// count COLMAP expects, a size of real images, finite parameters and positive focal lengths (a
// wrong height trips an assertion in OpenImageIO, a huge one exhausts memory, and a NaN focal
// length aborts COLMAP's matcher).
std::string camera_problem(const ColmapCamera& camera) {
  // COLMAP's camera models and their parameter counts (colmap/sensor/models.h); the focal
  // lengths come first in every one of them (one for the SIMPLE_ models, fx and fy otherwise).
  static const std::map<std::string, std::pair<std::size_t, int>> kModels = {
      {"SIMPLE_PINHOLE", {3, 1}},
      {"PINHOLE", {4, 2}},
      {"SIMPLE_RADIAL", {4, 1}},
      {"RADIAL", {5, 1}},
      {"OPENCV", {8, 2}},
      {"OPENCV_FISHEYE", {8, 2}},
      {"FULL_OPENCV", {12, 2}},
      {"FOV", {5, 2}},
      {"SIMPLE_RADIAL_FISHEYE", {4, 1}},
      {"RADIAL_FISHEYE", {5, 1}},
      {"THIN_PRISM_FISHEYE", {12, 2}}};
  const auto model = kModels.find(camera.model);
  if (model == kModels.end()) {
    return fmt::format("unknown camera model '{}' (COLMAP's are PINHOLE, OPENCV, ...)",
                       camera.model);
  }
  const auto [count, focals] = model->second;
  if (camera.params.size() != count) {
    return fmt::format("camera model {} takes {} parameters, not {}", camera.model, count,
                       camera.params.size());
  }
  constexpr int kLargestSide = 100000;
  if (camera.width < 1 || camera.height < 1 || camera.width > kLargestSide ||
      camera.height > kLargestSide) {
    return fmt::format("camera size {}x{} is not an image size (1 to {} pixels a side)",
                       camera.width, camera.height, kLargestSide);
  }
  for (double p : camera.params) {
    if (!std::isfinite(p)) return "a camera parameter is not a finite number";
  }
  const double most_focal = kMostFocalLengthPerSide * std::max(camera.width, camera.height);
  for (int i = 0; i < focals; ++i) {
    if (!(camera.params[i] > 0)) return "the focal length must be above 0";
    if (camera.params[i] > most_focal) {
      return fmt::format(
          "the focal length {:.6g} px is more than {} times the image's larger side ({} px)",
          camera.params[i], kMostFocalLengthPerSide, std::max(camera.width, camera.height));
    }
  }
  return {};
}

}  // namespace

std::optional<std::vector<ColmapCamera>> read_colmap_cameras(const fs::path& path,
                                                             std::string* error) {
  std::vector<ColmapCamera> cameras;
  std::set<int> ids;
  const bool ok = read_lines(
      path, error, [&](std::istream&, const std::string& line, int&, std::string* message) {
        const auto words = split_words(line);
        ColmapCamera camera;
        bool good = words.size() >= 4 && parse_number(words[0], &camera.camera_id) &&
                    parse_number(words[2], &camera.width) && parse_number(words[3], &camera.height);
        if (good) camera.model = std::string(words[1]);
        for (std::size_t i = 4; good && i < words.size(); ++i) {
          double p = 0;
          good = parse_number(words[i], &p);
          camera.params.push_back(p);
        }
        if (!good) {
          *message = "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]";
          return false;
        }
        *message = camera_problem(camera);
        if (!message->empty()) return false;
        if (!ids.insert(camera.camera_id).second) {
          *message = fmt::format("camera {} is listed twice", camera.camera_id);
          return false;
        }
        cameras.push_back(std::move(camera));
        return true;
      });
  if (!ok) return std::nullopt;
  if (cameras.empty()) {
    if (error != nullptr) *error = fmt::format("{} lists no camera", path.string());
    return std::nullopt;
  }
  return cameras;
}

bool check_camera_ids(const std::vector<ColmapImage>& images,
                      const std::vector<ColmapCamera>& cameras, const fs::path& images_path,
                      std::string* error) {
  std::set<int> ids;
  for (const ColmapCamera& camera : cameras) ids.insert(camera.camera_id);
  for (const ColmapImage& image : images) {
    if (ids.count(image.camera_id)) continue;
    if (error != nullptr) {
      const std::string at = image.line > 0 ? fmt::format("{}:{}", images_path.string(), image.line)
                                            : images_path.string();
      *error = fmt::format("{}: image '{}' uses camera {}, which the cameras file does not define",
                           at, image.name, image.camera_id);
    }
    return false;
  }
  return true;
}

ir::Vec2 project_opencv(const std::vector<double>& params, const ir::Mat4& camera_from_world,
                        const ir::Vec3& world_point) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::size_t n = params.size();
  if (n != 4 && n != 8 && n != 12) return {nan, nan};
  const ir::Vec3 p =
      camera_from_world.block<3, 3>(0, 0) * world_point + camera_from_world.block<3, 1>(0, 3);
  if (!(p.z() > 0)) return {nan, nan};
  const double x = p.x() / p.z(), y = p.y() / p.z();
  const auto k = [&](std::size_t i) { return i < n ? params[i] : 0.0; };
  const double k1 = k(4), k2 = k(5), p1 = k(6), p2 = k(7);
  const double k3 = k(8), k4 = k(9), k5 = k(10), k6 = k(11);
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial = (1 + k1 * r2 + k2 * r4 + k3 * r6) / (1 + k4 * r2 + k5 * r4 + k6 * r6);
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {params[0] * xd + params[2], params[1] * yd + params[3]};
}

}  // namespace rigc::run
