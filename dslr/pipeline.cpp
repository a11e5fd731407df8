#include "dslr/pipeline.h"

#include <chrono>
#include <string>
#include <utility>

#include "dslr/buffer_pool.h"
#include "dslr/develop.h"
#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/optics.h"
#include "dslr/sensor.h"

namespace rigc::dslr {

int output_bits(const ir::Camera& camera) {
  return camera.format == ir::ImageFormat::kJpeg ? 8 : 16;
}

namespace {

class StageClock {
 public:
  double lap_ms() {
    const auto now = std::chrono::steady_clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - last_).count();
    last_ = now;
    return ms;
  }

 private:
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

std::string check_frame(const LinearFrame& frame) {
  const std::size_t n =
      static_cast<std::size_t>(std::max(0, frame.width)) * std::max(0, frame.height);
  if (frame.width <= 0 || frame.height <= 0) return "the frame has no pixels";
  if (!(frame.fx > 0) || !(frame.fy > 0)) return "the frame has no focal length in pixels";
  if (frame.rgb.size() != 3 * n) {
    return "the frame's rgb has " + std::to_string(frame.rgb.size()) + " values, expected " +
           std::to_string(3 * n);
  }
  if (!frame.depth_m.empty() && frame.depth_m.size() != n) {
    return "the frame's depth has " + std::to_string(frame.depth_m.size()) + " values, expected " +
           std::to_string(n);
  }
  if (!frame.mask.empty() && frame.mask.size() != n) {
    return "the frame's mask has " + std::to_string(frame.mask.size()) + " values, expected " +
           std::to_string(n);
  }
  return {};
}

// The stages after the frame's checks, on `work`: the frame's radiance, copied or taken from it
// (the frame's own rgb is not read). `owned` (the frame itself, or null when it is the caller's):
// its depth and mask go back to the buffer pool once the sensor grid has its own.
DevelopResult develop(const ir::Camera& camera, const LinearFrame& frame, LinearFrame* owned,
                      std::vector<float> work, const ShotParams& shot, double scale) {
  DevelopResult result;
  StageClock clock;
  // Depth of field and diffraction are linear, so a clean frame's exposure can wait for the
  // warp's gain; any other frame is scaled here, which also zeroes its negative and non-finite
  // values before a blur could spread them.
  double signal_scale = 1;
  if (frame.rgb_clean) {
    signal_scale = exposure_scale(camera);
  } else {
    expose_in_place(camera, work);
  }
  result.timings.exposure_ms = clock.lap_ms();

  const Intrinsics canvas = frame.intrinsics();
  const Intrinsics sensor = sensor_intrinsics(camera, scale);
  std::vector<float> scratch = take_floats(work.size());
  if (camera.effects.depth_of_field && !frame.depth_m.empty()) {
    // The frame's tile ranges describe its own values: those of `work` only when no exposure
    // pass has scaled them.
    DepthOfFieldOptions options;
    if (frame.rgb_clean) options.tile_ranges = &frame.tile_ranges;
    apply_depth_of_field_in_place(camera, shot.focus_distance_m, canvas, work, frame.depth_m,
                                  scratch, options);
  }
  result.timings.depth_of_field_ms = clock.lap_ms();

  if (camera.effects.diffraction) apply_diffraction(camera, canvas, work);
  result.timings.diffraction_ms = clock.lap_ms();

  static const std::vector<float> no_depth;
  SensorImage image =
      warp_to_sensor(camera, sensor, canvas, work, shot.sensor_depth ? frame.depth_m : no_depth,
                     frame.mask, std::move(scratch), signal_scale);
  recycle(std::move(work));
  if (owned != nullptr) {
    recycle(std::move(owned->depth_m));
    recycle(std::move(owned->mask));
  }
  result.timings.distortion_ms = clock.lap_ms();

  result.width = sensor.width;
  result.height = sensor.height;
  result.bits = output_bits(camera);
  if (!shot.keep_linear && camera.white_balance == ir::WhiteBalanceMode::kKelvin) {
    // The gains do not depend on the image: noise and encoding in one pass (timed as noise).
    const auto gains = white_balance_gains(camera, {}, {});
    result.white_balance_gains = gains;
    const SrgbEncoding encoding = srgb_encoding(gains, result.bits);
    const ImageView<const float> signal =
        view_of(std::as_const(image.rgb), sensor.width, sensor.height);
    if (result.bits == 8) {
      result.encoded_bytes =
          apply_sensor_and_encode_bytes(camera, signal, {shot.seed, shot.shot_index}, encoding);
    } else {
      result.encoded =
          apply_sensor_and_encode(camera, signal, {shot.seed, shot.shot_index}, encoding);
    }
    recycle(std::move(image.rgb));
    result.timings.noise_ms = clock.lap_ms();
  } else {
    apply_sensor(camera, view_of(image.rgb, sensor.width, sensor.height),
                 {shot.seed, shot.shot_index});
    result.timings.noise_ms = clock.lap_ms();
    const auto gains = white_balance_gains(camera, image.rgb, image.mask);
    result.white_balance_gains = gains;
    result.encoded = encode_srgb(image.rgb, gains, result.bits);
    if (shot.keep_linear) {
      result.linear = std::move(image.rgb);
    } else {
      recycle(std::move(image.rgb));
    }
  }
  result.mask = std::move(image.mask);
  result.depth_m = std::move(image.depth_m);
  result.timings.develop_ms = clock.lap_ms();

  const auto& t = result.timings;
  result.timings.total_ms = t.exposure_ms + t.depth_of_field_ms + t.diffraction_ms +
                            t.distortion_ms + t.noise_ms + t.develop_ms;
  return result;
}

}  // namespace

DevelopResult develop_frame(const ir::Camera& camera, const LinearFrame& frame,
                            const ShotParams& shot, double scale, std::string* error) {
  if (std::string problem = check_frame(frame); !problem.empty()) {
    if (error != nullptr) *error = problem;
    return {};
  }
  std::vector<float> work = take_floats(frame.rgb.size());
  std::copy(frame.rgb.begin(), frame.rgb.end(), work.begin());
  return develop(camera, frame, nullptr, std::move(work), shot, scale);
}

DevelopResult develop_frame(const ir::Camera& camera, LinearFrame&& frame, const ShotParams& shot,
                            double scale, std::string* error) {
  if (std::string problem = check_frame(frame); !problem.empty()) {
    if (error != nullptr) *error = problem;
    return {};
  }
  std::vector<float> radiance = std::move(frame.rgb);
  return develop(camera, frame, &frame, std::move(radiance), shot, scale);
}

}  // namespace rigc::dslr
