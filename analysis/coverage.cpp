#include "analysis/coverage.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "compiler/color.h"
#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "raster/rasterizer.h"

namespace rigc::analysis {
namespace {

using Eigen::Vector3d;
using Eigen::Vector3f;

constexpr int kBlurBins = 1000;  // histogram of blur / max_blur, 0..10
constexpr double kBlurBinWidth = 0.01;

struct ShotSums {
  double visible = 0, fresh = 0, overlap = 0, out_of_focus = 0, clipped = 0, dark = 0, oblique = 0,
         coarse = 0;
  double seen_gain[4] = {0, 0, 0, 0};  // area whose view count reached 1, 2, 3 in this shot
  double reconstructable_gain = 0;
  double nearest = 1e30;
  std::vector<double> blur_histogram = std::vector<double>(kBlurBins + 1, 0.0);
  std::vector<double> signal_histogram = std::vector<double>(ShotCoverage::kSignalBins, 0.0);
};

// Mean albedo luminance of each face: material colour, texture average, pattern average.
std::vector<float> face_albedo(const ir::Scene& scene, const scene::StudioScene& studio) {
  std::vector<float> material_albedo;
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const scene::ShadedMaterial& material = studio.materials[m];
    Vector3f color = material.base_color;
    if (material.texture >= 0 && material.texture < static_cast<int>(studio.textures.size()) &&
        !studio.textures[material.texture].levels.empty()) {
      color = color.cwiseProduct(studio.textures[material.texture].levels.back().texels[0]);
    }
    // A footprint far larger than the pattern gives the pattern's mean.
    const float pattern_mean = scene::pattern_factor(material.pattern, Vector3f::Zero(), 1e6f);
    material_albedo.push_back(static_cast<float>(luminance(color.cast<double>()) * pattern_mean *
                                                 (1 - material.metallic)));
  }
  std::vector<float> albedo(studio.object.triangles.size(), 0.5f);
  for (size_t f = 0; f < albedo.size(); ++f) {
    const int m = studio.object.triangle_material[f];
    if (m >= 0 && m < static_cast<int>(material_albedo.size())) albedo[f] = material_albedo[m];
  }
  return albedo;
}

}  // namespace

CoverageResult analyse_coverage(const ir::Scene& scene, const scene::StudioScene& studio,
                                const CoverageOptions& options) {
  const ir::Camera& camera = scene.camera;
  const ir::CoverageSettings& settings = scene.coverage;
  const scene::Geometry& mesh = studio.object;
  const size_t face_count = mesh.triangles.size();
  const int shot_count = static_cast<int>(scene.shots.size());

  CoverageResult result;
  result.face_area_m2.resize(face_count);
  result.views.assign(face_count, 0);
  result.usable_views.assign(face_count, 0);
  result.reconstructable.assign(face_count, 0);
  result.resting.assign(face_count, 0);
  result.first_seen.assign(face_count, CoverageResult::kNever);
  result.second_seen.assign(face_count, CoverageResult::kNever);
  std::vector<Vector3d> center(face_count), normal(face_count);
  for (size_t f = 0; f < face_count; ++f) {
    const auto& t = mesh.triangles[f];
    const Vector3d a = mesh.positions[t[0]].cast<double>(), b = mesh.positions[t[1]].cast<double>(),
                   c = mesh.positions[t[2]].cast<double>();
    const Vector3d cross = (b - a).cross(c - a);
    result.face_area_m2[f] = cross.norm() / 2;
    normal[f] = cross.norm() > 0 ? Vector3d(cross.normalized()) : Vector3d::UnitZ();
    center[f] = (a + b + c) / 3;
    // Faces on the table top, facing down: the turntable hides them from every camera.
    result.resting[f] = normal[f].z() < -0.9 && center[f].z() < 0.002;
    result.total_area_m2 += result.face_area_m2[f];
  }
  const std::vector<float> albedo = face_albedo(scene, studio);

  const double visibility_scale = options.visibility_scale > 0
                                      ? options.visibility_scale
                                      : std::min(1.0, 1400.0 / camera.width_px);
  const dslr::Intrinsics canvas = dslr::sensor_intrinsics(camera, visibility_scale);
  const double pixel_pitch_m = camera.sensor_width_m / camera.width_px;
  const double exposure = dslr::exposure_scale(camera);

  // usable_by_shot[s][f]: face f has a usable view in shot s (for triangulation pairs).
  std::vector<std::vector<std::uint8_t>> usable_by_shot(shot_count);
  std::vector<std::uint8_t> seen_previous(face_count, 0), seen_now(face_count, 0);
  std::vector<Vector3d> eye_object(shot_count);
  std::vector<double> blur_histogram(kBlurBins + 1, 0.0);
  const double cos_max_angle = std::cos(settings.max_view_angle_rad);
  const double cos_min_triangulation = std::cos(settings.min_triangulation_angle_rad);
  double seen_area[4] = {0, 0, 0, 0}, reconstructable_area = 0;

  for (int s = 0; s < shot_count; ++s) {
    const ir::Shot& shot = scene.shots[s];
    raster::FrameRequest request;
    request.world_from_camera = shot.world_from_camera;
    request.turntable_angle_rad = shot.turntable_angle_rad;
    request.canvas = canvas;
    const raster::VisibilityBuffer buffer = raster::render_visibility(scene, studio, request);
    const ir::Mat4 camera_from_object = shot.object_from_camera.inverse();
    const Eigen::Matrix3d rotation = camera_from_object.block<3, 3>(0, 0);
    const Vector3d translation = camera_from_object.block<3, 1>(0, 3);
    eye_object[s] = shot.object_from_camera.block<3, 1>(0, 3);
    const ir::Mat4 world_from_object = ir::world_from_object(scene, shot.turntable_angle_rad);
    const Eigen::Matrix3d world_rotation = world_from_object.block<3, 3>(0, 0);
    const Vector3d world_translation = world_from_object.block<3, 1>(0, 3);
    usable_by_shot[s].assign(face_count, 0);

    tbb::enumerable_thread_specific<ShotSums> sums;
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, face_count, 2048),
        [&](const tbb::blocked_range<size_t>& range) {
          ShotSums& sum = sums.local();
          for (size_t f = range.begin(); f != range.end(); ++f) {
            seen_now[f] = 0;
            const Vector3d to_eye = eye_object[s] - center[f];
            if (normal[f].dot(to_eye) <= 0) continue;
            const Vector3d p = rotation * center[f] + translation;
            if (p.z() <= 0.01) continue;
            const double u = canvas.fx * p.x() / p.z() + canvas.cx;
            const double v = canvas.fy * p.y() / p.z() + canvas.cy;
            if (u < 0 || v < 0 || u >= canvas.width || v >= canvas.height) continue;
            const size_t pixel = static_cast<size_t>(v) * canvas.width + static_cast<size_t>(u);
            // The face's own triangle at its centre pixel, or a surface at the same depth there
            // (faces smaller than a pixel of the buffer).
            const bool visible = buffer.object_triangle[pixel] == static_cast<std::int32_t>(f) ||
                                 p.z() <= buffer.depth_m[pixel] * 1.004 + 0.0015;
            if (!visible) continue;
            seen_now[f] = 1;
            const double area = result.face_area_m2[f];
            sum.visible += area;
            if (result.views[f] == 0) sum.fresh += area;
            if (seen_previous[f]) sum.overlap += area;
            if (result.views[f] == 0) result.first_seen[f] = static_cast<std::uint16_t>(s);
            if (result.views[f] == 1) result.second_seen[f] = static_cast<std::uint16_t>(s);
            sum.nearest = std::min(sum.nearest, p.z());
            ++result.views[f];
            if (result.views[f] <= 3) sum.seen_gain[result.views[f]] += area;

            // Footprint at full resolution.
            const auto& t = mesh.triangles[f];
            std::array<Eigen::Vector2d, 3> corner;
            for (int k = 0; k < 3; ++k) {
              const Vector3d q = rotation * mesh.positions[t[k]].cast<double>() + translation;
              corner[k] = {camera.fx * q.x() / q.z(), camera.fy * q.y() / q.z()};
            }
            const Eigen::Vector2d e1 = corner[1] - corner[0], e2 = corner[2] - corner[0];
            const double footprint_px = std::abs(e1.x() * e2.y() - e1.y() * e2.x()) / 2;
            const double pixels_per_mm2 = footprint_px / std::max(area * 1e6, 1e-12);
            const double cos_view = normal[f].dot(to_eye.normalized());
            const double blur_px =
                dslr::coc_diameter_m(camera.focal_length_m, camera.aperture_f_number,
                                     shot.focus_distance_m, p.z()) /
                pixel_pitch_m;
            const int bin = std::min(
                kBlurBins, static_cast<int>(blur_px / settings.max_blur_px / kBlurBinWidth));
            sum.blur_histogram[bin] += area;
            const Vector3f world_center =
                (world_rotation * center[f] + world_translation).cast<float>();
            const Vector3f world_normal = (world_rotation * normal[f]).cast<float>();
            double illuminance = scene.studio.ambient_lx;
            for (const auto& light : scene.studio.lights) {
              illuminance += luminance(
                  raster::light_illuminance(light, world_center, world_normal).cast<double>());
            }
            const double signal = albedo[f] * illuminance / std::numbers::pi * exposure;

            // A signal that is not a number (no light data) counts as the darkest.
            const double stops_over =
                std::isfinite(signal) ? std::log2(std::max(signal, 1e-300) / settings.max_signal)
                                      : ShotCoverage::kSignalLowestStops;
            const int signal_bin = static_cast<int>(
                std::clamp(std::floor((stops_over - ShotCoverage::kSignalLowestStops) /
                                      ShotCoverage::kSignalBinStops),
                           0.0, ShotCoverage::kSignalBins - 1.0));
            sum.signal_histogram[signal_bin] += area;

            const bool in_focus = blur_px <= settings.max_blur_px;
            const bool clipped = signal > settings.max_signal;
            const bool dark = signal < settings.min_signal;
            const bool oblique = cos_view < cos_max_angle;
            const bool coarse = pixels_per_mm2 < settings.min_pixels_per_mm2;
            if (!in_focus) sum.out_of_focus += area;
            if (clipped) sum.clipped += area;
            if (dark) sum.dark += area;
            if (oblique) sum.oblique += area;
            if (coarse) sum.coarse += area;
            if (!in_focus || clipped || dark || oblique || coarse) continue;

            usable_by_shot[s][f] = 1;
            ++result.usable_views[f];
            if (result.reconstructable[f]) continue;
            const Vector3d ray = to_eye.normalized();
            for (int earlier = 0; earlier < s; ++earlier) {
              if (!usable_by_shot[earlier][f]) continue;
              if (ray.dot((eye_object[earlier] - center[f]).normalized()) <=
                  cos_min_triangulation) {
                result.reconstructable[f] = 1;
                sum.reconstructable_gain += area;
                break;
              }
            }
          }
        });

    ShotSums total;
    for (const ShotSums& part : sums) {
      total.visible += part.visible;
      total.fresh += part.fresh;
      total.overlap += part.overlap;
      total.out_of_focus += part.out_of_focus;
      total.clipped += part.clipped;
      total.dark += part.dark;
      total.oblique += part.oblique;
      total.coarse += part.coarse;
      total.nearest = std::min(total.nearest, part.nearest);
      for (int k = 1; k <= 3; ++k) seen_area[k] += part.seen_gain[k];
      reconstructable_area += part.reconstructable_gain;
      for (int b = 0; b <= kBlurBins; ++b) blur_histogram[b] += part.blur_histogram[b];
      for (int b = 0; b < ShotCoverage::kSignalBins; ++b) {
        total.signal_histogram[b] += part.signal_histogram[b];
      }
    }
    ShotCoverage coverage;
    coverage.signal_histogram = total.signal_histogram;
    coverage.shot = s;
    coverage.visible_area_m2 = total.visible;
    coverage.new_area_m2 = total.fresh;
    const double visible = std::max(total.visible, 1e-30);
    coverage.overlap_with_previous = s > 0 ? total.overlap / visible : 0;
    coverage.out_of_focus = total.out_of_focus / visible;
    coverage.clipped = total.clipped / visible;
    coverage.too_dark = total.dark / visible;
    coverage.too_oblique = total.oblique / visible;
    coverage.too_coarse = total.coarse / visible;
    coverage.nearest_depth_m = total.nearest;
    size_t object_pixels = 0;
    for (const auto id : buffer.object_triangle) object_pixels += id >= 0;
    coverage.frame_fill = static_cast<double>(object_pixels) / buffer.object_triangle.size();
    const double total_area = std::max(result.total_area_m2, 1e-30);
    // Running totals: the faces that gained a view or became reconstructable in this shot.
    coverage.seen_1 = seen_area[1] / total_area;
    coverage.seen_2 = seen_area[2] / total_area;
    coverage.seen_3 = seen_area[3] / total_area;
    coverage.reconstructable = reconstructable_area / total_area;
    result.shots.push_back(coverage);
    std::swap(seen_previous, seen_now);
  }

  // The blur that 95 % of the seen surface stays within.
  double histogram_total = 0;
  for (double a : blur_histogram) histogram_total += a;
  double running = 0;
  for (int b = 0; b <= kBlurBins; ++b) {
    running += blur_histogram[b];
    if (running >= 0.95 * histogram_total) {
      result.blur_ratio_95 = (b + 1) * kBlurBinWidth;
      break;
    }
  }
  return result;
}

}  // namespace rigc::analysis
