#include "studio/live_develop.h"

#include <chrono>
#include <utility>

#include "dslr/buffer_pool.h"
#include "dslr/depth_of_field.h"
#include "dslr/develop.h"
#include "dslr/diffraction.h"
#include "dslr/exposure.h"
#include "dslr/pipeline.h"
#include "dslr/sensor.h"

namespace rigc::studio {
namespace {

using Clock = std::chrono::steady_clock;

double lap_ms(Clock::time_point* last) {
  const auto now = Clock::now();
  const double ms = std::chrono::duration<double, std::milli>(now - *last).count();
  *last = now;
  return ms;
}

bool same_lens(const ir::Camera& a, const ir::Camera& b) {
  const ir::Distortion &da = a.distortion, &db = b.distortion;
  const ir::Effects &ea = a.effects, &eb = b.effects;
  return a.aperture_f_number == b.aperture_f_number && a.focal_length_m == b.focal_length_m &&
         a.sensor_width_m == b.sensor_width_m && a.sensor_height_m == b.sensor_height_m &&
         a.width_px == b.width_px && a.height_px == b.height_px && a.fx == b.fx && a.fy == b.fy &&
         a.cx == b.cx && a.cy == b.cy && da.k1 == db.k1 && da.k2 == db.k2 && da.k3 == db.k3 &&
         da.p1 == db.p1 && da.p2 == db.p2 && a.vignetting == b.vignetting &&
         a.circle_of_confusion_m == b.circle_of_confusion_m &&
         ea.depth_of_field == eb.depth_of_field && ea.diffraction == eb.diffraction &&
         ea.distortion == eb.distortion && ea.vignetting == eb.vignetting;
}

// The 8-bit codes of the exposed signal (result->width x result->height) through the sensor and
// the white balance.
void sense_and_encode(const ir::Camera& camera, std::vector<float>& signal, dslr::NoiseDraw draw,
                      const std::vector<std::uint8_t>& mask, dslr::DevelopResult* result) {
  const int width = result->width, height = result->height;
  if (camera.white_balance == ir::WhiteBalanceMode::kKelvin) {
    result->white_balance_gains = dslr::white_balance_gains(camera, {}, {});
    result->encoded_bytes = dslr::apply_sensor_and_encode_bytes(
        camera, dslr::view_of(std::as_const(signal), width, height), draw,
        dslr::srgb_encoding(result->white_balance_gains, 8));
    return;
  }
  dslr::apply_sensor(camera, dslr::view_of(signal, width, height), draw);
  result->white_balance_gains = dslr::white_balance_gains(camera, signal, mask);
  const std::vector<std::uint16_t> codes =
      dslr::encode_srgb(signal, result->white_balance_gains, 8);
  result->encoded_bytes.assign(codes.begin(), codes.end());
}

}  // namespace

bool LiveDevelop::OpticsKey::same_as(const OpticsKey& other) const {
  return rendered == other.rendered && focus_m == other.focus_m && scale == other.scale &&
         same_lens(camera, other.camera);
}

// Depth of field, diffraction and the warp of the clean radiance, at unit exposure.
bool LiveDevelop::develop_optics(const OpticsKey& key, std::string* error,
                                 std::map<std::string, double>* stage_ms) {
  const dslr::LinearFrame& frame = key.rendered->frame;
  const size_t pixels = static_cast<size_t>(frame.width) * frame.height;
  if (frame.width <= 0 || frame.height <= 0 || frame.rgb.size() != 3 * pixels ||
      (!frame.depth_m.empty() && frame.depth_m.size() != pixels)) {
    *error = "the renderer's frame is malformed";
    return false;
  }
  auto last = Clock::now();
  ir::Camera camera = key.camera;
  // The renderer's lens already blurred out-of-focus points: do not blur them twice.
  if (key.rendered->depth_of_field_rendered) camera.effects.depth_of_field = false;
  std::vector<float> work = dslr::take_floats(frame.rgb.size());
  std::copy(frame.rgb.begin(), frame.rgb.end(), work.begin());
  const dslr::Intrinsics canvas = frame.intrinsics();
  std::vector<float> scratch = dslr::take_floats(work.size());
  if (camera.effects.depth_of_field && !frame.depth_m.empty()) {
    dslr::DepthOfFieldOptions options;
    options.tile_ranges = &frame.tile_ranges;
    dslr::apply_depth_of_field_in_place(camera, key.focus_m, canvas, work, frame.depth_m, scratch,
                                        options);
  }
  (*stage_ms)["depth_of_field"] = lap_ms(&last);
  if (camera.effects.diffraction) dslr::apply_diffraction(camera, canvas, work);
  (*stage_ms)["diffraction"] = lap_ms(&last);
  static const std::vector<float> no_depth;
  const dslr::Intrinsics sensor = dslr::sensor_intrinsics(camera, key.scale);
  if (kept_) dslr::recycle(std::move(kept_->image.rgb));
  kept_.reset();
  dslr::SensorImage image = dslr::warp_to_sensor(camera, sensor, canvas, work, no_depth, frame.mask,
                                                 std::move(scratch), 1.0);
  dslr::recycle(std::move(work));
  (*stage_ms)["distortion_vignetting"] = lap_ms(&last);
  kept_ = Optics{key, std::move(image)};
  return true;
}

dslr::DevelopResult LiveDevelop::develop(const ir::Camera& camera,
                                         std::shared_ptr<const run::RenderedShot> rendered,
                                         const ir::Shot& shot, const run::RenderSettings& settings,
                                         DevelopReport* report, std::string* error) {
  report->reused_optics = false;
  if (!rendered->frame.rgb_clean) {
    // Radiance with negative or non-finite values: the full pipeline scales and cleans it first.
    dslr::ShotParams params;
    params.focus_distance_m = shot.focus_distance_m;
    params.shot_index = shot.index;
    params.seed = settings.seed;
    params.sensor_depth = false;
    params.keep_linear = false;
    ir::Camera live = camera;
    live.format = ir::ImageFormat::kJpeg;
    if (rendered->depth_of_field_rendered) live.effects.depth_of_field = false;
    dslr::DevelopResult result =
        dslr::develop_frame(live, rendered->frame, params, settings.scale, error);
    if (result.encoded_bytes.empty()) {
      result.encoded_bytes.assign(result.encoded.begin(), result.encoded.end());
    }
    return result;
  }
  OpticsKey key{std::move(rendered), camera, shot.focus_distance_m, settings.scale};
  report->reused_optics = kept_ && kept_->key.same_as(key);
  if (!report->reused_optics && !develop_optics(key, error, &report->stage_ms)) return {};
  auto last = Clock::now();
  const dslr::SensorImage& image = kept_->image;
  std::vector<float> signal = dslr::take_floats(image.rgb.size());
  const float gain = static_cast<float>(dslr::exposure_scale(camera));
  for (size_t i = 0; i < signal.size(); ++i) signal[i] = image.rgb[i] * gain;
  report->stage_ms["exposure"] = lap_ms(&last);
  dslr::DevelopResult result;
  result.width = image.intrinsics.width;
  result.height = image.intrinsics.height;
  result.bits = 8;
  sense_and_encode(camera, signal, {settings.seed, shot.index}, image.mask, &result);
  dslr::recycle(std::move(signal));
  report->stage_ms["noise"] = lap_ms(&last);
  return result;
}

}  // namespace rigc::studio
