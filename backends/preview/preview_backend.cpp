#include "backends/preview/preview_backend.h"

#include <fmt/format.h>
#include <tbb/task_group.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <future>
#include <memory>
#include <optional>
#include <ostream>

#include "dslr/buffer_pool.h"
#include "dslr/exposure.h"
#include "dslr/image_io.h"
#include "dslr/lens.h"
#include "dslr/pipeline.h"
#include "run/colmap_text.h"
#include "run/manifest.h"
#include "run/run_folder.h"
#include "run/transforms_json.h"
#include "scene/motion_blur.h"

namespace rigc::preview {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

dslr::DevelopResult render_shot(const ir::Scene& scene, const scene::StudioScene& studio,
                                const ir::Shot& shot, double scale, std::uint64_t seed,
                                ShotTiming* timing, dslr::LinearFrame* linear_out,
                                bool keep_linear) {
  const auto start = Clock::now();
  const dslr::RenderGeometry geometry = dslr::render_geometry_for(scene.camera, scale);
  raster::FrameRequest request;
  request.world_from_camera = shot.world_from_camera;
  request.canvas = geometry;
  request.shadow_map_size = std::clamp(geometry.width / 2, 512, 2048);
  const int subframes = scene::motion_blur_subframes(scene, studio, shot, scale);
  raster::RasterTimings raster;
  dslr::LinearFrame frame;
  if (subframes == 1) {
    request.turntable_angle_rad = shot.turntable_angle_rad;
    frame = raster::render_frame(scene, studio, request, &raster);
  } else {
    // Sub-frames spread evenly over the open shutter, centred on the shot's angle. Depth and
    // mask come from the middle one.
    const double sweep = shot.turntable_velocity_rad_s * scene.camera.shutter_s;
    std::vector<double> sum;
    for (int k = 0; k < subframes; ++k) {
      request.turntable_angle_rad =
          shot.turntable_angle_rad + sweep * ((k + 0.5) / subframes - 0.5);
      dslr::LinearFrame sub = raster::render_frame(scene, studio, request, &raster);
      if (sum.empty()) sum.assign(sub.rgb.size(), 0.0);
      for (size_t i = 0; i < sub.rgb.size(); ++i) sum[i] += sub.rgb[i];
      if (k == subframes / 2) frame = std::move(sub);
    }
    for (size_t i = 0; i < sum.size(); ++i) frame.rgb[i] = static_cast<float>(sum[i] / subframes);
    frame.tile_ranges = {};  // they described the middle sub-frame alone
  }
  if (linear_out) *linear_out = frame;
  dslr::ShotParams params;
  params.focus_distance_m = shot.focus_distance_m;
  params.shot_index = shot.index;
  params.seed = seed;
  params.sensor_depth = false;  // only the image and the mask are written
  params.keep_linear = keep_linear;
  dslr::DevelopResult result = dslr::develop_frame(scene.camera, std::move(frame), params, scale);
  if (timing) {
    timing->raster = raster;
    timing->develop = result.timings;
    timing->subframes = subframes;
    timing->total_ms = ms_since(start);
  }
  return result;
}

std::map<std::string, double> stage_ms(const ShotTiming& timing) {
  return {{"shadows", timing.raster.shadow_ms},
          {"setup", timing.raster.setup_ms},
          {"raster_and_shading", timing.raster.raster_ms},
          {"exposure", timing.develop.exposure_ms},
          {"depth_of_field", timing.develop.depth_of_field_ms},
          {"diffraction", timing.develop.diffraction_ms},
          {"distortion_vignetting", timing.develop.distortion_ms},
          {"noise", timing.develop.noise_ms},
          {"develop", timing.develop.develop_ms},
          {"write", timing.write_ms}};
}

int run_preview(const ir::Scene& scene, const RenderOptions& options, std::ostream& log,
                std::vector<ShotTiming>* timings) {
  const fs::path run_dir = options.output_dir;
  // The check the run's cameras.txt makes at the end (a positive, finite scale), made before
  // anything is written: a NaN scale used to render and record a shot first.
  std::string camera_error;
  if (!run::output_camera(scene.camera, options.scale, &camera_error)) {
    log << fmt::format("rigc: error: {}\n", camera_error);
    return 1;
  }
  if (!run::prepare_run_folder(run_dir, {}, log)) return 1;
  run::RunFolderLock lock;
  if (!lock.acquire(run_dir, log)) return 1;
  std::vector<int> shots = options.shots;
  if (shots.empty()) {
    for (const auto& shot : scene.shots) shots.push_back(shot.index);
  }

  const fs::path manifest_path = run_dir / "manifest.json";
  run::Manifest manifest = run::Manifest::load(manifest_path);
  if (!run::prune_stale_outputs(manifest, scene, run_dir, manifest_path, log)) return 2;
  const std::string content_hash = run::scene_content_hash(scene);
  manifest.set_backend("preview");
  manifest.set_inputs({{"scene", scene.name},
                       {"source_file", scene.source_file},
                       {"content_sha256", content_hash},
                       {"object_sha256", run::object_geometry_hash(scene)},
                       {"scale", options.scale},
                       {"seed", options.seed}});
  const scene::StudioScene studio = scene::prepare_studio_scene(scene);
  int failures = 0, done = 0;

  // A shot's files are encoded and written while the next shot renders: JPEG encoding is
  // serial, and the renderer keeps both cores busy meanwhile. The manifest records a shot only
  // once its files are in place.
  struct WriteOutcome {
    std::string error;  // empty when both files are in place
    double ms = 0;
  };
  struct PendingWrite {
    const ir::Shot* shot = nullptr;
    std::string key, image, mask;
    ShotTiming timing;
    std::future<WriteOutcome> outcome;
  };
  std::optional<PendingWrite> pending;
  // The writes run as tasks of the renderer's own threads: a thread of their own made three
  // threads share the two cores, and the renderer's loops waited for whichever was descheduled.
  tbb::task_group writers;
  struct WaitForWriters {  // every return waits for the last write (task_group requires it)
    tbb::task_group& group;
    ~WaitForWriters() { group.wait(); }
  } wait_for_writers{writers};
  bool manifest_failed = false;
  // Saved after a shot once half a second has passed since the last save, and at the end, so an
  // interrupted run resumes about where it stopped (the shots of that last half second render
  // again). Rewriting the whole manifest after every shot made 3600 small shots take 97 s, 0.1 s
  // of it rendering.
  auto last_save = Clock::now() - std::chrono::hours(1);
  bool unsaved = false;
  auto save_manifest = [&](bool now) {
    if (!unsaved || (!now && ms_since(last_save) < 500)) return true;
    std::string save_error;
    if (!manifest.save(manifest_path, &save_error)) {
      log << fmt::format("rigc: error: {}\n", save_error);
      manifest_failed = true;
      return false;
    }
    last_save = Clock::now();
    unsaved = false;
    return true;
  };
  auto finish_pending = [&]() {
    if (!pending) return;
    PendingWrite write = std::move(*pending);
    pending.reset();
    writers.wait();  // runs the write here if no other thread has taken it up
    const WriteOutcome outcome = write.outcome.get();
    const std::string& error = outcome.error;
    const ir::Shot& shot = *write.shot;
    ShotTiming& timing = write.timing;
    timing.write_ms = outcome.ms;
    timing.total_ms += outcome.ms;
    if (!error.empty()) {
      log << fmt::format("{}rigc: error: {}: {}\n", options.progress_bar ? "\n" : "", shot.name,
                         error);
      ++failures;
      return;
    }
    run::ShotRecord record;
    record.name = shot.name;
    record.key = write.key;
    record.render_ms = timing.total_ms;
    record.stage_ms = stage_ms(timing);
    record.files = {write.image, write.mask};
    manifest.record(record);
    unsaved = true;
    if (!save_manifest(false)) return;
    ++done;
    if (timings) timings->push_back(timing);
    if (options.progress_bar) {
      log << run::progress_line(done, static_cast<int>(shots.size()), shot.name,
                                timing.total_ms / 1000)
          << std::flush;
    } else {
      log << fmt::format("{}: rendered in {:.2f} s ({} sub-frame{})\n", shot.name,
                         timing.total_ms / 1000, timing.subframes,
                         timing.subframes == 1 ? "" : "s");
    }
  };

  for (int index : shots) {
    const ir::Shot& shot = scene.shots[index];
    const std::string key =
        run::shot_key(scene, content_hash, shot, "preview", options.scale, options.seed);
    if (manifest.is_done(shot.name, key, run_dir)) {
      ShotTiming timing;
      timing.skipped = true;
      finish_pending();
      ++done;
      if (timings) timings->push_back(timing);
      if (!options.progress_bar) log << fmt::format("{}: up to date, skipped\n", shot.name);
      continue;
    }
    ShotTiming timing;
    dslr::DevelopResult result =
        render_shot(scene, studio, shot, options.scale, options.seed, &timing, nullptr, false);
    finish_pending();
    if (manifest_failed) return 2;
    PendingWrite write;
    write.shot = &shot;
    write.key = key;
    write.image = run::image_relative_path(scene.camera, shot);
    write.mask = run::mask_relative_path(shot);
    write.timing = timing;
    auto task = std::make_shared<std::packaged_task<WriteOutcome()>>(
        [&scene, &run_dir, image = write.image, mask = write.mask,
         result = std::move(result)]() mutable -> WriteOutcome {
          const auto start = Clock::now();
          WriteOutcome outcome;
          if (result.encoded.empty() && result.encoded_bytes.empty()) {
            outcome.error = "the DSLR model produced no image";
          } else if (dslr::write_image(run_dir / image, result, scene.camera, &outcome.error)) {
            dslr::write_mask(run_dir / mask, result.mask, result.width, result.height,
                             &outcome.error);
          }
          dslr::recycle(std::move(result.encoded));
          dslr::recycle(std::move(result.encoded_bytes));
          dslr::recycle(std::move(result.mask));
          outcome.ms = ms_since(start);
          return outcome;
        });
    write.outcome = task->get_future();
    writers.run([task] { (*task)(); });
    pending = std::move(write);
  }
  finish_pending();
  if (manifest_failed || !save_manifest(true)) return 2;
  if (options.progress_bar) log << '\n';

  return run::finish_run(scene, manifest, run_dir, options.scale, failures, shots.size(), log);
}

}  // namespace rigc::preview
