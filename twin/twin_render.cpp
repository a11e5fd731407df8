#include "twin/twin_render.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "backends/registry.h"
#include "compiler/frontend.h"
#include "dslr/image_io.h"
#include "io/atomic_file.h"
#include "run/colmap_text.h"
#include "run/run_loop.h"

namespace rigc::twin {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The photos' and the renders' mean luminance over where both show the object.
struct Brightness {
  double photos = 0, renders = 0;
};

double luminance(const Eigen::Vector3f& c) {
  return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

struct RenderedView {
  std::vector<Eigen::Vector3f> linear;
  Silhouette silhouette;
};

std::optional<RenderedView> read_render(const fs::path& run, const ir::Scene& scene, int shot,
                                        std::string* error) {
  const ir::Shot& s = scene.shots.at(static_cast<std::size_t>(shot));
  OIIO::ImageBuf image((run / run::image_relative_path(scene.camera, s)).string());
  auto mask = read_silhouette(run / run::mask_relative_path(s), error);
  if (!mask || !image.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
    *error = fmt::format("cannot read the twin's render of shot {} in {}", shot, run.string());
    return std::nullopt;
  }
  const int w = image.spec().width, h = image.spec().height;
  RenderedView v;
  const OIIO::ImageBuf linear = OIIO::ImageBufAlgo::colorconvert(
      OIIO::ImageBufAlgo::channels(image, 3, {0, 1, 2}), "sRGB", "linear");
  v.linear.resize(static_cast<std::size_t>(w) * h);
  linear.get_pixels(OIIO::ROI(0, w, 0, h, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, v.linear.data());
  v.silhouette = std::move(*mask);
  return v;
}

// Renders `shots` of the scene file with the preview into `run`; 0 or 2 with `error`.
int render_shots(const fs::path& scene_path, const std::vector<int>& shots, const fs::path& run,
                 std::optional<ir::Scene>* compiled, std::ostream& log, std::string* error) {
  DiagnosticEngine diag;
  std::string messages;
  diag.set_handler([&](const Diagnostic& d, const std::string& text) {
    if (d.severity == Severity::kError) messages += text;
  });
  *compiled = compile_scene_file(scene_path.string(), diag);
  if (!*compiled) {
    *error = fmt::format("the twin's scene does not compile:\n{}", messages);
    return 2;
  }
  run::RunOptions options;
  options.output_dir = run;
  options.shots = shots;
  options.force = true;
  std::ostringstream run_log;
  const auto backend = backends::find_backend("preview")->make();
  if (run::run_backend(**compiled, *backend, options, run_log) != 0) {
    *error = fmt::format("rendering the twin failed:\n{}", run_log.str());
    return 2;
  }
  (void)log;
  return 0;
}

Brightness brightness(const std::vector<CapturedPhoto>& photos, const RenderedView& render,
                      std::size_t photo) {
  Brightness b;
  const CapturedPhoto& p = photos[photo];
  for (std::size_t i = 0; i < p.linear.size() && i < render.linear.size(); ++i) {
    if (p.silhouette.coverage[i] < 0.5f || render.silhouette.coverage[i] < 0.5f) continue;
    b.photos += luminance(p.linear[i]);
    b.renders += luminance(render.linear[i]);
  }
  return b;
}

// The photos' brightness over the twin's, on the object, in `probes` rendered with `lights`.
// (Eight parameters: the twin being made and where its renders go, as twin.cpp holds them.)
std::optional<double> photos_over_twin(const fs::path& scene_path, TwinScene& scene,
                                       const TwinLights& lights,
                                       const std::vector<CapturedPhoto>& photos,
                                       const std::vector<int>& probes, const fs::path& run,
                                       std::ostream& log, std::string* error) {
  scene.lights = lights;
  if (!write_file_atomically(scene_path, scene_yaml(scene), error)) return std::nullopt;
  std::optional<ir::Scene> compiled;
  if (render_shots(scene_path, probes, run, &compiled, log, error)) return std::nullopt;
  Brightness total;
  for (int shot : probes) {
    const auto render = read_render(run, *compiled, shot, error);
    if (!render) return std::nullopt;
    const Brightness b = brightness(photos, *render, static_cast<std::size_t>(shot));
    total.photos += b.photos;
    total.renders += b.renders;
  }
  if (!(total.renders > 0 && total.photos > 0)) {
    *error = "the twin's renders show no object where the photos do";
    return std::nullopt;
  }
  return std::clamp(total.photos / total.renders, 1e-4, 1e4);
}

// The lights that make the twin as bright as the photos on four views, 85 % of it ambient: the
// photos' shading is in the colours already, and a strong key would shade them twice (views
// from its far side dark). The ambient and the key are measured alone, then together once more
// (the development's tone curve is not linear).
// (Seven parameters: the twin being made and where its renders go, as twin.cpp holds them.)
int calibrate_lights(const fs::path& scene_path, TwinScene& scene,
                     const std::vector<CapturedPhoto>& photos, const fs::path& run, json& report,
                     std::ostream& log, std::string* error) {
  constexpr double kAmbientShare = 0.85;
  std::vector<int> probes;
  const int n = static_cast<int>(photos.size());
  for (int k = 0; k < std::min(n, 4); ++k) probes.push_back(k * n / std::min(n, 4));
  TwinLights ambient = scene.lights, key = scene.lights;
  ambient.ambient_lux = 100;
  ambient.key_power_w = 1e-6;
  key.ambient_lux = 0;
  key.key_power_w = 10;
  const auto by_ambient =
      photos_over_twin(scene_path, scene, ambient, photos, probes, run, log, error);
  if (!by_ambient) return 2;
  const auto by_key = photos_over_twin(scene_path, scene, key, photos, probes, run, log, error);
  if (!by_key) return 2;
  TwinLights both = scene.lights;
  both.ambient_lux = kAmbientShare * ambient.ambient_lux * *by_ambient;
  both.key_power_w = (1 - kAmbientShare) * key.key_power_w * *by_key;
  const auto check = photos_over_twin(scene_path, scene, both, photos, probes, run, log, error);
  if (!check) return 2;
  both.ambient_lux *= *check;
  both.key_power_w *= *check;
  scene.lights = both;
  if (!write_file_atomically(scene_path, scene_yaml(scene), error)) return 2;
  report["light_calibration"] = {
      {"ambient_share", kAmbientShare},      {"photos_over_twin_ambient_100lx", *by_ambient},
      {"photos_over_twin_key_10W", *by_key}, {"correction_for_the_tone_curve", *check},
      {"ambient_lux", both.ambient_lux},     {"key_power_w", both.key_power_w}};
  return 0;
}

// A side-by-side pair per photo, four pairs a row, each image `tile` pixels wide.
bool write_contact_sheet(const std::vector<CapturedPhoto>& photos,
                         const std::vector<RenderedView>& renders, const fs::path& path,
                         std::string* error) {
  const int tile = 240;
  const int w0 = photos.front().camera.width, h0 = photos.front().camera.height;
  const int tile_h = std::max(1, tile * h0 / w0);
  const int per_row = 4, gap = 6;
  const int rows = (static_cast<int>(photos.size()) + per_row - 1) / per_row;
  const int width = per_row * (2 * tile + gap) + gap, height = rows * (tile_h + gap) + gap;
  OIIO::ImageBuf sheet(OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::FLOAT));
  OIIO::ImageBufAlgo::fill(sheet, {0.25f, 0.25f, 0.25f});
  auto paste = [&](const std::vector<Eigen::Vector3f>& linear, int x, int y) {
    OIIO::ImageBuf image(OIIO::ImageSpec(w0, h0, 3, OIIO::TypeDesc::FLOAT),
                         const_cast<Eigen::Vector3f*>(linear.data()));
    const OIIO::ImageBuf small =
        OIIO::ImageBufAlgo::resize(image, "", 0, OIIO::ROI(0, tile, 0, tile_h, 0, 1, 0, 3));
    OIIO::ImageBufAlgo::paste(sheet, x, y, 0, 0, small);
  };
  for (std::size_t k = 0; k < photos.size(); ++k) {
    const int col = static_cast<int>(k) % per_row, row = static_cast<int>(k) / per_row;
    const int x = gap + col * (2 * tile + gap), y = gap + row * (tile_h + gap);
    paste(photos[k].linear, x, y);
    paste(renders[k].linear, x + tile, y);
  }
  const OIIO::ImageBuf srgb = OIIO::ImageBufAlgo::colorconvert(sheet, "linear", "sRGB");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(width) * height * 3);
  srgb.get_pixels(OIIO::ROI(0, width, 0, height, 0, 1, 0, 3), OIIO::TypeDesc::UINT8, bytes.data());
  if (!dslr::write_pixels(path, OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8),
                          bytes.data(), error)) {
    return false;
  }
  return true;
}

}  // namespace

int render_and_compare(const fs::path& scene_path, TwinScene& scene,
                       const std::vector<CapturedPhoto>& photos, const fs::path& out, json& report,
                       std::ostream& log, std::string* error) {
  const fs::path run = out / "render";
  if (const int rc = calibrate_lights(scene_path, scene, photos, run, report, log, error))
    return rc;
  std::optional<ir::Scene> compiled;
  if (const int rc = render_shots(scene_path, {}, run, &compiled, log, error)) return rc;
  std::vector<RenderedView> renders;
  json per_photo = json::array();
  std::vector<double> ious;
  for (std::size_t k = 0; k < photos.size(); ++k) {
    auto render = read_render(run, *compiled, static_cast<int>(k), error);
    if (!render) return 2;
    const double iou = silhouette_iou(render->silhouette, photos[k].silhouette);
    const Brightness b = brightness(photos, *render, k);
    ious.push_back(iou);
    per_photo.push_back(
        {{"photo", photos[k].name},
         {"render",
          (run / run::image_relative_path(compiled->camera, compiled->shots[k])).string()},
         {"silhouette_iou", iou},
         {"brightness_twin_over_photo", b.photos > 0 ? b.renders / b.photos : 0}});
    renders.push_back(std::move(*render));
  }
  const fs::path sheet = out / "contact_sheet.png";
  if (!write_contact_sheet(photos, renders, sheet, error)) return 2;
  std::sort(ious.begin(), ious.end());
  report["comparison"] = {{"render", run.string()},
                          {"contact_sheet", sheet.string()},
                          {"min_silhouette_iou", ious.front()},
                          {"median_silhouette_iou", ious[ious.size() / 2]},
                          {"photos", per_photo}};
  return 0;
}

}  // namespace rigc::twin
