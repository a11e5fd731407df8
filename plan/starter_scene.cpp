#include "plan/starter_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>

#include "analysis/advice.h"
#include "compiler/frontend.h"
#include "dslr/optics.h"
#include "dslr/stops.h"
#include "plan/plan_scene.h"

namespace rigc::plan {

namespace {

namespace fs = std::filesystem;

// The share of the frame's height (or width) the object fills.
constexpr double kFrameFill = 0.6;
// The turntable's photos before the plan: a ring that the advice can judge.
constexpr int kDraftSteps = 24;
// Advice rounds: each applies the exposure and aperture `check` works out, then checks again.
constexpr int kAdviceRounds = 4;

// What the scene states, and why (each reason becomes the comment at its line).
struct Choices {
  std::string model;  // as the scene writes it: relative to the scene's folder
  std::optional<double> height_m;
  std::string body;
  double focal_length_m = 0.05;
  // The first draft's camera stands outside any object the language allows (100 m at most).
  double distance_m = 500, camera_height_m = 0.15;
  double f_number = 8, shutter_s = 1.0 / 125, iso = 200;
  double light_power_w = 80;
  bool speckle = false;  // the model has no colours or texture of its own
  std::string shots;     // the planner's shots section; empty: the draft's ring
  std::string size_why, distance_why, aperture_why, exposure_why;
};

std::string length_text(double m) {
  return fmt::format("{:.1f}cm", 100 * m);
}

std::string shutter_text(double s) {
  return s >= 0.3 ? fmt::format("{:g}s", s) : fmt::format("1/{:.0f}", 1 / s);
}

// `text` as comment lines of at most 100 characters, indented by `indent`.
std::string comment(const std::string& text, int indent) {
  const std::string lead = std::string(indent, ' ') + "# ";
  std::string out, line;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(' ', start);
    if (end == std::string::npos) end = text.size();
    const std::string word = text.substr(start, end - start);
    if (!line.empty() && lead.size() + line.size() + 1 + word.size() > 100) {
      out += lead + line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    start = end + 1;
  }
  if (!line.empty()) out += lead + line + "\n";
  return out;
}

std::string scene_text(const Choices& c) {
  std::string y = "# A starting scene written by `rigc new` for " + c.model +
                  ". Each choice says why; edit any of\n"
                  "# them and run `rigc check` (docs/commands.md).\n";
  y += "rigc: 1\n";
  y += "name: " + fs::path(c.model).stem().string() + "\n";
  y += "object:\n";
  y += fmt::format("  mesh: \"{}\"\n", c.model);
  if (c.height_m)
    y += fmt::format("  fit: {{height: {}}}   # {}\n", length_text(*c.height_m), c.size_why);
  else
    y += "  # " + c.size_why + "\n";
  if (c.speckle) {
    y += "  # The model has no colours or texture: a speckle stands for the real object's (SfM "
         "needs\n"
         "  # texture); remove it if the object has its own.\n";
    y += "  surface: {pattern: speckle, scale: 2mm, contrast: 0.7, roughness: 0.8}\n";
  }
  y += "studio:\n";
  y += "  turntable: {diameter: 40cm, height: 75cm, color: [0.05, 0.05, 0.05]}\n";
  y += "  backdrop: {green_screen: {color: [0.0, 0.69, 0.25]}}   # keyed out by eval's masks\n";
  y += "  lights:\n";
  y += "    # Two 50 cm softboxes either side behind the camera, as far again as the camera.\n";
  const double side = 0.78 * c.distance_m, back = -1.44 * c.distance_m;
  const double up = 0.75 + c.camera_height_m + 0.45 * c.distance_m;
  for (const double x : {side, -side}) {
    y += fmt::format(
        "    - {{type: area, position: [{:.3f}m, {:.3f}m, {:.3f}m], size: [50cm, 50cm], power: "
        "{:.0f}W, temperature: 5500K}}\n",
        x, back, up, c.light_power_w);
  }
  y += "  ambient: 20lx\n";
  y += "camera:\n";
  y += comment(c.distance_why, 2);
  y += fmt::format("  body: {}\n", c.body);
  y += fmt::format("  lens: {{focal_length: {:.0f}mm}}\n", 1000 * c.focal_length_m);
  y += comment(c.aperture_why, 2);
  y += comment(c.exposure_why, 2);
  y += fmt::format("  exposure: {{aperture: f/{:g}, shutter: {}, iso: {:g}}}\n", c.f_number,
                   shutter_text(c.shutter_s), c.iso);
  y += "  focus: auto   # at the object's centre\n";
  y += "  white_balance: 5500K\n";
  if (!c.shots.empty()) return y + c.shots;
  y += "shots:\n";
  y += fmt::format(
      "  - turntable: {{steps: {}, step: {:g}deg, camera: {{distance: {}, height: {}}}}}\n",
      kDraftSteps, 360.0 / kDraftSteps, length_text(c.distance_m), length_text(c.camera_height_m));
  return y;
}

// The smallest third-stop f-number that keeps the object's depth (`radius_m` either side of the
// focus at `distance_m`) within the circle of confusion, from f/4; f/22 when none does.
double aperture_for_depth(const ir::Camera& camera, double distance_m, double radius_m) {
  for (const double n : dslr::kFNumberStops) {
    if (n < 4) continue;
    const double near = dslr::coc_diameter_m(camera.focal_length_m, n, distance_m,
                                             std::max(distance_m - radius_m, 1e-3));
    const double far =
        dslr::coc_diameter_m(camera.focal_length_m, n, distance_m, distance_m + radius_m);
    if (std::max(near, far) <= camera.circle_of_confusion_m || n >= 22) return n;
  }
  return 22;
}

bool is_textured(const ir::Scene& scene) {
  if (!scene.object.mesh.colors.empty()) return true;
  return std::any_of(scene.materials.begin(), scene.materials.end(),
                     [](const ir::Material& m) { return m.base_color_texture >= 0; });
}

// Places the camera and sets the aperture for the object `scene` holds.
void frame_the_object(const ir::Scene& scene, Choices& c) {
  const ir::Vec3 size = scene.object.bounds_max_object - scene.object.bounds_min_object;
  const ir::Camera& camera = scene.camera;
  const double across = std::hypot(size.x(), size.y());  // its widest as the table turns
  const double by_height = camera.focal_length_m * size.z() / (kFrameFill * camera.sensor_height_m);
  const double by_width = camera.focal_length_m * across / (kFrameFill * camera.sensor_width_m);
  c.distance_m = std::max(by_height, by_width);
  c.camera_height_m = 0.5 * size.z();
  c.distance_why = fmt::format(
      "The camera {} from the table's axis, level with the object's middle: the object ({} x {} "
      "x {}) fills about {:.0f} % of the frame's {}.",
      length_text(c.distance_m), length_text(size.x()), length_text(size.y()),
      length_text(size.z()), 100 * kFrameFill, by_height >= by_width ? "height" : "width");
  c.f_number = aperture_for_depth(camera, c.distance_m, 0.5 * across);
  c.aperture_why = fmt::format(
      "f/{:g}: the smallest aperture from f/4 whose depth of field holds the object's {} of "
      "depth at {}.",
      c.f_number, length_text(across), length_text(c.distance_m));
}

// `c`'s scene compiled where it will be written. Its diagnostics reach `diag` only when it does
// not compile: a draft's warnings are the draft's.
std::optional<ir::Scene> compile_draft(const Choices& c, const StarterOptions& o,
                                       DiagnosticEngine& diag) {
  const std::string folder = fs::absolute(o.output_path).parent_path().string();
  DiagnosticEngine quiet;
  quiet.set_handler([](const Diagnostic&, const std::string&) {});
  auto scene = compile_scene_text(scene_text(c), o.output_path, folder, quiet);
  if (!scene) compile_scene_text(scene_text(c), o.output_path, folder, diag);
  return scene;
}

// The value an advice works out for `setting` (0 when it works none out).
double suggested(const std::vector<analysis::Advice>& advice, analysis::Setting setting) {
  for (const auto& a : advice) {
    for (const auto& change : a.changes) {
      if (change.setting == setting && change.value > 0) return change.value;
    }
  }
  return 0;
}

// Applies check's advice on the aperture, the ISO (from 100 to 3200) and then the light, until
// it has none; says what it did in `c.exposure_why`.
bool settle_exposure(const StarterOptions& o, Choices& c, DiagnosticEngine& diag,
                     std::string* error) {
  if (c.exposure_why.empty()) {
    c.exposure_why = "The exposure: `rigc check` gives no advice on it for these lights.";
  }
  for (int round = 0; round < kAdviceRounds; ++round) {
    const auto scene = compile_draft(c, o, diag);
    if (!scene) {
      *error = "the starting scene does not compile";
      return false;
    }
    const auto advice = analysis::check_advice(*scene);
    const double iso = suggested(advice, analysis::Setting::kIso);
    const double light = suggested(advice, analysis::Setting::kLight);
    const double aperture = suggested(advice, analysis::Setting::kFNumber);
    if (aperture > 0 && aperture != c.f_number) {
      c.f_number = aperture;
    } else if (iso >= 100 && iso <= 3200 && iso != c.iso) {
      // The dial's stop at or above the advice's value: the side of more light.
      c.iso = *std::find_if(std::begin(dslr::kIsoStops), std::end(dslr::kIsoStops) - 1,
                            [&](double stop) { return stop >= iso * 0.999; });
    } else if (light > 0 && std::abs(light - 1) > 0.05) {
      c.light_power_w = std::clamp(c.light_power_w * light, 5.0, 1000.0);
    } else {
      return true;
    }
    c.exposure_why = fmt::format(
        "f/{:g}, {}, ISO {:g} and {:.0f} W softboxes: `rigc check`'s exposure advice, applied.",
        c.f_number, shutter_text(c.shutter_s), c.iso, c.light_power_w);
  }
  return true;
}

}  // namespace

std::optional<std::string> starter_scene_text(const StarterOptions& o, DiagnosticEngine& diag,
                                              std::ostream& log, std::string* error) {
  Choices c;
  const fs::path folder = fs::absolute(o.output_path).parent_path();
  std::error_code ec;
  const fs::path relative = fs::relative(fs::absolute(o.model_path), folder, ec);
  // Relative when the model is in the scene's folder or below it, as a project keeps them.
  const bool below = !ec && !relative.empty() && *relative.begin() != "..";
  c.model = below ? relative.string() : fs::absolute(o.model_path).lexically_normal().string();
  c.body = o.body;
  c.focal_length_m = o.focal_length_m;
  c.height_m = o.height_m;
  c.size_why = o.height_m ? "as given (--height)" : "the model file's own size, in metres";

  // The object as the file gives it, in a first draft.
  const auto draft = compile_draft(c, o, diag);
  if (!draft) {
    *error = "the starting scene does not compile (its diagnostics above)";
    return std::nullopt;
  }
  const ir::Vec3 size = draft->object.bounds_max_object - draft->object.bounds_min_object;
  if (!o.height_m && (size.maxCoeff() < 0.01 || size.maxCoeff() > 3)) {
    *error = fmt::format(
        "{} is {:.3g} units across: not a plausible object in metres; give its height "
        "(--height 25cm)",
        o.model_path, size.maxCoeff());
    return std::nullopt;
  }
  c.speckle = !is_textured(*draft);
  frame_the_object(*draft, c);
  if (!settle_exposure(o, c, diag, error)) return std::nullopt;
  log << fmt::format("rigc new: {}\n  {}\n  {}\n  {}\n", o.model_path, c.distance_why,
                     c.aperture_why, c.exposure_why);

  // The planner's shots for the target, in place of the draft's ring.
  PlanRequest request;
  request.scene_path = o.output_path;
  request.scene_text = scene_text(c);
  request.output_path = o.output_path;
  request.target = o.target;
  request.visibility_scale = o.visibility_scale;
  // The planner's rings and one below the table's top, for what faces down.
  request.candidates.ring_elevations_rad.push_back(-10 * kDegree);
  for (const double deg : kDefaultRingsDeg) {
    request.candidates.ring_elevations_rad.push_back(deg * kDegree);
  }
  std::string plan_error;
  const auto outcome = plan_scene(request, diag, &plan_error);
  if (!outcome) {
    *error = plan_error.empty() ? "the starting scene could not be planned" : plan_error;
    return std::nullopt;
  }
  if (!outcome->plan.target_reached) {
    log << fmt::format(
        "  the plan reaches {:.1f} %, short of {:.0f} %: `rigc plan` says what stays unseen\n",
        100 * outcome->plan.reconstructable, 100 * o.target);
  }
  log << fmt::format("  {} shots from the planner make {:.1f} % of the surface reconstructable\n",
                     outcome->plan.shots.size(), 100 * outcome->plan.reconstructable);
  // The planned views see the object from above and below as well: the advice once more.
  c.shots = planned_shots_text(*outcome);
  if (!settle_exposure(o, c, diag, error)) return std::nullopt;
  log << "  " << c.exposure_why << "\n";
  return scene_text(c);
}

}  // namespace rigc::plan
