#include "dslr/exposure.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "dslr/lens.h"

namespace rigc::dslr {

double ev100(double f_number, double shutter_s, double iso) {
  return std::log2(f_number * f_number / shutter_s) - std::log2(iso / 100.0);
}

double exposure_scale(const ir::Camera& camera) {
  const double n = camera.aperture_f_number;
  return camera.shutter_s * camera.iso * kExposureQ / (78.0 * n * n);
}

namespace {

void expose_into(const ir::Camera& camera, const float* radiance, float* signal, std::size_t n) {
  const float scale = static_cast<float>(exposure_scale(camera));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 16),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        const float v = radiance[i] * scale;
                        signal[i] = v > 0 && v < std::numeric_limits<float>::infinity() ? v : 0;
                      }
                    });
}

}  // namespace

std::vector<float> expose(const ir::Camera& camera, const std::vector<float>& radiance) {
  std::vector<float> signal(radiance.size());
  expose_into(camera, radiance.data(), signal.data(), radiance.size());
  return signal;
}

void expose_in_place(const ir::Camera& camera, std::vector<float>& radiance) {
  expose_into(camera, radiance.data(), radiance.data(), radiance.size());
}

double motion_blur_length_px(double angular_velocity_rad_s, double shutter_s,
                             double radius_perpendicular_m, double depth_m, double f_px) {
  if (!(depth_m > 0)) return 0;
  return std::abs(angular_velocity_rad_s) * shutter_s * std::abs(radius_perpendicular_m) * f_px /
         depth_m;
}

double motion_blur_length_px(const ir::Camera& camera, double scale, double angular_velocity_rad_s,
                             double radius_perpendicular_m, double depth_m) {
  return motion_blur_length_px(angular_velocity_rad_s, camera.shutter_s, radius_perpendicular_m,
                               depth_m, sensor_intrinsics(camera, scale).fx);
}

}  // namespace rigc::dslr
