#include "backends/external/reference_backend.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <unistd.h>

#include <chrono>
#include <ostream>

#include "backends/external/process.h"
#include "backends/external/script_text.h"
#include "dslr/image_io.h"
#include "dslr/lens.h"
#include "dslr/pipeline.h"
#include "run/colmap_text.h"
#include "run/manifest.h"
#include "run/run_folder.h"
#include "run/transforms_json.h"

namespace rigc::external {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

fs::path render_folder(const fs::path& run_dir) {
  return run_dir / "render";
}

bool read_linear_image(const fs::path& path, LinearImage* image, std::string* error) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) {
    *error = fmt::format("cannot read '{}': {}", path.string(), OIIO::geterror());
    return false;
  }
  const OIIO::ImageSpec& spec = input->spec();
  const int channels = spec.nchannels;
  if (channels < 1 || spec.width <= 0 || spec.height <= 0) {
    *error = fmt::format("'{}' has no pixels", path.string());
    return false;
  }
  std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * channels);
  if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    *error = fmt::format("cannot read '{}': {}", path.string(), input->geterror());
    return false;
  }
  image->width = spec.width;
  image->height = spec.height;
  const size_t count = static_cast<size_t>(spec.width) * spec.height;
  image->rgb.resize(count * 3);
  image->alpha.clear();
  const int alpha_channel = spec.alpha_channel >= 0 ? spec.alpha_channel : (channels == 4 ? 3 : -1);
  if (alpha_channel >= 0) image->alpha.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const float* p = &pixels[i * channels];
    for (int c = 0; c < 3; ++c) image->rgb[i * 3 + c] = p[std::min(c, channels - 1)];
    if (alpha_channel >= 0) image->alpha[i] = p[alpha_channel];
  }
  return true;
}

bool write_texture_png(const fs::path& path, const ir::Texture& texture, std::string* error) {
  auto output = OIIO::ImageOutput::create(path.string());
  OIIO::ImageSpec spec(texture.width, texture.height, texture.channels, OIIO::TypeDesc::UINT8);
  if (!output || !output->open(path.string(), spec) ||
      !output->write_image(OIIO::TypeDesc::UINT8, texture.pixels.data()) || !output->close()) {
    *error = fmt::format("cannot write the texture '{}': {}", path.string(),
                         output ? output->geterror() : OIIO::geterror());
    return false;
  }
  return true;
}

bool prepare_emit_folder(const ir::Scene& scene, const fs::path& dir, double scale,
                         std::string* error) {
  if (!(scale > 0) || !std::isfinite(scale)) {
    *error = "the render scale must be a positive number";
    return false;
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) {
    *error = fmt::format("cannot create the folder '{}'", dir.string());
    return false;
  }
  for (const auto& shot : scene.shots) {
    if (!is_plain_file_stem(shot.name)) {
      *error = fmt::format("shot name '{}' cannot be a file name", comment_text(shot.name));
      return false;
    }
  }
  return true;
}

int run_reference(const ir::Scene& scene, const ReferenceOptions& options, Renderer& renderer,
                  std::ostream& log, std::vector<ShotTiming>* timings) {
  const fs::path run_dir = options.output_dir;
  const fs::path work_dir = render_folder(run_dir);
  if (!run::prepare_run_folder(run_dir, {work_dir}, log)) return 1;
  run::RunFolderLock lock;
  if (!lock.acquire(run_dir, log)) return 1;
  if (!(options.scale > 0) || options.samples < 0) {
    log << "rigc: error: the scale must be positive and the samples not negative\n";
    return 1;
  }
  if (!find_executable(renderer.executable())) {
    log << fmt::format(
        "rigc: error: the {} backend needs '{}', which is not installed (not found in PATH); "
        "install it with: sudo apt-get install {}\n",
        renderer.name(), renderer.executable(), renderer.package());
    return 2;
  }
  std::vector<int> shots = options.shots;
  if (shots.empty()) {
    for (const auto& shot : scene.shots) shots.push_back(shot.index);
  }
  for (int index : shots) {
    if (index < 0 || index >= static_cast<int>(scene.shots.size())) {
      log << fmt::format("rigc: error: shot {} does not exist (0..{})\n", index,
                         scene.shots.size() - 1);
      return 1;
    }
  }

  const fs::path manifest_path = run_dir / "manifest.json";
  run::Manifest manifest = run::Manifest::load(manifest_path);
  if (!run::prune_stale_outputs(manifest, scene, run_dir, manifest_path, log)) return 2;
  const std::string content_hash = run::scene_content_hash(scene);
  const std::string extra = fmt::format("samples={}", options.samples);
  manifest.set_backend(renderer.name());
  manifest.set_inputs({{"scene", scene.name},
                       {"source_file", scene.source_file},
                       {"content_sha256", content_hash},
                       {"object_sha256", run::object_geometry_hash(scene)},
                       {"scale", options.scale},
                       {"seed", options.seed},
                       {"samples", options.samples}});

  // Only the shots still to do need the scene files.
  std::vector<int> pending;
  for (int index : shots) {
    const ir::Shot& shot = scene.shots[index];
    const std::string key = run::shot_key(scene, content_hash, shot, renderer.name(), options.scale,
                                          options.seed, extra);
    if (!manifest.is_done(shot.name, key, run_dir)) pending.push_back(index);
  }
  if (!pending.empty()) {
    std::string error;
    if (!renderer.emit(scene, work_dir, options.scale, options.samples, &error)) {
      log << fmt::format("rigc: error: {}\n", error);
      return 2;
    }
  }

  int failures = 0, done = 0;
  for (int index : shots) {
    const ir::Shot& shot = scene.shots[index];
    const std::string key = run::shot_key(scene, content_hash, shot, renderer.name(), options.scale,
                                          options.seed, extra);
    ShotTiming timing;
    if (manifest.is_done(shot.name, key, run_dir)) {
      timing.skipped = true;
      ++done;
      if (timings) timings->push_back(timing);
      if (!options.progress_bar) log << fmt::format("{}: up to date, skipped\n", shot.name);
      continue;
    }
    const auto start = Clock::now();
    const fs::path log_path = work_dir / (shot.name + ".log");
    std::error_code ec;
    fs::remove(log_path, ec);
    RenderedShot rendered;
    std::string error;
    bool ok = renderer.render(scene, work_dir, shot, options.scale, options.samples, log_path,
                              &rendered, &error);
    timing.render_ms = ms_since(start);
    timing.subframes = rendered.subframes;
    dslr::DevelopResult result;
    if (ok) {
      const auto develop_start = Clock::now();
      ir::Camera camera = scene.camera;
      // The renderer's lens already blurred out-of-focus points: do not blur them twice.
      if (rendered.depth_of_field_rendered) camera.effects.depth_of_field = false;
      dslr::ShotParams params;
      params.focus_distance_m = shot.focus_distance_m;
      params.shot_index = shot.index;
      params.seed = options.seed;
      result = dslr::develop_frame(camera, rendered.frame, params, options.scale, &error);
      timing.develop_ms = ms_since(develop_start);
      ok = !result.encoded.empty();
      if (!ok && error.empty()) error = "the DSLR model produced no image";
    }
    const auto write_start = Clock::now();
    const std::string image = run::image_relative_path(scene.camera, shot);
    const std::string mask = run::mask_relative_path(shot);
    ok = ok && dslr::write_image(run_dir / image, result, scene.camera, &error);
    ok = ok && dslr::write_mask(run_dir / mask, result.mask, result.width, result.height, &error);
    timing.write_ms = ms_since(write_start);
    timing.total_ms = ms_since(start);
    if (!ok) {
      timing.failed = true;
      if (timings) timings->push_back(timing);
      log << fmt::format("{}rigc: error: {}: {} (renderer log: {})\n",
                         options.progress_bar ? "\n" : "", shot.name, error, log_path.string());
      ++failures;
      continue;
    }
    run::ShotRecord record;
    record.name = shot.name;
    record.key = key;
    record.render_ms = timing.total_ms;
    record.stage_ms = {
        {"render", timing.render_ms}, {"develop", timing.develop_ms}, {"write", timing.write_ms}};
    record.files = {image, mask};
    manifest.record(record);
    // Saved after every shot, so an interrupted run resumes where it stopped.
    if (!manifest.save(manifest_path, &error)) {
      log << fmt::format("rigc: error: {}\n", error);
      return 2;
    }
    ++done;
    if (timings) timings->push_back(timing);
    if (options.progress_bar) {
      log << run::progress_line(done, static_cast<int>(shots.size()), shot.name,
                                timing.total_ms / 1000)
          << std::flush;
    } else {
      log << fmt::format("{}: rendered with {} in {:.2f} s\n", shot.name, renderer.name(),
                         timing.total_ms / 1000);
    }
  }
  if (options.progress_bar) log << '\n';

  return run::finish_run(scene, manifest, run_dir, options.scale, failures, shots.size(), log);
}

}  // namespace rigc::external
