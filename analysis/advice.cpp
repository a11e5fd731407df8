#include "analysis/advice.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <string>
#include <vector>

#include "compiler/limits.h"
#include "dslr/exposure.h"
#include "dslr/lens.h"
#include "dslr/sensor.h"
#include "dslr/stops.h"

namespace rigc::analysis {
namespace {

constexpr double kWavelengthM = 550e-9;
// The widest angle between a view and its nearest neighbour (about the object's centre) across
// which SfM's features still match reliably: the verdict benchmark's single ring passes at 20
// degree steps and degrades at 30 (bench/verdict/README.md).
constexpr double kMaxNeighbourAngleDeg = 25;
// The signal-to-noise ratio of the seen surface's median pixel below which the sensor's noise
// costs SfM its features: between the verdict benchmark's ISO 800 (38, passes) and ISO 25600 at
// the same exposure (6, degrades).
constexpr double kMinMedianSnr = 15;
// Shares of the seen surface above which a problem is worth a warning.
constexpr double kWarnShare = 0.05;

const SourceLoc& first_known(const SourceLoc& a, const SourceLoc& b) {
  return a.line > 0 ? a : b;
}

// Stops of less light that leave at most kWarnShare of the seen area clipped, from the shots'
// signal histograms summed (`histogram`, over `visible` m²), rounded up to a third of a stop.
double stops_to_unclip(const std::vector<double>& histogram, double visible) {
  double above = 0;
  for (int b = ShotCoverage::kSignalBins - 1; b >= 0; --b) {
    if (above + histogram[b] > kWarnShare * visible) {
      const double upper =
          ShotCoverage::kSignalLowestStops + (b + 1) * ShotCoverage::kSignalBinStops;
      return std::ceil(std::max(0.0, upper) * 3 - 1e-9) / 3;
    }
    above += histogram[b];
  }
  return 0;
}

// Stops of more light that leave at most kWarnShare of the seen area below `dark_stops` (the
// dark limit, in stops from the clipping level), rounded up to a third of a stop.
double stops_to_undarken(const std::vector<double>& histogram, double visible, double dark_stops) {
  double below = 0;
  for (int b = 0; b < ShotCoverage::kSignalBins; ++b) {
    if (below + histogram[b] > kWarnShare * visible) {
      const double lower = ShotCoverage::kSignalLowestStops + b * ShotCoverage::kSignalBinStops;
      return std::ceil(std::max(0.0, dark_stops - lower) * 3 - 1e-9) / 3;
    }
    below += histogram[b];
  }
  return 0;
}

// "1/250 s" or "2.5 s": a shutter time as a camera shows it.
std::string shutter_text(double seconds) {
  if (seconds >= 0.3) return fmt::format("{:.2g} s", seconds);
  return fmt::format("1/{:.0f} s", 1 / seconds);
}

// A number of stops in thirds, as cameras step: "1/3 stop", "5 2/3 stops".
std::string stops_text(double stops) {
  const int thirds = static_cast<int>(std::lround(stops * 3));
  const int whole = thirds / 3, rest = thirds % 3;
  const std::string count = whole == 0  ? fmt::format("{}/3", rest)
                            : rest == 0 ? fmt::format("{}", whole)
                                        : fmt::format("{} {}/3", whole, rest);
  return count + (thirds > 3 ? " stops" : " stop");
}

using dslr::kFNumberStops;
static_assert(kFNumberStops[0] == limits::camera::kAperture.min &&
              kFNumberStops[std::size(kFNumberStops) - 1] == limits::camera::kAperture.max);

// The seen surface over all shots: its area, the area-weighted shares of its problems, and the
// signal histograms summed.
struct SeenSurface {
  double visible = 0;  // m², never 0
  double out_of_focus = 0, clipped = 0, dark = 0;
  std::vector<double> signal_histogram = std::vector<double>(ShotCoverage::kSignalBins, 0.0);
};

SeenSurface seen_surface(const CoverageResult& coverage) {
  SeenSurface seen;
  for (const auto& shot : coverage.shots) {
    for (std::size_t b = 0; b < shot.signal_histogram.size() && b < seen.signal_histogram.size();
         ++b) {
      seen.signal_histogram[b] += shot.signal_histogram[b];
    }
    seen.visible += shot.visible_area_m2;
    seen.out_of_focus += shot.out_of_focus * shot.visible_area_m2;
    seen.clipped += shot.clipped * shot.visible_area_m2;
    seen.dark += shot.too_dark * shot.visible_area_m2;
  }
  seen.visible = std::max(seen.visible, 1e-30);
  return seen;
}

// Depth of field, and diffraction where the depth of field does not need the aperture.
void advise_aperture(const ir::Scene& scene, const CoverageResult& coverage,
                     const SeenSurface& seen, std::vector<Advice>& out) {
  const ir::Camera& camera = scene.camera;
  const double max_blur_px = scene.coverage.max_blur_px;
  const SourceLoc& aperture_loc = first_known(camera.aperture_loc, camera.loc);
  const double pixel_pitch_m = camera.sensor_width_m / camera.width_px;
  const double n = camera.aperture_f_number;
  // The blur scales as 1/N, so the aperture that keeps 95 % sharp follows.
  const double needed_n = n * coverage.blur_ratio_95;
  if (seen.out_of_focus / seen.visible > kWarnShare) {
    out.push_back({aperture_loc,
                   fmt::format("depth of field at f/{:g} is shallower than the object: {:.0f}% of "
                               "the seen surface is blurred beyond {:.1f} px; f/{:g} would keep "
                               "95% sharp (or focus nearer the object's front)",
                               n, 100 * seen.out_of_focus / seen.visible, max_blur_px,
                               next_standard_f_number(needed_n)),
                   {{Setting::kFNumber, +1, next_standard_f_number(needed_n)}}});
  }
  // An Airy disc wider than the blur budget.
  const double airy_px = 2.44 * kWavelengthM * n / pixel_pitch_m;
  if (airy_px > max_blur_px && n > next_standard_f_number(needed_n) * 1.01) {
    const double limit_n = max_blur_px * pixel_pitch_m / (2.44 * kWavelengthM);
    out.push_back(
        {aperture_loc,
         fmt::format("f/{:g} is diffraction-limited on this sensor ({:.1f} µm pixels): the "
                     "Airy disc is {:.1f} px; the depth of field only needs f/{:g}, and "
                     "f/{:.1f} or wider keeps diffraction under {:.1f} px",
                     n, pixel_pitch_m * 1e6, airy_px,
                     next_standard_f_number(std::max(needed_n, limits::camera::kAperture.min)),
                     limit_n, max_blur_px),
         {{Setting::kFNumber, -1,
           next_standard_f_number(std::max(needed_n, limits::camera::kAperture.min))}}});
  }
}

// Whether an advice already given suggests `change`.
bool suggested(const std::vector<Advice>& given, SettingChange change) {
  return std::any_of(given.begin(), given.end(), [&](const Advice& a) {
    return std::find(a.changes.begin(), a.changes.end(), change) != a.changes.end();
  });
}

// The settings that would give `direction` (+1 more, -1 less) light, leaving out those another
// advice in `given` moves the other way (a shorter shutter against motion blur, a larger
// f-number for depth of field, a smaller one against diffraction). Aperture is left out of more
// light: opening it shortens the depth of field the coverage was judged with.
std::vector<SettingChange> light_changes(int direction, const std::vector<Advice>& given) {
  std::vector<SettingChange> changes;
  const SettingChange shutter{Setting::kShutter, direction};
  if (!suggested(given, {Setting::kShutter, -direction})) changes.push_back(shutter);
  if (direction < 0 && !suggested(given, {Setting::kFNumber, -1})) {
    changes.push_back({Setting::kFNumber, +1});
  }
  changes.push_back({Setting::kIso, direction});
  changes.push_back({Setting::kLight, direction});
  return changes;
}

// Each change's value for `stops` more light (fewer where negative): the shutter, the ISO and
// the light by 2^stops, the f-number (stopped down to take the light away) by 2^(-stops / 2),
// to the next standard one.
void set_exposure_values(const ir::Camera& camera, double stops,
                         std::vector<SettingChange>& changes) {
  for (SettingChange& change : changes) {
    switch (change.setting) {
      case Setting::kShutter:
        change.value = camera.shutter_s * std::exp2(stops);
        break;
      case Setting::kIso:
        change.value = camera.iso * std::exp2(stops);
        break;
      case Setting::kLight:
        change.value = std::exp2(stops);
        break;
      case Setting::kFNumber:
        change.value = next_standard_f_number(camera.aperture_f_number * std::exp2(-stops / 2));
        break;
    }
  }
}

bool offers(const std::vector<SettingChange>& changes, Setting setting) {
  return std::any_of(changes.begin(), changes.end(),
                     [&](const SettingChange& c) { return c.setting == setting; });
}

// The share of the seen surface that clips is more than kWarnShare.
void advise_over_exposure(const ir::Scene& scene, const SeenSurface& seen,
                          const std::vector<Advice>& given, std::vector<Advice>& out) {
  const ir::Camera& camera = scene.camera;
  const double stops = std::max(1.0 / 3, stops_to_unclip(seen.signal_histogram, seen.visible));
  const double shutter = camera.shutter_s * std::exp2(-stops);
  std::vector<SettingChange> changes = light_changes(-1, given);
  const bool stop_down = offers(changes, Setting::kFNumber);
  std::string remedy;
  if (shutter >= limits::camera::kShutter.min) {
    remedy = fmt::format("a shutter of {} ({}a lower ISO)", shutter_text(shutter),
                         stop_down ? "or stop down, or " : "or ");
  } else {
    changes.erase(changes.begin());  // no shutter is short enough
    remedy = stop_down ? "stop down, lower the ISO or dim the lights"
                       : "lower the ISO or dim the lights";
  }
  set_exposure_values(camera, -stops, changes);
  out.push_back({first_known(camera.shutter_loc, camera.loc),
                 fmt::format("over-exposure: {:.0f}% of the seen surface clips at these settings "
                             "(EV100 {:.1f}); {} less light: {}",
                             100 * seen.clipped / seen.visible,
                             dslr::ev100(camera.aperture_f_number, camera.shutter_s, camera.iso),
                             stops_text(stops), remedy),
                 std::move(changes)});
}

// The share of the seen surface below min_signal is more than kWarnShare.
void advise_under_exposure(const ir::Scene& scene, const SeenSurface& seen,
                           const std::vector<Advice>& given, std::vector<Advice>& out) {
  const ir::Camera& camera = scene.camera;
  const ir::CoverageSettings& settings = scene.coverage;
  const double dark_stops = std::log2(settings.min_signal / settings.max_signal);
  const double stops =
      std::max(1.0 / 3, stops_to_undarken(seen.signal_histogram, seen.visible, dark_stops));
  std::vector<SettingChange> changes = light_changes(+1, given);
  set_exposure_values(camera, stops, changes);
  const std::string remedy = offers(changes, Setting::kShutter)
                                 ? "lengthen the shutter, raise the ISO or add light"
                                 : "raise the ISO or add light (a longer shutter would smear)";
  out.push_back({first_known(camera.shutter_loc, camera.loc),
                 fmt::format("under-exposure: {:.0f}% of the seen surface is below {:.0f}% of "
                             "full scale, where sensor noise hides texture; {} more light: {}",
                             100 * seen.dark / seen.visible, 100 * settings.min_signal,
                             stops_text(stops), remedy),
                 std::move(changes)});
}

// The signal, in stops from the clipping level, below which `share` of the seen area lies.
double signal_percentile_stops(const std::vector<double>& histogram, double visible, double share) {
  double below = 0;
  for (int b = 0; b < ShotCoverage::kSignalBins; ++b) {
    below += histogram[b];
    if (below >= share * visible) {
      return ShotCoverage::kSignalLowestStops + (b + 0.5) * ShotCoverage::kSignalBinStops;
    }
  }
  return ShotCoverage::kSignalLowestStops +
         ShotCoverage::kSignalBins * ShotCoverage::kSignalBinStops;
}

// Both clipped and dark surface: the scene's brightness range is wider than the window between
// too dark and clipping, so less light for the one is more darkness for the other. Light
// (fill or ambient) narrows the range; bracketing records it in two exposures.
void advise_brightness_range(const ir::Scene& scene, const SeenSurface& seen,
                             std::vector<Advice>& out) {
  const ir::Camera& camera = scene.camera;
  const ir::CoverageSettings& settings = scene.coverage;
  const double dark = signal_percentile_stops(seen.signal_histogram, seen.visible, kWarnShare);
  const double bright =
      signal_percentile_stops(seen.signal_histogram, seen.visible, 1 - kWarnShare);
  const double window = std::log2(settings.max_signal / settings.min_signal);
  const double sensor = std::log2(dslr::electrons_at_clipping(camera.noise, camera.iso) /
                                  dslr::read_noise_electrons(camera.noise, camera.iso));
  out.push_back(
      {first_known(camera.shutter_loc, camera.loc),
       fmt::format("the scene's brightness range is wider than the sensor records: the seen "
                   "surface spans {:.1f} stops from its darkest to its brightest {:.0f}%, but "
                   "only the {:.1f} stops from {:.0f}% to {:.0f}% of full scale are usable (the "
                   "sensor's dynamic range at ISO {:g} is {:.1f} stops); {:.0f}% clips and "
                   "{:.0f}% is too dark, and no exposure fixes both: add fill light on the "
                   "shadow side or raise the studio's ambient light, or bracket the exposures",
                   bright - dark, 100 * kWarnShare, window, 100 * settings.min_signal,
                   100 * settings.max_signal, camera.iso, sensor, 100 * seen.clipped / seen.visible,
                   100 * seen.dark / seen.visible),
       {{Setting::kLight, +1}}});
}

// A well-exposed surface whose pixels still collect too few electrons (a high ISO making up for
// little light): the shot and read noise of the median pixel against its signal.
void advise_sensor_noise(const ir::Scene& scene, const SeenSurface& seen,
                         std::vector<Advice>& out) {
  const ir::Camera& camera = scene.camera;
  if (!camera.effects.noise) return;
  const double median_signal =
      std::exp2(signal_percentile_stops(seen.signal_histogram, seen.visible, 0.5));
  const double electrons = median_signal * dslr::electrons_at_clipping(camera.noise, camera.iso);
  const double read = dslr::read_noise_electrons(camera.noise, camera.iso);
  const double snr = electrons / std::sqrt(electrons + read * read);
  if (snr >= kMinMedianSnr) return;
  out.push_back({first_known(camera.iso_loc, camera.loc),
                 fmt::format("sensor noise at ISO {:g}: the seen surface's median pixel collects "
                             "about {:.0f} electrons, a signal-to-noise ratio of {:.0f} (SfM's "
                             "features want {:.0f} or more); give more light and lower the ISO",
                             camera.iso, electrons, snr, kMinMedianSnr),
                 {{Setting::kLight, +1}}});
}

// Clipped or too dark surface, with how many stops of light would fix it; both at once are a
// brightness range no exposure fits. `given`: the advice that pins settings (motion blur,
// aperture), which the exposure remedies must not reverse.
void advise_exposure(const ir::Scene& scene, const SeenSurface& seen,
                     const std::vector<Advice>& given, std::vector<Advice>& out) {
  const bool clipped = seen.clipped / seen.visible > kWarnShare;
  const bool dark = seen.dark / seen.visible > kWarnShare;
  if (clipped && dark) {
    advise_brightness_range(scene, seen, out);
  } else if (clipped) {
    advise_over_exposure(scene, seen, given, out);
  } else if (dark) {
    advise_under_exposure(scene, seen, given, out);
  } else {
    advise_sensor_noise(scene, seen, out);
  }
}

// A distortion that draws the frame's edge from beyond the canvas the renderers make (at most
// twice the sensor's extent): the pixels there repeat the canvas's border, a smear that is not
// the scene, and nothing else would tell.
void advise_distortion(const ir::Camera& camera, std::vector<Advice>& out) {
  if (camera.effects.distortion && dslr::render_geometry_for(camera, 1.0).clipped) {
    out.push_back({first_known(camera.distortion_loc, camera.loc),
                   "the distortion draws part of the frame from beyond the canvas the renderers "
                   "make (at most twice the sensor's extent): pixels there repeat the canvas's "
                   "border instead of the scene; make the coefficients smaller",
                   {}});
  }
}

// Motion blur from a turning table, per shot group (reported once per source line).
void advise_motion_blur(const ir::Scene& scene, const scene::StudioScene& studio,
                        const CoverageResult& coverage, std::vector<Advice>& out) {
  const ir::Camera& camera = scene.camera;
  int last_line = -1;
  for (const auto& shot : scene.shots) {
    if (shot.turntable_velocity_rad_s == 0 || shot.loc.line == last_line) continue;
    const double radius = studio.object_center.head<2>().norm() + studio.object_radius;
    const double depth = std::max(0.05, coverage.shots[shot.index].nearest_depth_m);
    const double blur_px = dslr::motion_blur_length_px(
        camera, 1.0, std::abs(shot.turntable_velocity_rad_s), radius, depth);
    if (!(blur_px > 1)) continue;
    last_line = shot.loc.line;
    // A camera's shutter speed that keeps the smear under a pixel, if there is one (the smear
    // grows with the exposure).
    const double sharp_shutter = 0.99 * camera.shutter_s / blur_px;
    const double shutter = next_faster_standard_shutter(sharp_shutter);
    const bool shutter_helps = shutter <= sharp_shutter + 1e-12;
    const std::string remedy =
        shutter_helps ? fmt::format("stop the table for each shot or use {} or shorter",
                                    shutter_text(shutter))
                      : std::string("stop the table for each shot (no shutter is fast enough)");
    std::vector<SettingChange> changes;
    if (shutter_helps) changes.push_back({Setting::kShutter, -1, shutter});
    out.push_back({shot.loc,
                   fmt::format("the turning table smears the object by up to {:.1f} px during "
                               "the {:g} s exposure; {}",
                               blur_px, camera.shutter_s, remedy),
                   std::move(changes)});
  }
}

// Faces never seen (the base resting on the table cannot be, so it does not count), with the
// shots that would see them.
void advise_unseen_faces(const ir::Scene& scene, const scene::StudioScene& studio,
                         const CoverageResult& coverage, std::vector<Advice>& out) {
  double unseen = 0, resting = 0;
  Eigen::Vector3d unseen_normal = Eigen::Vector3d::Zero();
  const auto& mesh = studio.object;
  for (size_t f = 0; f < coverage.views.size(); ++f) {
    if (coverage.resting[f]) {
      resting += coverage.face_area_m2[f];
      continue;
    }
    if (coverage.views[f] > 0) continue;
    unseen += coverage.face_area_m2[f];
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d a = mesh.positions[t[0]].cast<double>();
    unseen_normal +=
        (mesh.positions[t[1]].cast<double>() - a).cross(mesh.positions[t[2]].cast<double>() - a) /
        2;
  }
  const double visible_total = std::max(coverage.total_area_m2 - resting, 1e-30);
  if (scene.shots.empty() || !(unseen / visible_total > kWarnShare)) return;
  std::string fix = "add shots from the directions the red faces face";
  if (unseen_normal.norm() > 0.3 * unseen) {
    const double elevation = std::asin(std::clamp(unseen_normal.normalized().z(), -1.0, 1.0));
    if (elevation > 0.35)
      fix = "add a ring at a higher elevation, e.g. 60deg";
    else if (elevation < -0.35)
      fix =
          "add a ring from below (elevation -30deg) or turn the "
          "object over for a second pass";
  }
  out.push_back({scene.shots.front().loc,
                 fmt::format("{:.0f}% of the object's surface is never seen by any shot; {}",
                             100 * unseen / visible_total, fix),
                 {}});
}

// Overlap between consecutive shots, and the object's size in the frame (the first shot short
// of each).
void advise_overlap_and_framing(const ir::Scene& scene, const CoverageResult& coverage,
                                std::vector<Advice>& out) {
  const ir::CoverageSettings& settings = scene.coverage;
  for (size_t i = 1; i < coverage.shots.size(); ++i) {
    const ShotCoverage& shot = coverage.shots[i];
    if (shot.visible_area_m2 > 0 && shot.overlap_with_previous < settings.min_overlap) {
      out.push_back({scene.shots[i].loc,
                     fmt::format("{} overlaps the previous shot by only {:.0f}% of its seen "
                                 "surface (SfM wants {:.0f}% or more); take smaller steps",
                                 scene.shots[i].name, 100 * shot.overlap_with_previous,
                                 100 * settings.min_overlap),
                     {}});
      break;
    }
  }
  for (const auto& shot : coverage.shots) {
    if (shot.frame_fill < settings.min_frame_fill) {
      out.push_back({scene.shots[shot.shot].loc,
                     fmt::format("the object fills only {:.1f}% of {}'s frame; move the camera "
                                 "closer or use a longer lens",
                                 100 * shot.frame_fill, scene.shots[shot.shot].name),
                     {}});
      break;
    }
  }
}

// A shot whose nearest other view is more than kMaxNeighbourAngleDeg away about the object's
// centre: its features have no close view to match, whatever the overlap of the seen surface.
void advise_view_spacing(const ir::Scene& scene, std::vector<Advice>& out) {
  if (scene.shots.size() < 2) return;
  const Eigen::Vector3d center =
      (scene.object.bounds_min_object + scene.object.bounds_max_object) / 2;
  std::vector<Eigen::Vector3d> directions;
  for (const ir::Shot& shot : scene.shots) {
    directions.push_back((shot.object_from_camera.block<3, 1>(0, 3) - center).normalized());
  }
  for (std::size_t i = 0; i < directions.size(); ++i) {
    double nearest = 180;
    for (std::size_t j = 0; j < directions.size(); ++j) {
      if (j == i) continue;
      const double cosine = std::clamp(directions[i].dot(directions[j]), -1.0, 1.0);
      nearest = std::min(nearest, std::acos(cosine) * 180 / std::numbers::pi);
    }
    if (nearest <= kMaxNeighbourAngleDeg) continue;
    out.push_back({scene.shots[i].loc,
                   fmt::format("{}'s nearest other view is {:.0f} deg away; SfM matches features "
                               "between views up to about {:.0f} deg apart: take smaller steps "
                               "(20 deg or less) or add views between",
                               scene.shots[i].name, nearest, kMaxNeighbourAngleDeg),
                   {}});
    return;
  }
}

}  // namespace

double next_faster_standard_shutter(double seconds) {
  // Cameras' third-stop speeds from 1/8000 s to 1 s, as denominators, fastest first.
  static constexpr double kDenominators[] = {
      8000, 6400, 5000, 4000, 3200, 2500, 2000, 1600, 1250, 1000, 800, 640, 500, 400,
      320,  250,  200,  160,  125,  100,  80,   60,   50,   40,   30,  25,  20,  15,
      13,   10,   8,    6,    5,    4,    3,    2.5,  2,    1.6,  1.3, 1};
  double slowest = 1 / kDenominators[0];
  for (const double denominator : kDenominators) {
    if (1 / denominator > seconds * 1.001) break;
    slowest = 1 / denominator;
  }
  return slowest;
}

double next_standard_f_number(double f_number) {
  for (double stop : kFNumberStops) {
    if (stop >= f_number * 0.999) return stop;
  }
  return limits::camera::kAperture.max;
}

std::vector<Advice> capture_advice(const ir::Scene& scene, const scene::StudioScene& studio,
                                   const CoverageResult& coverage) {
  const SeenSurface seen = seen_surface(coverage);
  // Aperture and motion blur pin settings the exposure remedies then leave alone.
  std::vector<Advice> aperture, motion_blur, pinned;
  advise_aperture(scene, coverage, seen, aperture);
  advise_motion_blur(scene, studio, coverage, motion_blur);
  pinned = aperture;
  pinned.insert(pinned.end(), motion_blur.begin(), motion_blur.end());
  std::vector<Advice> out = std::move(aperture);
  advise_exposure(scene, seen, pinned, out);
  advise_distortion(scene.camera, out);
  out.insert(out.end(), motion_blur.begin(), motion_blur.end());
  advise_unseen_faces(scene, studio, coverage, out);
  advise_overlap_and_framing(scene, coverage, out);
  advise_view_spacing(scene, out);
  return out;
}

const char* setting_name(Setting setting) {
  switch (setting) {
    case Setting::kShutter:
      return "shutter";
    case Setting::kFNumber:
      return "f-number";
    case Setting::kIso:
      return "iso";
    case Setting::kLight:
      return "light";
  }
  return "";
}

double advice_visibility_scale(const ir::Camera& camera) {
  return std::min(1.0, 700.0 / camera.width_px);
}

std::vector<Advice> check_advice(const ir::Scene& scene) {
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  CoverageOptions options;
  options.visibility_scale = advice_visibility_scale(scene.camera);
  return capture_advice(scene, studio, analyse_coverage(scene, studio, options));
}

void report_capture_advice(const ir::Scene& scene, const scene::StudioScene& studio,
                           const CoverageResult& coverage, DiagnosticEngine& diag) {
  for (const Advice& advice : capture_advice(scene, studio, coverage)) {
    diag.warning(advice.loc, advice.message);
  }
}

}  // namespace rigc::analysis
