#include "run/run_loop.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <future>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "dslr/buffer_pool.h"
#include "dslr/image_io.h"
#include "dslr/pipeline.h"
#include "io/elapsed.h"
#include "run/colmap_text.h"
#include "run/manifest.h"
#include "run/run_folder.h"

namespace rigc::run {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

// The manifest is saved once this long has passed since the last save (and at the end): an
// interrupted run resumes about where it stopped, and thousands of small shots do not rewrite
// it thousands of times.
constexpr double kManifestSaveIntervalMs = 500;

std::map<std::string, double> development_stage_ms(const dslr::StageTimings& timings) {
  return {{"exposure", timings.exposure_ms},
          {"depth_of_field", timings.depth_of_field_ms},
          {"diffraction", timings.diffraction_ms},
          {"distortion_vignetting", timings.distortion_ms},
          {"noise", timings.noise_ms},
          {"develop", timings.develop_ms}};
}

struct WriteOutcome {
  std::string error;  // empty when both files are in place
  double ms = 0;
};

// Encodes and writes a developed shot's image and mask, then returns their buffers to the pool.
WriteOutcome write_shot_files(const ir::Scene& scene, const fs::path& run_dir,
                              const std::string& image, const std::string& mask,
                              dslr::DevelopResult& result) {
  const auto start = Clock::now();
  WriteOutcome outcome;
  if (dslr::write_image(run_dir / image, result, scene.camera, &outcome.error) &&
      !dslr::write_mask(run_dir / mask, dslr::view_of(result.mask, result.width, result.height, 1),
                        &outcome.error)) {
    // A shot has both files or neither: an image without its mask is in no manifest.
    std::error_code ec;
    fs::remove(run_dir / image, ec);
  }
  dslr::recycle(std::move(result.encoded));
  dslr::recycle(std::move(result.encoded_bytes));
  dslr::recycle(std::move(result.mask));
  outcome.ms = io::ms_since(start);
  return outcome;
}

// A shot whose files are being written while the next shot renders. The manifest records it only
// once its files are in place.
struct PendingWrite {
  const ir::Shot* shot = nullptr;
  std::string key, image, mask;
  fs::path renderer_log;
  ShotTiming timing;
  std::future<WriteOutcome> outcome;
};

class RunLoop {
 public:
  RunLoop(const ir::Scene& scene, Backend& backend, const RunOptions& options, std::ostream& log,
          std::vector<ShotTiming>* timings)
      : scene_(scene),
        backend_(backend),
        options_(options),
        settings_(settings_for(backend, options.settings)),
        log_(log),
        timings_(timings),
        run_dir_(options.output_dir),
        manifest_path_(run_dir_ / "manifest.json") {}

  ~RunLoop() { writers_.wait(); }  // a task_group must be waited for before it dies

  int run();

 private:
  int check_options();
  bool open_run_folder();
  // The samples a pixel the run renders with: the settings', or the backend's default for 0.
  int samples() const {
    return settings_.samples != 0 ? settings_.samples : backend_.default_samples();
  }
  std::string key_of(const ir::Shot& shot) const;
  bool prepare_backend();
  bool render_and_queue(const ir::Shot& shot, const std::string& key);
  void queue_write(PendingWrite write, dslr::DevelopResult result);
  void finish_pending_write();
  void record_shot(const PendingWrite& write);
  void report_failure(const ir::Shot& shot, const std::string& error, const fs::path& log_path);
  void report_skipped(const ir::Shot& shot);
  void report_rendered(const ir::Shot& shot, const ShotTiming& timing);
  bool save_manifest(bool now);

  const ir::Scene& scene_;
  Backend& backend_;
  const RunOptions& options_;
  const RenderSettings settings_;
  std::ostream& log_;
  std::vector<ShotTiming>* timings_;
  const fs::path run_dir_, manifest_path_;
  fs::path work_dir_;
  std::vector<int> shots_;
  RunFolderLock lock_;
  Manifest manifest_;
  std::string content_hash_;
  std::optional<scene::StudioScene> studio_;
  std::optional<PendingWrite> pending_;
  tbb::task_group writers_;  // the writes run as tasks of the renderer's own threads
  int failures_ = 0, done_ = 0, rendered_ = 0;
  const Clock::time_point started_ = Clock::now();
  bool manifest_failed_ = false, write_failed_ = false, unsaved_ = false;
  Clock::time_point last_save_ = Clock::now() - std::chrono::hours(1);
};

int RunLoop::check_options() {
  std::string error;
  if (!settings_.check(&error) || !output_camera(scene_.camera, settings_.scale, &error) ||
      !backend_.check_settings(settings_, &error)) {
    log_ << fmt::format("rigc: error: {}\n", error);
    return 1;
  }
  if (!backend_.available(&error)) {
    log_ << fmt::format("rigc: error: {}\n", error);
    return 2;
  }
  shots_ = options_.shots;
  if (shots_.empty()) {
    for (const auto& shot : scene_.shots) shots_.push_back(shot.index);
  }
  for (int index : shots_) {
    if (index < 0 || index >= static_cast<int>(scene_.shots.size())) {
      log_ << fmt::format("rigc: error: shot {} does not exist (0..{})\n", index,
                          scene_.shots.size() - 1);
      return 1;
    }
  }
  return 0;
}

bool RunLoop::open_run_folder() {
  if (backend_.emits_scripts()) work_dir_ = run_dir_ / "render";
  std::vector<fs::path> extra;
  if (!work_dir_.empty()) extra.push_back(work_dir_);
  if (!prepare_run_folder(run_dir_, extra, log_) || !lock_.acquire(run_dir_, log_)) return false;
  remove_stale_temporaries(run_dir_);
  manifest_ = Manifest::load(manifest_path_);
  return claim_run_folder(manifest_, scene_, run_dir_, options_.force, log_) &&
         remove_unrecorded_outputs(manifest_, scene_, run_dir_, options_.force, log_) &&
         check_one_scale(manifest_, scene_, shots_, settings_.scale, log_);
}

std::string RunLoop::key_of(const ir::Shot& shot) const {
  std::vector<std::string> extra;
  if (backend_.takes_samples()) extra.push_back("samples=" + samples_text(samples()));
  if (const std::string options = backend_.options_key(); !options.empty()) {
    extra.push_back(options);
  }
  if (const int version = backend_.output_version(); version > 1) {
    extra.push_back(fmt::format("version={}", version));
  }
  return shot_key(scene_, content_hash_, shot, backend_.name(), settings_.scale, settings_.seed,
                  fmt::format("{}", fmt::join(extra, ";")));
}

// Instantiates the scene and lets the backend prepare (emit its scripts), once.
bool RunLoop::prepare_backend() {
  if (studio_) return true;
  studio_ = scene::prepare_studio_scene(scene_);
  std::string error;
  if (!backend_.prepare(scene_, *studio_, settings_, ShotFiles{work_dir_, {}}, &error)) {
    log_ << fmt::format("rigc: error: {}\n", error);
    return false;
  }
  return true;
}

int RunLoop::run() {
  if (const int code = check_options()) return code;
  if (!open_run_folder()) return 1;
  if (!prune_stale_outputs(manifest_, scene_, run_dir_, manifest_path_, log_)) return 2;
  content_hash_ = scene_content_hash(scene_);
  manifest_.set_backend(backend_.name());
  nlohmann::json inputs = {{"scene", scene_.name},
                           {"source_file", scene_.source_file},
                           {"content_sha256", content_hash_},
                           {"object_sha256", object_geometry_hash(scene_)},
                           {"scale", settings_.scale},
                           {"seed", settings_.seed}};
  if (backend_.takes_samples()) {
    inputs["samples"] =
        samples() == kConvergedSamples ? nlohmann::json("auto") : nlohmann::json(samples());
  }
  manifest_.set_inputs(std::move(inputs));

  for (int index : shots_) {
    const ir::Shot& shot = scene_.shots[index];
    const std::string key = key_of(shot);
    if (manifest_.is_done(shot.name, key, run_dir_)) {
      finish_pending_write();
      report_skipped(shot);
      continue;
    }
    if (!prepare_backend() || !render_and_queue(shot, key)) {
      finish_pending_write();
      return 2;
    }
    if (write_failed_) break;
  }
  finish_pending_write();
  if (write_failed_) {
    log_ << fmt::format("{}rigc: stopped after a shot's files could not be written\n",
                        options_.progress_bar ? "\n" : "");
  }
  if (manifest_failed_ || !save_manifest(true)) return 2;
  if (options_.progress_bar) log_ << '\n';
  return finish_run(scene_, manifest_, run_dir_, settings_.scale, failures_, shots_.size(), log_);
}

// Renders and develops a shot, finishes the previous shot's write meanwhile started, and queues
// this one's. False when the run must stop (the manifest cannot be saved).
bool RunLoop::render_and_queue(const ir::Shot& shot, const std::string& key) {
  const auto start = Clock::now();
  const ShotFiles files{work_dir_,
                        work_dir_.empty() ? fs::path() : work_dir_ / (shot.name + ".log")};
  std::error_code ec;
  if (!files.log.empty()) fs::remove(files.log, ec);
  RenderedShot rendered;
  std::string error;
  bool ok = backend_.render(scene_, *studio_, shot, settings_, files, &rendered, &error);
  PendingWrite write;
  write.timing.stage_ms = rendered.stage_ms;
  write.timing.subframes = rendered.subframes;
  dslr::DevelopResult result;
  if (ok) {
    result = develop_shot(scene_, shot, std::move(rendered), settings_, false, &error,
                          &write.timing.stage_ms);
    ok = !result.encoded.empty() || !result.encoded_bytes.empty();
    if (!ok && error.empty()) error = "the DSLR model produced no image";
  }
  write.timing.total_ms = io::ms_since(start);
  finish_pending_write();
  if (manifest_failed_) return false;
  if (!ok) {
    write.timing.failed = true;
    if (timings_) timings_->push_back(write.timing);
    report_failure(shot, error, files.log);
    return true;
  }
  write.shot = &shot;
  write.key = key;
  write.image = image_relative_path(scene_.camera, shot);
  write.mask = mask_relative_path(shot);
  write.renderer_log = files.log;
  queue_write(std::move(write), std::move(result));
  return true;
}

void RunLoop::queue_write(PendingWrite write, dslr::DevelopResult result) {
  auto task = std::make_shared<std::packaged_task<WriteOutcome()>>(
      [this, image = write.image, mask = write.mask, result = std::move(result)]() mutable {
        return write_shot_files(scene_, run_dir_, image, mask, result);
      });
  write.outcome = task->get_future();
  writers_.run([task] { (*task)(); });
  pending_ = std::move(write);
}

void RunLoop::finish_pending_write() {
  if (!pending_) return;
  PendingWrite write = std::move(*pending_);
  pending_.reset();
  writers_.wait();  // runs the write here if no other thread has taken it up
  const WriteOutcome outcome = write.outcome.get();
  write.timing.stage_ms["write"] = outcome.ms;
  write.timing.total_ms += outcome.ms;
  if (!outcome.error.empty()) {
    write.timing.failed = true;
    if (timings_) timings_->push_back(write.timing);
    report_failure(*write.shot, outcome.error, write.renderer_log);
    write_failed_ = true;  // a full disk or a lost folder: every later shot would fail the same way
    return;
  }
  record_shot(write);
}

void RunLoop::record_shot(const PendingWrite& write) {
  ShotRecord record;
  record.name = write.shot->name;
  record.key = write.key;
  record.render_ms = write.timing.total_ms;
  record.stage_ms = write.timing.stage_ms;
  record.files = {write.image, write.mask};
  record.scale = settings_.scale;
  record.seed = settings_.seed;
  manifest_.record(record);
  unsaved_ = true;
  if (!save_manifest(false)) return;
  ++done_;
  if (timings_) timings_->push_back(write.timing);
  report_rendered(*write.shot, write.timing);
}

bool RunLoop::save_manifest(bool now) {
  if (!unsaved_ || (!now && io::ms_since(last_save_) < kManifestSaveIntervalMs)) return true;
  // inputs.seed is every shot's seed, or null when `--shots` reran some with another.
  nlohmann::json inputs = manifest_.inputs();
  const bool one_seed =
      std::all_of(manifest_.shots().begin(), manifest_.shots().end(), [&](const auto& entry) {
        return !entry.second.seed || *entry.second.seed == settings_.seed;
      });
  inputs["seed"] = one_seed ? nlohmann::json(settings_.seed) : nlohmann::json(nullptr);
  manifest_.set_inputs(std::move(inputs));
  std::string error;
  if (!manifest_.save(manifest_path_, &error)) {
    log_ << fmt::format("rigc: error: {}\n", error);
    manifest_failed_ = true;
    return false;
  }
  last_save_ = Clock::now();
  unsaved_ = false;
  return true;
}

void RunLoop::report_failure(const ir::Shot& shot, const std::string& error,
                             const fs::path& log_path) {
  ++failures_;
  log_ << fmt::format(
      "{}rigc: error: {}: {}{}\n", options_.progress_bar ? "\n" : "", shot.name, error,
      log_path.empty() ? "" : fmt::format(" (renderer log: {})", log_path.string()));
}

void RunLoop::report_skipped(const ir::Shot& shot) {
  ShotTiming timing;
  timing.skipped = true;
  ++done_;
  if (timings_) timings_->push_back(timing);
  if (!options_.progress_bar) log_ << fmt::format("{}: up to date, skipped\n", shot.name);
}

void RunLoop::report_rendered(const ir::Shot& shot, const ShotTiming& timing) {
  // The time left at the pace of the shots rendered so far (those skipped took none).
  ++rendered_;
  const int total = static_cast<int>(shots_.size());
  const double left = io::ms_since(started_) / 1000 / rendered_ * (total - done_);
  if (options_.progress_bar) {
    log_ << progress_line(done_, total, shot.name, timing.total_ms / 1000, left) << std::flush;
    return;
  }
  log_ << fmt::format("{}: rendered with {} in {:.2f} s ({} sub-frame{}); {}/{}{}\n", shot.name,
                      backend_.name(), timing.total_ms / 1000, timing.subframes,
                      timing.subframes == 1 ? "" : "s", done_, total,
                      done_ < total ? ", about " + time_left_text(left) + " left" : "");
}

}  // namespace

int run_backend(const ir::Scene& scene, Backend& backend, const RunOptions& options,
                std::ostream& log, std::vector<ShotTiming>* timings) {
  return RunLoop(scene, backend, options, log, timings).run();
}

bool RenderSettings::check(std::string* error) const {
  if (!(scale > 0) || !std::isfinite(scale)) {
    *error = "the render scale must be a positive number";
    return false;
  }
  if (samples < 0 && samples != kConvergedSamples) {
    *error = "the samples per pixel must not be negative";
    return false;
  }
  return true;
}

std::optional<int> parse_samples(const std::string& text) {
  if (text == "auto") return kConvergedSamples;
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || value < 0 ||
      value > 65536) {
    return std::nullopt;
  }
  return value;
}

std::string samples_text(int samples) {
  return samples == kConvergedSamples ? "auto" : std::to_string(samples);
}

RenderSettings settings_for(const Backend& backend, RenderSettings settings) {
  if (settings.samples == kConvergedSamples && !backend.converges()) settings.samples = 0;
  return settings;
}

bool Backend::available(std::string* /*error*/) const {
  return true;
}

bool Backend::emit(const ir::Scene& /*scene*/, const scene::StudioScene& /*studio*/,
                   const fs::path& /*dir*/, const RenderSettings& /*settings*/,
                   std::string* error) {
  *error = fmt::format("the {} backend writes no scripts", name());
  return false;
}

bool Backend::prepare(const ir::Scene& /*scene*/, const scene::StudioScene& /*studio*/,
                      const RenderSettings& /*settings*/, const ShotFiles& /*files*/,
                      std::string* /*error*/) {
  return true;
}

dslr::DevelopResult develop_shot(const ir::Scene& scene, const ir::Shot& shot,
                                 RenderedShot&& rendered, const RenderSettings& settings,
                                 bool keep_linear, std::string* error,
                                 std::map<std::string, double>* stage_ms) {
  ir::Camera camera = scene.camera;
  // The renderer's lens already blurred out-of-focus points: do not blur them twice.
  if (rendered.depth_of_field_rendered) camera.effects.depth_of_field = false;
  dslr::ShotParams params;
  params.focus_distance_m = shot.focus_distance_m;
  params.shot_index = shot.index;
  params.seed = settings.seed;
  params.sensor_depth = false;  // only the image and the mask are written
  params.keep_linear = keep_linear;
  dslr::DevelopResult result =
      dslr::develop_frame(camera, std::move(rendered.frame), params, settings.scale, error);
  if (stage_ms) stage_ms->merge(development_stage_ms(result.timings));
  return result;
}

}  // namespace rigc::run
