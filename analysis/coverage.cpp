#include "analysis/coverage.h"

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "ir/color.h"
#include "raster/rasterizer.h"

namespace rigc::analysis {

bool CoverageOptions::check(std::string* error) const {
  if (visibility_scale == 0 || (visibility_scale >= 0.01 && visibility_scale <= 1)) return true;
  if (error) {
    *error = fmt::format("visibility_scale {} is neither 0 (automatic) nor within 0.01..1",
                         visibility_scale);
  }
  return false;
}

namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

constexpr int kBlurBins = 1000;  // histogram of blur / max_blur, 0..10
constexpr double kBlurBinWidth = 0.01;

// Areas (m²) of one shot's visible surface, summed per thread and then over the threads.
struct ShotAreas {
  double visible = 0, fresh = 0, overlap = 0;
  double out_of_focus = 0, clipped = 0, dark = 0, oblique = 0, coarse = 0;
  double nearest_depth_m = 1e30;
  std::vector<double> signal_histogram = std::vector<double>(ShotCoverage::kSignalBins, 0.0);

  void add(const ShotAreas& part) {
    visible += part.visible;
    fresh += part.fresh;
    overlap += part.overlap;
    out_of_focus += part.out_of_focus;
    clipped += part.clipped;
    dark += part.dark;
    oblique += part.oblique;
    coarse += part.coarse;
    nearest_depth_m = std::min(nearest_depth_m, part.nearest_depth_m);
    for (int b = 0; b < ShotCoverage::kSignalBins; ++b) {
      signal_histogram[b] += part.signal_histogram[b];
    }
  }
};

// What one shot adds to the totals over all shots so far (m²).
struct CumulativeGain {
  double seen[4] = {0, 0, 0, 0};  // area whose view count reached 1, 2, 3 in this shot
  double reconstructable = 0;
  std::vector<double> blur_histogram = std::vector<double>(kBlurBins + 1, 0.0);
};

// One thread's sums over the faces it visited in a shot.
struct ShotSums {
  ShotAreas areas;
  CumulativeGain gain;
};

// Totals over all shots so far.
struct CumulativeTotals {
  double seen_area[4] = {0, 0, 0, 0};  // area seen by at least 1, 2, 3 shots (index = views)
  double reconstructable_area = 0;
  std::vector<double> blur_histogram = std::vector<double>(kBlurBins + 1, 0.0);

  void add(const CumulativeGain& part) {
    for (int k = 1; k <= 3; ++k) seen_area[k] += part.seen[k];
    reconstructable_area += part.reconstructable;
    for (int b = 0; b <= kBlurBins; ++b) blur_histogram[b] += part.blur_histogram[b];
  }

  // The blur (a multiple of max_blur_px) that 95 % of the seen surface stays within.
  double blur_ratio_95() const {
    double histogram_total = 0;
    for (double a : blur_histogram) histogram_total += a;
    double running = 0;
    for (int b = 0; b <= kBlurBins; ++b) {
      running += blur_histogram[b];
      if (running >= 0.95 * histogram_total) return (b + 1) * kBlurBinWidth;
    }
    return 0;
  }
};

// One shot as the analysis needs it: the camera and the turntable in the object frame, and what
// the camera sees (from a visibility buffer at the reduced canvas).
struct ShotView {
  int index = 0;
  const ir::Shot* shot = nullptr;
  std::shared_ptr<const ShotVisibility> visibility;
  Eigen::Matrix3d camera_rotation;  // camera_from_object
  Vector3d camera_translation;
  Vector3d eye;                    // camera centre, object frame
  Eigen::Matrix3d world_rotation;  // world_from_object at the shot's turntable angle
  Vector3d world_translation;

  Vector3d to_camera(const Vector3d& object_point) const {
    return camera_rotation * object_point + camera_translation;
  }
};

// A face as one shot sees it: the quantities the usability tests judge.
struct FaceView {
  double pixels_per_mm2 = 0;  // footprint on the sensor at full resolution per mm² of surface
  double cos_view = 0;        // cosine of the angle between the normal and the line of sight
  double blur_px = 0;         // circle of confusion in sensor pixels
  double signal = 0;          // in the units of min_signal and max_signal (clipping)
};

// Why SfM cannot use a view of a face (all false: it can).
struct ViewFaults {
  bool out_of_focus = false, clipped = false, dark = false, oblique = false, coarse = false;
  bool any() const { return out_of_focus || clipped || dark || oblique || coarse; }
};

}  // namespace

std::vector<float> face_albedo(const ir::Scene& scene, const scene::StudioScene& studio) {
  const scene::Geometry& object = studio.object;
  std::vector<float> material_albedo, material_factor;
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const scene::ShadedMaterial& material = studio.materials[m];
    Vector3f color = material.base_color;
    if (material.texture >= 0 && material.texture < static_cast<int>(studio.textures.size()) &&
        !studio.textures[material.texture].levels.empty()) {
      color = color.cwiseProduct(studio.textures[material.texture].levels.back().texels[0]);
    }
    // A footprint far larger than the pattern gives the pattern's mean.
    const float pattern_mean = scene::pattern_factor(material.pattern, Vector3f::Zero(), 1e6f);
    material_factor.push_back(pattern_mean * (1 - material.metallic));
    material_albedo.push_back(
        static_cast<float>(luminance(color.cast<double>()) * material_factor.back()));
  }
  std::vector<float> albedo(object.triangles.size(), 0.5f);
  for (size_t f = 0; f < albedo.size(); ++f) {
    const int m = object.triangle_material[f];
    if (m < 0 || m >= static_cast<int>(material_albedo.size())) continue;
    albedo[f] = material_albedo[m];
    if (!object.colors.empty()) {
      const auto& t = object.triangles[f];
      const Vector3f mean = (object.colors[t[0]] + object.colors[t[1]] + object.colors[t[2]]) / 3;
      albedo[f] = static_cast<float>(luminance(mean.cast<double>()) * material_factor[m]);
    }
  }
  return albedo;
}

// The whole analysis: per shot, per face visibility, usability and triangulation; the per-face
// state persists across shots (view counts, usable views by shot). Shots are added in order.
class CoverageAnalysis {
 public:
  CoverageAnalysis(const ir::Scene& scene, const scene::StudioScene& studio,
                   const CoverageOptions& options);
  CoverageAnalysis(const CoverageAnalysis&) = default;
  // Analyses `shot` (of a scene that differs from the constructor's in its shots alone) as the
  // next shot.
  void add_shot(const ir::Shot& shot);
  CoverageResult result() const;
  int shot_count() const { return static_cast<int>(result_.shots.size()); }

 private:
  void measure_faces();
  ShotView view_shot(int s, const ir::Shot& shot) const;
  std::string visibility_key(const ShotView& view) const;
  ShotVisibility see_faces(const ShotView& view) const;
  bool sees_face(const ShotView& view, const raster::VisibilityBuffer& buffer, size_t f) const;
  ShotAreas analyse_faces(const ShotView& view);
  void analyse_face(const ShotView& view, size_t f, ShotSums& sum);
  void count_view(int s, size_t f, double depth_m, ShotAreas& areas, CumulativeGain& gain);
  FaceView measure_face_view(const ShotView& view, size_t f, const Vector3d& to_eye,
                             double depth_m) const;
  double footprint_px(const ShotView& view, size_t f) const;
  double face_signal(const ShotView& view, size_t f) const;
  void keep_sight(const ShotView& view);
  void add_to_histograms(const FaceView& face, double area, ShotSums& sum) const;
  ViewFaults judge(const FaceView& face) const;
  bool triangulates_with_earlier_shot(int s, size_t f, const Vector3d& to_eye) const;
  ShotCoverage summarise_shot(const ShotView& view, const ShotAreas& areas) const;

  const ir::Scene& scene_;
  const scene::StudioScene& studio_;
  const ir::Camera& camera_;
  const ir::CoverageSettings& settings_;
  const scene::Geometry& mesh_;
  const size_t face_count_;
  const dslr::Intrinsics canvas_;
  const double pixel_pitch_m_;
  const double exposure_;
  const double cos_max_angle_;
  const double cos_min_triangulation_;
  const bool keep_sights_;
  const std::shared_ptr<VisibilityCache> visibility_cache_;
  std::string geometry_key_;  // what the visibility depends on besides the shot's poses

  CoverageResult result_;
  std::vector<Vector3d> center_, normal_;  // object frame
  std::vector<float> albedo_;
  // usable_by_shot_[s][f]: face f has a usable view in shot s (for triangulation pairs).
  std::vector<std::vector<std::uint8_t>> usable_by_shot_;
  std::vector<std::uint8_t> seen_previous_, seen_now_;
  std::vector<Vector3d> eye_by_shot_;  // camera centres, object frame
  CumulativeTotals totals_;
};

namespace {

double visibility_scale(const CoverageOptions& options, const ir::Camera& camera) {
  return options.visibility_scale > 0 ? options.visibility_scale
                                      : std::min(1.0, 1400.0 / camera.width_px);
}

// Appends the bytes of a fixed-size Eigen matrix (its values, not its padding).
template <class Matrix>
void append_bytes(std::string& key, const Matrix& m) {
  const typename Matrix::PlainObject values = m;
  key.append(reinterpret_cast<const char*>(values.data()),
             sizeof(typename Matrix::Scalar) * values.size());
}

template <class T>
std::size_t hash_of(const std::vector<T>& values) {
  return std::hash<std::string_view>()(
      std::string_view(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)));
}

// What the visibility buffers depend on besides the poses: the object's and the studio's
// meshes (hashed, with their sizes), which solids are closed, and the canvas.
std::string geometry_key(const scene::StudioScene& studio, const dslr::Intrinsics& canvas) {
  return fmt::format("{:x}/{}/{:x}/{}/{:x}/{}/{:x}/{}/{}/{}/{}x{}/{}/{}/{}/{}/",
                     hash_of(studio.object.positions), studio.object.positions.size(),
                     hash_of(studio.object.triangles), studio.object.triangles.size(),
                     hash_of(studio.studio.positions), studio.studio.positions.size(),
                     hash_of(studio.studio.triangles), studio.studio.triangles.size(),
                     studio.object_closed, studio.closed_studio_triangles, canvas.width,
                     canvas.height, canvas.fx, canvas.fy, canvas.cx, canvas.cy);
}

}  // namespace

CoverageAnalysis::CoverageAnalysis(const ir::Scene& scene, const scene::StudioScene& studio,
                                   const CoverageOptions& options)
    : scene_(scene),
      studio_(studio),
      camera_(scene.camera),
      settings_(scene.coverage),
      mesh_(studio.object),
      face_count_(mesh_.triangles.size()),
      canvas_(dslr::sensor_intrinsics(camera_, visibility_scale(options, camera_))),
      pixel_pitch_m_(camera_.sensor_width_m / camera_.width_px),
      exposure_(dslr::exposure_scale(camera_)),
      cos_max_angle_(std::cos(settings_.max_view_angle_rad)),
      cos_min_triangulation_(std::cos(settings_.min_triangulation_angle_rad)),
      keep_sights_(options.keep_sights),
      visibility_cache_(options.visibility_cache),
      seen_previous_(face_count_, 0),
      seen_now_(face_count_, 0) {
  std::string error;
  if (!options.check(&error)) throw std::invalid_argument(error);
  measure_faces();
  albedo_ = face_albedo(scene_, studio_);
  if (visibility_cache_) geometry_key_ = geometry_key(studio_, canvas_);
}

void CoverageAnalysis::add_shot(const ir::Shot& shot) {
  const int s = shot_count();
  usable_by_shot_.emplace_back();
  eye_by_shot_.emplace_back();
  const ShotView view = view_shot(s, shot);
  result_.shots.push_back(summarise_shot(view, analyse_faces(view)));
  if (keep_sights_) keep_sight(view);
  std::swap(seen_previous_, seen_now_);
}

CoverageResult CoverageAnalysis::result() const {
  CoverageResult result = result_;
  result.blur_ratio_95 = totals_.blur_ratio_95();
  if (keep_sights_) {
    result.face_center = center_;
    result.face_normal = normal_;
  }
  return result;
}

// Every face in one shot, in parallel; returns the shot's areas and adds its gains to the
// totals.
ShotAreas CoverageAnalysis::analyse_faces(const ShotView& view) {
  eye_by_shot_[view.index] = view.eye;
  usable_by_shot_[view.index].assign(face_count_, 0);
  tbb::enumerable_thread_specific<ShotSums> sums;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, face_count_, 2048),
                    [&](const tbb::blocked_range<size_t>& range) {
                      ShotSums& sum = sums.local();
                      for (size_t f = range.begin(); f != range.end(); ++f) {
                        analyse_face(view, f, sum);
                      }
                    });
  ShotAreas areas;
  for (const ShotSums& part : sums) {
    areas.add(part.areas);
    totals_.add(part.gain);
  }
  return areas;
}

// Area, centre and normal of every face; the faces resting on the turntable.
void CoverageAnalysis::measure_faces() {
  result_.face_area_m2.resize(face_count_);
  result_.views.assign(face_count_, 0);
  result_.usable_views.assign(face_count_, 0);
  result_.reconstructable.assign(face_count_, 0);
  result_.resting.assign(face_count_, 0);
  result_.first_seen.assign(face_count_, CoverageResult::kNever);
  result_.second_seen.assign(face_count_, CoverageResult::kNever);
  center_.resize(face_count_);
  normal_.resize(face_count_);
  for (size_t f = 0; f < face_count_; ++f) {
    const auto& t = mesh_.triangles[f];
    const Vector3d a = mesh_.positions[t[0]].cast<double>(),
                   b = mesh_.positions[t[1]].cast<double>(),
                   c = mesh_.positions[t[2]].cast<double>();
    const Vector3d cross = (b - a).cross(c - a);
    result_.face_area_m2[f] = cross.norm() / 2;
    normal_[f] = cross.norm() > 0 ? Vector3d(cross.normalized()) : Vector3d::UnitZ();
    center_[f] = (a + b + c) / 3;
    // Faces on the table top, facing down: the turntable hides them from every camera.
    result_.resting[f] = normal_[f].z() < -0.9 && center_[f].z() < 0.002;
    result_.total_area_m2 += result_.face_area_m2[f];
  }
}

// The shot's poses, and what it sees: from the cache when it holds this geometry seen from here.
ShotView CoverageAnalysis::view_shot(int s, const ir::Shot& shot) const {
  ShotView view;
  view.index = s;
  view.shot = &shot;
  const ir::Mat4 camera_from_object = shot.object_from_camera.inverse();
  view.camera_rotation = camera_from_object.block<3, 3>(0, 0);
  view.camera_translation = camera_from_object.block<3, 1>(0, 3);
  view.eye = shot.object_from_camera.block<3, 1>(0, 3);
  const ir::Mat4 world_from_object = ir::world_from_object(scene_, shot.turntable_angle_rad);
  view.world_rotation = world_from_object.block<3, 3>(0, 0);
  view.world_translation = world_from_object.block<3, 1>(0, 3);
  if (!visibility_cache_) {
    view.visibility = std::make_shared<const ShotVisibility>(see_faces(view));
    return view;
  }
  const std::string key = visibility_key(view);
  view.visibility = visibility_cache_->find(key);
  if (!view.visibility) {
    view.visibility = std::make_shared<const ShotVisibility>(see_faces(view));
    visibility_cache_->insert(key, view.visibility);
  }
  return view;
}

// The geometry's fingerprint, the poses and the canvas, byte for byte.
std::string CoverageAnalysis::visibility_key(const ShotView& view) const {
  std::string key = geometry_key_;
  append_bytes(key, view.shot->world_from_camera);
  append_bytes(key, view.shot->object_from_camera);
  append_bytes(key, view.world_rotation);
  append_bytes(key, view.world_translation);
  return key;
}

// Renders the shot's visibility buffer and tells from it which faces the shot sees.
ShotVisibility CoverageAnalysis::see_faces(const ShotView& view) const {
  raster::FrameRequest request;
  request.world_from_camera = view.shot->world_from_camera;
  request.turntable_angle_rad = view.shot->turntable_angle_rad;
  request.canvas = canvas_;
  const raster::VisibilityBuffer buffer = raster::render_visibility(scene_, studio_, request);
  ShotVisibility sight;
  sight.seen.assign(face_count_, 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, face_count_, 4096),
                    [&](const tbb::blocked_range<size_t>& range) {
                      for (size_t f = range.begin(); f != range.end(); ++f) {
                        sight.seen[f] = sees_face(view, buffer, f);
                      }
                    });
  for (const auto id : buffer.object_triangle) sight.object_pixels += id >= 0;
  sight.pixels = buffer.object_triangle.size();
  return sight;
}

void CoverageAnalysis::analyse_face(const ShotView& view, size_t f, ShotSums& sum) {
  seen_now_[f] = 0;
  const Vector3d to_eye = view.eye - center_[f];
  if (!view.visibility->seen[f]) return;
  const double depth_m = view.to_camera(center_[f]).z();
  seen_now_[f] = 1;
  count_view(view.index, f, depth_m, sum.areas, sum.gain);

  const double area = result_.face_area_m2[f];
  const FaceView face = measure_face_view(view, f, to_eye, depth_m);
  add_to_histograms(face, area, sum);
  const ViewFaults faults = judge(face);
  if (faults.out_of_focus) sum.areas.out_of_focus += area;
  if (faults.clipped) sum.areas.clipped += area;
  if (faults.dark) sum.areas.dark += area;
  if (faults.oblique) sum.areas.oblique += area;
  if (faults.coarse) sum.areas.coarse += area;
  if (faults.any()) return;

  usable_by_shot_[view.index][f] = 1;
  ++result_.usable_views[f];
  if (result_.reconstructable[f]) return;
  if (triangulates_with_earlier_shot(view.index, f, to_eye)) {
    result_.reconstructable[f] = 1;
    sum.gain.reconstructable += area;
  }
}

// Whether the camera sees the face's centre: facing the camera, in front of it, inside the
// canvas, and not hidden.
bool CoverageAnalysis::sees_face(const ShotView& view, const raster::VisibilityBuffer& buffer,
                                 size_t f) const {
  if (normal_[f].dot(view.eye - center_[f]) <= 0) return false;
  const Vector3d p = view.to_camera(center_[f]);
  if (p.z() <= 0.01) return false;
  const double u = canvas_.fx * p.x() / p.z() + canvas_.cx;
  const double v = canvas_.fy * p.y() / p.z() + canvas_.cy;
  if (u < 0 || v < 0 || u >= canvas_.width || v >= canvas_.height) return false;
  const size_t pixel = static_cast<size_t>(v) * canvas_.width + static_cast<size_t>(u);
  // The face's own triangle at its centre pixel, or a surface at the same depth there (faces
  // smaller than a pixel of the buffer).
  return buffer.object_triangle[pixel] == static_cast<std::int32_t>(f) ||
         p.z() <= buffer.depth_m[pixel] * 1.004 + 0.0015;
}

// Records that shot `s` sees face `f`: view counts, first and second sighting, new and
// overlapping area.
void CoverageAnalysis::count_view(int s, size_t f, double depth_m, ShotAreas& areas,
                                  CumulativeGain& gain) {
  const double area = result_.face_area_m2[f];
  areas.visible += area;
  if (result_.views[f] == 0) areas.fresh += area;
  if (seen_previous_[f]) areas.overlap += area;
  if (result_.views[f] == 0) result_.first_seen[f] = static_cast<std::uint16_t>(s);
  if (result_.views[f] == 1) result_.second_seen[f] = static_cast<std::uint16_t>(s);
  areas.nearest_depth_m = std::min(areas.nearest_depth_m, depth_m);
  ++result_.views[f];
  if (result_.views[f] <= 3) gain.seen[result_.views[f]] += area;
}

FaceView CoverageAnalysis::measure_face_view(const ShotView& view, size_t f, const Vector3d& to_eye,
                                             double depth_m) const {
  FaceView face;
  face.pixels_per_mm2 = footprint_px(view, f) / std::max(result_.face_area_m2[f] * 1e6, 1e-12);
  face.cos_view = normal_[f].dot(to_eye.normalized());
  face.blur_px = dslr::coc_diameter_m(camera_.focal_length_m, camera_.aperture_f_number,
                                      view.shot->focus_distance_m, depth_m) /
                 pixel_pitch_m_;
  face.signal = face_signal(view, f);
  return face;
}

// The face's area on the sensor in pixels, at full resolution.
double CoverageAnalysis::footprint_px(const ShotView& view, size_t f) const {
  const auto& t = mesh_.triangles[f];
  std::array<Eigen::Vector2d, 3> corner;
  for (int k = 0; k < 3; ++k) {
    const Vector3d q = view.to_camera(mesh_.positions[t[k]].cast<double>());
    corner[k] = {camera_.fx * q.x() / q.z(), camera_.fy * q.y() / q.z()};
  }
  const Eigen::Vector2d e1 = corner[1] - corner[0], e2 = corner[2] - corner[0];
  return std::abs(e1.x() * e2.y() - e1.y() * e2.x()) / 2;
}

// The sensor signal of a face's diffuse reflection: albedo x illuminance / pi x exposure, each
// light's illuminance shaped by the preview's diffuse lobe (see docs/camera-model.md).
double CoverageAnalysis::face_signal(const ShotView& view, size_t f) const {
  const Vector3d center = view.world_rotation * center_[f] + view.world_translation;
  const Vector3d eye = view.world_rotation * view.eye + view.world_translation;
  const Vector3f world_center = center.cast<float>();
  const Vector3f world_normal = (view.world_rotation * normal_[f]).cast<float>();
  const Vector3f to_eye = (eye - center).normalized().cast<float>();
  const int m = mesh_.triangle_material[f];
  const float roughness = m >= 0 && m < static_cast<int>(studio_.materials.size())
                              ? studio_.materials[m].roughness
                              : 0.5f;
  double illuminance = scene_.studio.ambient_lx;
  for (const auto& light : scene_.studio.lights) {
    const Vector3f reflected =
        raster::diffuse_illuminance(light, world_center, world_normal, to_eye, roughness);
    illuminance += luminance(reflected.cast<double>());
  }
  return albedo_[f] * illuminance / std::numbers::pi * exposure_;
}

void CoverageAnalysis::keep_sight(const ShotView& view) {
  ShotSight sight;
  sight.eye = view.eye;
  const std::vector<std::uint8_t>& usable = usable_by_shot_[view.index];
  for (size_t f = 0; f < face_count_; ++f) {
    if (seen_now_[f]) sight.seen.push_back(static_cast<std::uint32_t>(f));
    if (usable[f]) sight.usable.push_back(static_cast<std::uint32_t>(f));
  }
  result_.sights.push_back(std::move(sight));
}

void CoverageAnalysis::add_to_histograms(const FaceView& face, double area, ShotSums& sum) const {
  const int blur_bin =
      std::min(kBlurBins, static_cast<int>(face.blur_px / settings_.max_blur_px / kBlurBinWidth));
  sum.gain.blur_histogram[blur_bin] += area;
  // A signal that is not a number (no light data) counts as the darkest.
  const double stops_over = std::isfinite(face.signal)
                                ? std::log2(std::max(face.signal, 1e-300) / settings_.max_signal)
                                : ShotCoverage::kSignalLowestStops;
  const int signal_bin = static_cast<int>(std::clamp(
      std::floor((stops_over - ShotCoverage::kSignalLowestStops) / ShotCoverage::kSignalBinStops),
      0.0, ShotCoverage::kSignalBins - 1.0));
  sum.areas.signal_histogram[signal_bin] += area;
}

// The usability tests: resolution on the surface, viewing angle, focus, exposure.
ViewFaults CoverageAnalysis::judge(const FaceView& face) const {
  ViewFaults faults;
  faults.out_of_focus = !(face.blur_px <= settings_.max_blur_px);
  faults.clipped = face.signal > settings_.max_signal;
  faults.dark = face.signal < settings_.min_signal;
  faults.oblique = face.cos_view < cos_max_angle_;
  faults.coarse = face.pixels_per_mm2 < settings_.min_pixels_per_mm2;
  return faults;
}

// Whether a usable view of face `f` in an earlier shot sees it from a direction at least the
// minimum triangulation angle away from shot `s`'s.
bool CoverageAnalysis::triangulates_with_earlier_shot(int s, size_t f,
                                                      const Vector3d& to_eye) const {
  const Vector3d ray = to_eye.normalized();
  for (int earlier = 0; earlier < s; ++earlier) {
    if (!usable_by_shot_[earlier][f]) continue;
    if (ray.dot((eye_by_shot_[earlier] - center_[f]).normalized()) <= cos_min_triangulation_) {
      return true;
    }
  }
  return false;
}

ShotCoverage CoverageAnalysis::summarise_shot(const ShotView& view, const ShotAreas& areas) const {
  ShotCoverage coverage;
  coverage.signal_histogram = areas.signal_histogram;
  coverage.shot = view.index;
  coverage.visible_area_m2 = areas.visible;
  coverage.new_area_m2 = areas.fresh;
  const double visible = std::max(areas.visible, 1e-30);
  coverage.overlap_with_previous = view.index > 0 ? areas.overlap / visible : 0;
  coverage.out_of_focus = areas.out_of_focus / visible;
  coverage.clipped = areas.clipped / visible;
  coverage.too_dark = areas.dark / visible;
  coverage.too_oblique = areas.oblique / visible;
  coverage.too_coarse = areas.coarse / visible;
  coverage.nearest_depth_m = areas.nearest_depth_m;
  coverage.frame_fill = static_cast<double>(view.visibility->object_pixels) /
                        static_cast<double>(view.visibility->pixels);
  const double total_area = std::max(result_.total_area_m2, 1e-30);
  coverage.seen_1 = totals_.seen_area[1] / total_area;
  coverage.seen_2 = totals_.seen_area[2] / total_area;
  coverage.seen_3 = totals_.seen_area[3] / total_area;
  coverage.reconstructable = totals_.reconstructable_area / total_area;
  return coverage;
}

CoverageResult analyse_coverage(const ir::Scene& scene, const scene::StudioScene& studio,
                                const CoverageOptions& options) {
  CoverageAnalysis analysis(scene, studio, options);
  for (const ir::Shot& shot : scene.shots) analysis.add_shot(shot);
  return analysis.result();
}

IncrementalCoverage::IncrementalCoverage(std::shared_ptr<const ir::Scene> scene,
                                         std::shared_ptr<const scene::StudioScene> studio,
                                         const CoverageOptions& options)
    : scene_(std::move(scene)),
      studio_(std::move(studio)),
      analysis_(std::make_unique<CoverageAnalysis>(*scene_, *studio_, options)) {}

IncrementalCoverage::~IncrementalCoverage() = default;

int IncrementalCoverage::shot_count() const {
  return analysis_->shot_count();
}

void IncrementalCoverage::add_shot(const ir::Shot& shot) {
  before_.push_back(std::make_unique<CoverageAnalysis>(*analysis_));
  if (before_.size() > kUndoDepth) before_.pop_front();
  shots_.push_back(shot);
  analysis_->add_shot(shot);
}

void IncrementalCoverage::forget_undo() {
  before_.clear();
}

bool IncrementalCoverage::remove_last_shot() {
  if (before_.empty()) return false;
  analysis_ = std::move(before_.back());
  before_.pop_back();
  shots_.pop_back();
  return true;
}

CoverageResult IncrementalCoverage::result() const {
  return analysis_->result();
}

}  // namespace rigc::analysis
