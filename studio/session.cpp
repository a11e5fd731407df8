#include "studio/session.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "compiler/diagnostics.h"
#include "compiler/frontend.h"
#include "compiler/presets.h"
#include "compiler/scene_text.h"
#include "dslr/lens.h"
#include "dslr/stops.h"
#include "plan/plan_scene.h"

namespace rigc::studio {
namespace {

namespace fs = std::filesystem;

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

}  // namespace

std::unique_ptr<Session> Session::open(const fs::path& scene_file, std::string* error,
                                       fs::path run_folder) {
  std::unique_ptr<Session> session(new Session());
  SceneDocument& document = session->document_;
  if (!document.open(scene_file, error)) return nullptr;
  const Outcome outcome = session->apply_text(document.disk_text(), Change::kAnything);
  if (!outcome.ok) {
    *error = outcome.message;
    return nullptr;
  }
  document.set_text(document.disk_text());
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

// Compiles `text`; when it compiles it becomes the session's scene (the caller gives the
// document the text), otherwise the last good scene stays and the diagnostics are the message.
// What `change` cannot have touched is kept. Unless only shots changed, the view is compiled with
// it in one go: appended as the last shot (the compiler places, focuses and refuses it there as
// in a scene of its own).
Outcome Session::apply_text(const std::string& text, Change change) {
  const fs::path& file = document_.file();
  std::optional<ir::Shot> view_shot;
  std::optional<ir::Scene> compiled_scene;
  if (view_shot_ && change != Change::kShots) {
    std::string error;
    std::string entry = view_pose_text(view_);
    entry = entry.substr(1, entry.size() - 2);
    const auto with_view = append_to_list(text, {"shots"}, entry, &error);
    if (!with_view) return Outcome::fail(error);
    Compiled compiled = compile_text(*with_view, file);
    if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
    view_shot = as_view_shot(compiled.scene->shots.back());
    compiled.scene->shots.pop_back();
    compiled_scene = std::move(compiled.scene);
  } else {
    Compiled compiled = compile_text(text, file);
    if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
    compiled_scene = std::move(compiled.scene);
  }
  auto scene = std::make_shared<const ir::Scene>(std::move(*compiled_scene));
  studio_ = change != Change::kAnything && studio_
                ? studio_
                : std::make_shared<const scene::StudioScene>(scene::prepare_studio_scene(*scene));
  scene_ = scene;
  if (view_shot) view_shot_ = std::move(view_shot);
  if (change != Change::kShots) analyses_.next_generation();
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
  const auto text =
      replace_section(document_.text(), "shots", "shots:\n  - " + pose + "\n", &error);
  if (!text) return Outcome::fail(error);
  Compiled compiled = compile_text(*text, document_.file());
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
  std::string text = document_.text();
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
  const auto text = append_to_list(document_.text(), {"studio", "lights"}, entry, &error);
  if (!text) return Outcome::fail(error);
  return push_text(*text, Change::kAnything);
}

Outcome Session::remove_light(size_t index) {
  std::lock_guard lock(mutex_);
  std::string error;
  const auto text = remove_from_list(document_.text(), {"studio", "lights"}, index, &error);
  if (!text) return Outcome::fail(error);
  return push_text(*text, Change::kAnything);
}

// A change the user can undo.
Outcome Session::push_text(const std::string& text, Change change) {
  const Outcome outcome = apply_text(text, change);
  if (outcome.ok) document_.change_text(text, change);
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
  const auto text = append_to_list(document_.text(), {"shots"}, entry, &error);
  if (!text) return Outcome::fail(error);
  const Outcome outcome = push_text(*text, Change::kShots);
  if (outcome.ok) ++captures_;
  return outcome;
}

Outcome Session::suggest_next_shot(Suggestion* suggestion) {
  std::lock_guard planning(analyses_.advice_mutex());
  plan::PlanRequest request;
  {
    std::lock_guard lock(mutex_);
    request.scene_text = document_.text();
  }
  request.scene_path = request.output_path = document_.file().string();
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
  if (!document_.can_undo()) return Outcome::fail("nothing to undo");
  const UndoStep& step = document_.last_step();
  const Outcome outcome = apply_text(step.text, step.change);
  if (outcome.ok) document_.undo_last_step();
  return outcome;
}

// The session's text compiled when it was applied, so the file written always compiles; the
// write is atomic.
Outcome Session::save() {
  std::lock_guard lock(mutex_);
  const Compiled compiled = compile_text(document_.text(), document_.file());
  if (!compiled.scene) return Outcome::fail(compiled.diagnostics);
  std::string error;
  if (!document_.save(&error)) return Outcome::fail(error);
  return {};
}

void Session::reload_if_changed() {
  std::lock_guard lock(mutex_);
  bool read_error_changed = false;
  const std::optional<std::string> text = document_.poll_disk(&read_error_changed);
  if (read_error_changed) ++revision_;
  if (!text) return;
  const Outcome outcome = apply_text(*text, Change::kAnything);
  document_.reloaded(*text, outcome.ok, outcome.message);
  ++revision_;
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

// A table of camera steps for the page's sliders.
template <std::size_t N>
nlohmann::json table(const double (&steps)[N]) {
  return std::vector<double>(std::begin(steps), std::end(steps));
}

}  // namespace

nlohmann::json Session::state() {
  std::lock_guard lock(mutex_);
  const ir::Scene& scene = *scene_;
  const ir::Shot& view_shot = *view_shot_;
  const std::string& text = document_.text();
  const auto focus = scene_focus_auto(text);
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
  return {{"file", document_.file().filename().string()},
          {"name", scene.name},
          {"unsaved", document_.unsaved()},
          {"file_error", document_.file_error()},
          {"captures", captures_},
          {"revision", revision_},
          {"reloads", document_.reloads()},
          {"can_undo", document_.can_undo()},
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
          {"stops",
           {{"apertures", table(dslr::kFNumberStops)},
            {"shutters", table(dslr::kShutterStops)},
            {"isos", table(dslr::kIsoStops)}}},
          {"lens", scene_lens_preset(text)},
          {"lenses", lenses}};
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
  return live_view_.frame(*scene, studio, shot, {scale, draft}, error);
}

// What the analyses see now: the scene, its studio, the generation and the cache key.
AnalysedScene Session::analysed() {
  std::lock_guard lock(mutex_);
  std::string error;
  const std::string& text = document_.text();
  const auto without_shots = replace_section(text, "shots", "shots:\n", &error);
  return {scene_, studio_, analyses_.generation(), without_shots ? *without_shots : text};
}

std::optional<nlohmann::json> Session::coverage(bool background) {
  return analyses_.coverage(analysed(), background);
}

std::optional<nlohmann::json> Session::advice() {
  const AnalysedScene what = analysed();
  return analyses_.advice(
      what, [&] { return text_snapshot(what.scene); }, document_.file());
}

std::string Session::text_snapshot(const std::shared_ptr<const ir::Scene>& scene) {
  std::lock_guard lock(mutex_);
  return scene == scene_ ? document_.text() : std::string();
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
