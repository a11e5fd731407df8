#include "studio/session.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <thread>

#include "analysis/advice.h"
#include "analysis/coverage_output.h"
#include "backends/preview/preview_backend.h"
#include "compiler/diagnostics.h"
#include "compiler/frontend.h"
#include "compiler/limits.h"
#include "compiler/presets.h"
#include "compiler/scene_text.h"
#include "dslr/lens.h"
#include "io/atomic_file.h"
#include "io/bounded_file.h"
#include "io/file_status.h"
#include "plan/plan_scene.h"
#include "raster/shadow_map_cache.h"
#include "run/run_loop.h"
#include "scene/motion_blur.h"
#include "studio/frame_encoding.h"

namespace rigc::studio {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Compiled {
  std::optional<ir::Scene> scene;
  std::string diagnostics;  // rendered errors, each with its source line
};

Compiled compile_text(const std::string& text, const fs::path& file) {
  Compiled out;
  DiagnosticEngine diag;
  diag.set_handler([&](const Diagnostic& d, const std::string& rendered) {
    if (d.severity == Severity::kError) out.diagnostics += rendered;
  });
  out.scene = compile_scene_text(text, file.string(), file.parent_path().string(), diag);
  if (!out.scene && out.diagnostics.empty()) out.diagnostics = "the scene does not compile\n";
  return out;
}

// A number in metres as scene text, to the tenth of a millimetre.
std::string metres(double value) {
  return fmt::format("{:.4f}m", value);
}

std::string point_text(const Eigen::Vector3d& p) {
  return fmt::format("[{}, {}, {}]", metres(p.x()), metres(p.y()), metres(p.z()));
}

// Whether the scene's focus is `auto` (the IR keeps only the distances it gave each shot).
bool scene_focus_auto(const std::string& text) {
  try {
    const YAML::Node focus = YAML::Load(text)["camera"]["focus"];
    return !focus || (focus.IsScalar() && focus.Scalar() == "auto");
  } catch (const YAML::Exception&) {
    return false;
  }
}

// The scene's lens preset (`camera.lens.preset`), or "" when it gives a focal length only.
std::string scene_lens_preset(const std::string& text) {
  try {
    const YAML::Node preset = YAML::Load(text)["camera"]["lens"]["preset"];
    return preset && preset.IsScalar() ? preset.Scalar() : std::string();
  } catch (const YAML::Exception&) {
    return {};
  }
}

double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace

std::unique_ptr<Session> Session::open(const fs::path& scene_file, std::string* error,
                                       fs::path run_folder) {
  std::unique_ptr<Session> session(new Session());
  session->file_ = scene_file;
  session->disk_text_ = session->read_disk(error, &session->disk_identity_);
  if (!error->empty()) return nullptr;
  session->opened_target_ = file_to_replace(scene_file, error);
  if (!error->empty()) return nullptr;
  const Outcome outcome = session->apply_text(session->disk_text_, Change::kAnything);
  if (!outcome.ok) {
    *error = outcome.message;
    return nullptr;
  }
  // The first view: the scene's first shot.
  const ir::Shot& first = session->scene_->shots.front();
  View view;
  view.position = first.world_from_camera.block<3, 1>(0, 3);
  view.look_at = view.position + first.focus_distance_m * first.world_from_camera.block<3, 1>(0, 2);
  view.turntable_rad = first.turntable_angle_rad;
  const Outcome viewed = session->compile_view(view);
  if (!viewed.ok) {
    *error = viewed.message;
    return nullptr;
  }
  if (run_folder.empty()) run_folder = fs::path("out") / session->scene_->name / "studio";
  session->reference_ = std::make_unique<ReferenceCheck>(run_folder);
  return session;
}

Session::~Session() = default;

Outcome Session::start_reference(const ReferenceRequest& request) {
  if (!(request.width >= 64 && request.width <= 4096) || request.samples < 0) {
    return Outcome::fail("a reference is 64..4096 pixels wide, with samples >= 0");
  }
  const std::shared_ptr<const ir::Scene> view = view_scene();
  const double scale = std::min(1.0, static_cast<double>(request.width) / view->camera.width_px);
  std::string error;
  std::optional<Frame> preview = frame(scale, false, &error);
  if (!preview) return Outcome::fail(error);
  if (!reference_->start(view, scale, std::move(preview->jpeg), request, &error)) {
    return Outcome::fail(error);
  }
  return {};
}

std::string Session::read_disk(std::string* error, FileIdentity* identity) const {
  std::string why;
  auto file = read_bounded_file(file_, limits::kMostSceneFileBytes, &why);
  if (!file) {
    *error = fmt::format("rigc: error: cannot read {}: it {}\n", file_.string(), why);
    return {};
  }
  error->clear();
  *identity = file->identity;
  return std::move(file->bytes);
}

// Empty when file_ still leads to the file the session opened, that file is the one read or saved
// last and it holds what was read: otherwise why Save must not replace it.
std::string Session::changed_on_disk() const {
  std::string error;
  const fs::path target = file_to_replace(file_, &error);
  if (!error.empty()) return error;
  if (target != opened_target_) {
    return fmt::format("{} now leads to {}, not to the file the studio opened ({})", file_.string(),
                       target.string(), opened_target_.string());
  }
  if (names_nothing(target)) return "";  // deleted since: Save writes it anew
  FileIdentity identity;
  const std::string now = read_disk(&error, &identity);
  if (!error.empty()) return error;
  if (identity == disk_identity_ && now == disk_text_) return "";
  std::size_t line = 1, at = 0;
  while (at < now.size() && at < disk_text_.size() && now[at] == disk_text_[at]) {
    if (now[at++] == '\n') ++line;
  }
  const std::size_t start = now.rfind('\n', at == 0 ? 0 : at - 1);
  const std::size_t from = start == std::string::npos || at == 0 ? 0 : start + 1;
  const std::string now_line = now.substr(from, now.find('\n', from) - from);
  return fmt::format(
      "{} changed on disk since the studio read it (line {} now reads '{}'); the studio "
      "loads it on its next poll, then Save writes your changes over it",
      file_.string(), line, now_line.substr(0, 80));
}

// Compiles `text`; when it compiles it becomes the session's scene, otherwise the last good
// scene stays and the diagnostics are the message. What `change` cannot have touched is kept.
// Unless only shots changed, the view is compiled with it in one go: appended as the last shot
// (the compiler places, focuses and refuses it there as in a scene of its own).
Outcome Session::apply_text(std::string text, Change change) {
  std::optional<ir::Shot> view_shot;
  std::optional<ir::Scene> compiled_scene;
  if (view_shot_ && change != Change::kShots) {
    std::string error;
    std::string entry = view_pose_text(view_);
    entry = entry.substr(1, entry.size() - 2);
    const auto with_view = append_to_list(text, {"shots"}, entry, &error);
    if (!with_view) return Outcome::fail(error);
    Compiled compiled = compile_text(*with_view, file_);
    if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
    view_shot = as_view_shot(compiled.scene->shots.back());
    compiled.scene->shots.pop_back();
    compiled_scene = std::move(compiled.scene);
  } else {
    Compiled compiled = compile_text(text, file_);
    if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
    compiled_scene = std::move(compiled.scene);
  }
  auto scene = std::make_shared<const ir::Scene>(std::move(*compiled_scene));
  studio_ = change != Change::kAnything && studio_
                ? studio_
                : std::make_shared<const scene::StudioScene>(scene::prepare_studio_scene(*scene));
  text_ = std::move(text);
  scene_ = scene;
  if (view_shot) view_shot_ = std::move(view_shot);
  if (change != Change::kShots) ++analysis_generation_;
  ++revision_;
  return {};
}

std::string Session::view_pose_text(const View& view) const {
  return fmt::format("{{pose: {{position: {}, look_at: {}, turntable: {:.3f}deg}}}}",
                     point_text(view.position), point_text(view.look_at),
                     view.turntable_rad * 180 / std::numbers::pi);
}

// The view is compiled as the scene's only shot, so that the compiler places it, focuses it and
// refuses it (below the floor, inside the table) with its own message.
Outcome Session::compile_view(const View& view) {
  std::string error;
  std::string pose = view_pose_text(view);
  pose = pose.substr(1, pose.size() - 2);  // the entry without its braces
  const auto text = replace_section(text_, "shots", "shots:\n  - " + pose + "\n", &error);
  if (!text) return Outcome::fail(error);
  Compiled compiled = compile_text(*text, file_);
  if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
  view_shot_ = as_view_shot(compiled.scene->shots.front());
  view_ = view;
  ++revision_;
  return {};
}

// The view's shot as a scene of its own would hold it: the first.
ir::Shot Session::as_view_shot(ir::Shot shot) {
  shot.index = 0;
  shot.name = "shot_000";
  return shot;
}

// The scene with the view as its only shot (for the reference check).
std::shared_ptr<const ir::Scene> Session::view_scene() {
  std::lock_guard lock(mutex_);
  auto view = std::make_shared<ir::Scene>(*scene_);
  view->shots = {*view_shot_};
  return view;
}

Outcome Session::set_value(const ScenePath& path, const std::string& value) {
  return set_values({{path, value}});
}

Outcome Session::set_values(const std::vector<std::pair<ScenePath, std::string>>& values) {
  std::lock_guard lock(mutex_);
  std::string text = text_;
  Change change = Change::kCamera;
  for (const auto& [path, value] : values) {
    if (path.size() < 2 || (path[0] != "camera" && path[0] != "studio")) {
      return Outcome::fail("only camera.* and studio.* values can be set");
    }
    std::string error;
    const auto edited = rigc::set_value(text, path, value, &error);
    if (!edited) return Outcome::fail(error);
    text = *edited;
    if (path[0] != "camera") change = Change::kAnything;
  }
  return push_text(text, change);
}

Outcome Session::add_light(const std::string& entry) {
  std::lock_guard lock(mutex_);
  std::string error;
  const auto text = append_to_list(text_, {"studio", "lights"}, entry, &error);
  if (!text) return Outcome::fail(error);
  return push_text(*text, Change::kAnything);
}

Outcome Session::remove_light(size_t index) {
  std::lock_guard lock(mutex_);
  std::string error;
  const auto text = remove_from_list(text_, {"studio", "lights"}, index, &error);
  if (!text) return Outcome::fail(error);
  return push_text(*text, Change::kAnything);
}

void Session::remember_for_undo(std::string text, Change change) {
  undo_.push_back({std::move(text), change});
  if (undo_.size() > kMostUndoSteps) undo_.pop_front();
}

// A change the user can undo.
Outcome Session::push_text(const std::string& text, Change change) {
  std::string before = text_;
  const Outcome outcome = apply_text(text, change);
  if (outcome.ok) remember_for_undo(std::move(before), change);
  return outcome;
}

Outcome Session::set_view(const View& view) {
  std::lock_guard lock(mutex_);
  if (!view.position.allFinite() || !view.look_at.allFinite() ||
      !std::isfinite(view.turntable_rad)) {
    return Outcome::fail("the view's numbers must be finite");
  }
  return compile_view(view);
}

Outcome Session::capture() {
  std::lock_guard lock(mutex_);
  std::string error;
  std::string entry = view_pose_text(view_);
  entry = entry.substr(1, entry.size() - 2);
  const auto text = append_to_list(text_, {"shots"}, entry, &error);
  if (!text) return Outcome::fail(error);
  const Outcome outcome = push_text(*text, Change::kShots);
  if (outcome.ok) ++captures_;
  return outcome;
}

Outcome Session::suggest_next_shot(Suggestion* suggestion) {
  std::lock_guard analysing(analysis_mutex_);
  plan::PlanRequest request;
  {
    std::lock_guard lock(mutex_);
    request.scene_text = text_;
  }
  request.scene_path = request.output_path = file_.string();
  request.keep_scene_shots = request.next_shot_only = true;
  request.target = 1;
  request.candidates.azimuth_step_rad = 20 * std::numbers::pi / 180;  // seconds, not tens
  DiagnosticEngine diag;
  std::ostringstream diagnostics;
  diag.set_handler(
      [&](const Diagnostic&, const std::string& rendered) { diagnostics << rendered; });
  std::string error;
  const auto outcome = plan::plan_scene(request, diag, &error);
  if (!outcome) return Outcome::fail(error.empty() ? diagnostics.str() : error);
  if (static_cast<int>(outcome->plan.shots.size()) <= outcome->kept) {
    return Outcome::fail("no candidate pose adds reconstructable surface to the shots so far");
  }
  const plan::PlannedShot& next = outcome->plan.shots.back();
  const ir::Shot& shot = outcome->candidate_shots[next.candidate];
  View view;
  view.position = shot.world_from_camera.block<3, 1>(0, 3);
  view.look_at = view.position + shot.world_from_camera.block<3, 1>(0, 2) * shot.focus_distance_m;
  view.turntable_rad = shot.turntable_angle_rad;
  suggestion->gain = next.gain;
  suggestion->reconstructable = next.reconstructable;
  suggestion->entry = plan::planned_shots_text(*outcome);
  std::lock_guard lock(mutex_);
  return compile_view(view);
}

Outcome Session::undo() {
  std::lock_guard lock(mutex_);
  if (undo_.empty()) return Outcome::fail("nothing to undo");
  const UndoEntry entry = undo_.back();
  const Outcome outcome = apply_text(entry.text, entry.change);
  if (outcome.ok) undo_.pop_back();
  return outcome;
}

// The session's text compiled when it was applied, so the file written always compiles; the
// write is atomic.
Outcome Session::save() {
  std::lock_guard lock(mutex_);
  const Compiled compiled = compile_text(text_, file_);
  if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
  if (const std::string changed = changed_on_disk(); !changed.empty()) {
    return Outcome::fail("rigc: error: not saved: " + changed);
  }
  std::string error;
  if (!write_file_atomically(file_, text_, &error)) return Outcome::fail("rigc: error: " + error);
  disk_text_ = text_;
  if (const auto identity = identity_of(file_)) disk_identity_ = *identity;
  disk_error_.clear();
  file_error_.clear();
  return {};
}

void Session::reload_if_changed() {
  std::lock_guard lock(mutex_);
  std::string error;
  FileIdentity identity;
  const std::string text = read_disk(&error, &identity);
  if (error != disk_error_) ++revision_;
  disk_error_ = error;
  if (!error.empty()) return;
  disk_identity_ = identity;
  if (text == disk_text_) return;
  disk_text_ = text;
  const std::string before = text_;
  const Outcome outcome = apply_text(text, Change::kAnything);
  file_error_ = outcome.ok ? "" : outcome.message;
  ++revision_;
  ++reloads_;
  if (outcome.ok && before != text) remember_for_undo(before, Change::kAnything);
}

namespace {

nlohmann::json vec_json(const Eigen::Vector3d& v) {
  return {v.x(), v.y(), v.z()};
}

nlohmann::json camera_json(const ir::Camera& c) {
  const double ev100 =
      std::log2(c.aperture_f_number * c.aperture_f_number / c.shutter_s) - std::log2(c.iso / 100);
  return {{"body", c.body},
          {"make", c.make},
          {"model", c.model},
          {"sensor_mm", {c.sensor_width_m * 1000, c.sensor_height_m * 1000}},
          {"pixels", {c.width_px, c.height_px}},
          {"focal_length_mm", c.focal_length_m * 1000},
          {"aperture", c.aperture_f_number},
          {"shutter_s", c.shutter_s},
          {"iso", c.iso},
          {"white_balance_auto", c.white_balance == ir::WhiteBalanceMode::kAuto},
          {"white_balance_k", c.white_balance_k},
          {"ev100", ev100}};
}

nlohmann::json lights_json(const std::vector<ir::Light>& lights) {
  static const char* kTypes[] = {"point", "spot", "directional", "area"};
  nlohmann::json out = nlohmann::json::array();
  for (const auto& light : lights) {
    out.push_back({{"type", kTypes[static_cast<int>(light.type)]},
                   {"position", vec_json(light.position)},
                   {"power_w", light.power_w},
                   {"illuminance_lx", light.illuminance_lx},
                   {"temperature_k", light.temperature_k},
                   {"size_m", {light.size_m.x(), light.size_m.y()}},
                   {"line", light.loc.line}});
  }
  return out;
}

}  // namespace

nlohmann::json Session::state() {
  std::lock_guard lock(mutex_);
  const ir::Scene& scene = *scene_;
  const ir::Shot& view_shot = *view_shot_;
  const auto focus = scene_focus_auto(text_);
  nlohmann::json bodies = nlohmann::json::array();
  for (const auto& preset : body_presets()) bodies.push_back(preset.name);
  nlohmann::json lenses = nlohmann::json::array();
  for (const auto& lens : lens_presets()) {
    lenses.push_back({{"name", lens.name},
                      {"model", lens.model},
                      {"focal_mm", {lens.shortest_focal_m * 1000, lens.longest_focal_m * 1000}},
                      {"f_numbers", {lens.widest_f_number, lens.narrowest_f_number}},
                      {"min_focus_m", lens.min_focus_m}});
  }
  const Eigen::Vector3d center =
      (ir::world_from_object(scene, view_.turntable_rad) *
       ((scene.object.bounds_min_object + scene.object.bounds_max_object) / 2).homogeneous())
          .head<3>();
  return {{"file", file_.filename().string()},
          {"name", scene.name},
          {"unsaved", text_ != disk_text_},
          {"file_error", disk_error_.empty() ? file_error_ : disk_error_},
          {"captures", captures_},
          {"revision", revision_},
          {"reloads", reloads_},
          {"can_undo", !undo_.empty()},
          {"shots", scene.shots.size()},
          {"camera", camera_json(scene.camera)},
          {"focus_auto", focus},
          {"view",
           {{"position", vec_json(view_.position)},
            {"look_at", vec_json(view_.look_at)},
            {"turntable_deg", view_.turntable_rad * 180 / std::numbers::pi},
            {"focus_distance_m", view_shot.focus_distance_m}}},
          {"object_center", vec_json(center)},
          {"studio",
           {{"turntable_diameter_m", scene.studio.turntable.diameter_m},
            {"turntable_height_m", scene.studio.turntable.height_m},
            {"green_screen", scene.studio.backdrop.green_screen},
            {"ambient_lx", scene.studio.ambient_lx},
            {"lights", lights_json(scene.studio.lights)}}},
          {"bodies", bodies},
          {"lens", scene_lens_preset(text_)},
          {"lenses", lenses}};
}

// The preview's linear frame of `shot`, or the one kept from an earlier frame that differs only
// in what the DSLR model applies (exposure, focus, white balance, noise). The studio stays the
// same object as long as the object, the materials, the studio and its lights do.
bool Session::render_linear(const ir::Scene& scene,
                            const std::shared_ptr<const scene::StudioScene>& studio,
                            const ir::Shot& shot, const run::RenderSettings& settings, bool draft,
                            std::shared_ptr<const run::RenderedShot>* rendered, bool* reused) {
  RenderCache key;
  key.draft = draft;
  key.studio = studio;
  key.world_from_camera = shot.world_from_camera;
  key.turntable_angle_rad = shot.turntable_angle_rad;
  key.turntable_velocity_rad_s = shot.turntable_velocity_rad_s;
  key.canvas = dslr::render_geometry_for(scene.camera, settings.scale);
  key.subframes = scene::motion_blur_subframes(scene, *studio, shot, settings.scale);
  key.shutter_s = key.subframes > 1 ? scene.camera.shutter_s : 0;
  const auto same = [&](const RenderCache& c) {
    return c.studio == key.studio && c.world_from_camera == key.world_from_camera &&
           c.turntable_angle_rad == key.turntable_angle_rad &&
           c.turntable_velocity_rad_s == key.turntable_velocity_rad_s &&
           c.shutter_s == key.shutter_s && c.subframes == key.subframes && c.draft == key.draft &&
           c.canvas.width == key.canvas.width && c.canvas.height == key.canvas.height &&
           c.canvas.fx == key.canvas.fx && c.canvas.fy == key.canvas.fy &&
           c.canvas.cx == key.canvas.cx && c.canvas.cy == key.canvas.cy;
  };
  const auto hit = std::find_if(render_cache_.begin(), render_cache_.end(), same);
  *reused = hit != render_cache_.end();
  if (*reused) {
    *rendered = hit->rendered;
    return true;
  }
  auto fresh = std::make_shared<run::RenderedShot>();
  render_preview(scene, studio, shot, settings.scale, draft, fresh.get());
  key.rendered = *rendered = std::move(fresh);
  render_cache_.push_front(std::move(key));
  // The live view's two sizes (moving and at rest) of the current view.
  if (render_cache_.size() > 2) render_cache_.pop_back();
  return true;
}

// The preview's frame, with the shadow maps kept while the studio (and its lights) stays.
void Session::render_preview(const ir::Scene& scene,
                             const std::shared_ptr<const scene::StudioScene>& studio,
                             const ir::Shot& shot, double scale, bool draft,
                             run::RenderedShot* rendered) {
  if (shadow_studio_ != studio || !shadow_cache_) {
    shadow_cache_ = std::make_unique<raster::ShadowMapCache>();
    shadow_studio_ = studio;
  }
  *rendered = preview::render_linear(scene, *studio, shot, scale, shadow_cache_.get(),
                                     {.draft_surface = draft});
}

std::optional<Frame> Session::frame(double scale, bool draft, std::string* error) {
  std::shared_ptr<const ir::Scene> scene;
  std::shared_ptr<const scene::StudioScene> studio;
  ir::Shot shot;
  {
    std::lock_guard lock(mutex_);
    scene = scene_;
    shot = *view_shot_;
    studio = studio_;
  }
  ++frames_rendering_;
  struct Done {
    std::atomic<int>& count;
    std::atomic<std::int64_t>& ended;
    ~Done() {
      ended = Clock::now().time_since_epoch().count();
      --count;
    }
  } done{frames_rendering_, last_frame_end_};
  std::lock_guard render_lock(render_mutex_);
  const auto start = Clock::now();
  run::RenderSettings settings;
  settings.scale = scale;
  if (!settings.check(error)) return std::nullopt;
  std::shared_ptr<const run::RenderedShot> rendered;
  Frame frame;
  if (!render_linear(*scene, studio, shot, settings, draft, &rendered, &frame.reused_render)) {
    return std::nullopt;
  }
  error->clear();
  std::map<std::string, double> stages;
  if (!frame.reused_render) stages = rendered->stage_ms;
  bool reused_optics = false;
  dslr::DevelopResult developed =
      live_develop_.develop(scene->camera, std::move(rendered), shot, settings.seed, scale,
                            &reused_optics, error, &stages);
  if (developed.encoded_bytes.empty()) {
    if (error->empty()) *error = "the DSLR model produced no image";
    return std::nullopt;
  }
  frame.width = developed.width;
  frame.height = developed.height;
  frame.render_ms = ms_since(start);
  frame.stage_ms = std::move(stages);
  const auto encode_start = Clock::now();
  frame.jpeg = encode_jpeg(developed.encoded_bytes, frame.width, frame.height, 90, error);
  if (frame.jpeg.empty()) return std::nullopt;
  frame.histogram = histogram_of(developed.encoded_bytes);
  frame.encode_ms = ms_since(encode_start);
  return frame;
}

// The coverage of `scene`'s shots with `options`. A kept analysis of the same scene but for its
// shots (`key`: the scene text without them) serves: the shots it has beyond those `scene`
// begins with are taken back, and `scene`'s further shots added. Nullopt when a newer change
// started another generation meanwhile (the analysis stops at its next shot, and is kept for
// when its scene comes back), or when a capture waits for a background coverage. A background
// analysis yields to the live view between shots.
std::optional<analysis::CoverageResult> Session::analyse(std::deque<AnalysisCache>& caches,
                                                         const Analysed& what,
                                                         const analysis::CoverageOptions& options,
                                                         bool background) {
  const auto same_shot = [](const ir::Shot& a, const ir::Shot& b) {
    return a.world_from_camera == b.world_from_camera &&
           a.object_from_camera == b.object_from_camera &&
           a.turntable_angle_rad == b.turntable_angle_rad &&
           a.turntable_velocity_rad_s == b.turntable_velocity_rad_s &&
           a.focus_distance_m == b.focus_distance_m;
  };
  const auto& shots = what.scene->shots;
  auto hit = std::find_if(caches.begin(), caches.end(),
                          [&](const AnalysisCache& c) { return c.key == what.key; });
  if (hit == caches.end()) {
    caches.push_front({what.key, nullptr});
    if (caches.size() > kKeptAnalyses) caches.pop_back();
    hit = caches.begin();
  }
  // Each kept state is a copy of the whole analysis: only the scene in use keeps its undo.
  for (auto& other : caches) {
    if (&other != &*hit && other.run) other.run->forget_undo();
  }
  AnalysisCache& cache = *hit;
  if (cache.run) {
    const auto& kept = cache.run->shots();
    size_t common = 0;
    while (common < kept.size() && common < shots.size() &&
           same_shot(kept[common], shots[common])) {
      ++common;
    }
    while (cache.run && static_cast<size_t>(cache.run->shot_count()) > common) {
      if (!cache.run->remove_last_shot()) cache.run.reset();
    }
  }
  if (!cache.run) {
    cache.run = std::make_unique<analysis::IncrementalCoverage>(what.scene, what.studio, options);
  }
  // The live view first: while frames come (a slider or the camera moving), the next shot of a
  // background analysis waits until they pause, unless a capture waits for the coverage.
  const auto live_view_busy = [&] {
    const Clock::duration since_frame =
        Clock::now().time_since_epoch() - Clock::duration(last_frame_end_.load());
    return urgent_requests_ == 0 &&
           (frames_rendering_ > 0 || since_frame < std::chrono::milliseconds(200));
  };
  for (size_t s = cache.run->shot_count(); s < shots.size(); ++s) {
    if (analysis_generation_ != what.generation) return std::nullopt;
    // A background analysis hands the kept work to a waiting capture's (it goes on from here).
    if (background && urgent_requests_ > 0 && &caches == &coverage_caches_) return std::nullopt;
    while (background && live_view_busy() && analysis_generation_ == what.generation) {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    cache.run->add_shot(shots[s]);
  }
  return cache.run->result();
}

// What the analyses see now: the scene, its studio, the generation and the cache key.
Session::Analysed Session::analysed() {
  std::lock_guard lock(mutex_);
  std::string error;
  const auto without_shots = replace_section(text_, "shots", "shots:\n", &error);
  return {scene_, studio_, analysis_generation_, without_shots ? *without_shots : text_};
}

// The coverage `rigc coverage` computes (its default options). A capture's (not `background`)
// goes first: background analyses stop yielding to the live view while it waits.
std::optional<nlohmann::json> Session::coverage(bool background) {
  const Analysed what = analysed();
  struct Urgent {
    std::atomic<int>& count;
    bool on;
    ~Urgent() {
      if (on) --count;
    }
  } urgent{urgent_requests_, !background};
  if (!background) ++urgent_requests_;
  const auto asked = Clock::now();
  std::lock_guard coverage_lock(coverage_mutex_);
  const auto start = Clock::now();
  analysis::CoverageOptions options;
  options.visibility_cache = visibility_cache_;
  const auto result = analyse(coverage_caches_, what, options, background);
  if (!result) return std::nullopt;
  const double ms = ms_since(start);
  nlohmann::json out = coverage_json(*what.scene, *result);
  out["wait_ms"] = std::chrono::duration<double, std::milli>(start - asked).count();
  out["analysis_ms"] = ms;
  out["json_ms"] = ms_since(start) - ms;
  return out;
}

nlohmann::json Session::coverage_json(const ir::Scene& scene,
                                      const analysis::CoverageResult& coverage) const {
  std::ostringstream table;
  analysis::print_coverage_table(scene, coverage, table);
  const analysis::ShotCoverage& last = coverage.shots.back();
  return {{"views", coverage.views},
          {"reconstructable_faces", coverage.reconstructable},
          {"table", table.str()},
          {"shots", coverage.shots.size()},
          {"seen_1", last.seen_1},
          {"seen_2", last.seen_2},
          {"reconstructable", last.reconstructable},
          {"new", last.new_area_m2 / coverage.total_area_m2},
          {"overlap", last.overlap_with_previous}};
}

// The warnings `rigc check` prints, at the same reduced resolution.
std::optional<nlohmann::json> Session::advice() {
  const Analysed what = analysed();
  std::shared_ptr<const ir::Scene> scene = what.scene;
  std::lock_guard analysis_lock(analysis_mutex_);
  const std::string text = text_snapshot(scene);
  for (const auto& [given_for, given] : advice_given_) {
    if (!text.empty() && given_for == text) return given;
  }
  DiagnosticEngine diag;
  diag.add_source(file_.string(), text);
  nlohmann::json out = nlohmann::json::array();
  diag.set_handler([&](const Diagnostic& d, const std::string& rendered) {
    out.push_back({{"line", d.loc.line},
                   {"col", d.loc.col},
                   {"severity", d.severity == Severity::kError ? "error" : "warning"},
                   {"message", d.message},
                   {"rendered", rendered}});
  });
  analysis::CoverageOptions options;
  options.visibility_scale = std::min(1.0, 700.0 / scene->camera.width_px);
  options.visibility_cache = visibility_cache_;
  const auto coverage = analyse(advice_caches_, what, options, true);
  if (!coverage) return std::nullopt;
  analysis::report_capture_advice(*scene, *what.studio, *coverage, diag);
  if (!text.empty()) {
    advice_given_.emplace_front(text, out);
    if (advice_given_.size() > kKeptAnalyses) advice_given_.pop_back();
  }
  return out;
}

std::string Session::text_snapshot(const std::shared_ptr<const ir::Scene>& scene) {
  std::lock_guard lock(mutex_);
  return scene == scene_ ? text_ : std::string();
}

// The object's mesh in the object frame, for the page's coverage view.
nlohmann::json Session::mesh() {
  std::shared_ptr<const ir::Scene> scene;
  {
    std::lock_guard lock(mutex_);
    scene = scene_;
  }
  const std::vector<Eigen::Vector3f> positions = ir::object_frame_positions(scene->object);
  std::vector<float> flat;
  flat.reserve(positions.size() * 3);
  for (const auto& p : positions) flat.insert(flat.end(), {p.x(), p.y(), p.z()});
  std::vector<std::uint32_t> indices;
  indices.reserve(scene->object.mesh.triangles.size() * 3);
  for (const auto& t : scene->object.mesh.triangles)
    indices.insert(indices.end(), t.begin(), t.end());
  return {{"positions", flat}, {"triangles", indices}};
}

int Session::sensor_width_px() {
  std::lock_guard lock(mutex_);
  return scene_->camera.width_px;
}

}  // namespace rigc::studio
