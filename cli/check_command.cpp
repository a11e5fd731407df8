#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <iostream>
#include <nlohmann/json.hpp>

#include "analysis/advice.h"
#include "cli/commands.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/frontend.h"
#include "compiler/units.h"
#include "dslr/lens.h"
#include "ir/ir_json.h"

namespace rigc::cli {
namespace {

// Each diagnostic as JSON; those from first_advice on are advice[i - first_advice], with the
// settings it suggests changing and the values it works out.
nlohmann::json diagnostics_json(const DiagnosticEngine& diag,
                                const std::vector<analysis::Advice>& advice,
                                std::size_t first_advice) {
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t i = 0; i < diag.diagnostics().size(); ++i) {
    const Diagnostic& d = diag.diagnostics()[i];
    const char* severity = d.severity == Severity::kError     ? "error"
                           : d.severity == Severity::kWarning ? "warning"
                                                              : "note";
    nlohmann::json entry{{"severity", severity},
                         {"file", d.loc.file},
                         {"line", d.loc.line},
                         {"col", d.loc.col},
                         {"message", d.message}};
    if (i >= first_advice && i - first_advice < advice.size()) {
      nlohmann::json changes = nlohmann::json::array();
      for (const analysis::SettingChange& c : advice[i - first_advice].changes) {
        nlohmann::json change{{"setting", analysis::setting_name(c.setting)},
                              {"direction", c.direction > 0 ? "up" : "down"}};
        if (c.value > 0) change["value"] = c.value;
        changes.push_back(change);
      }
      entry["suggestions"] = changes;
    }
    out.push_back(entry);
  }
  return out;
}

}  // namespace

int run_check_command(std::vector<std::string> args) {
  CLI::App app{"Check a scene: report every error and capture warning, like a compiler."};
  app.footer(
      "\nExample:\n  rigc check scenes/paper-turntable.yaml            # or --format json for "
      "editors");
  std::string scene_path, format = "text";
  bool json = false;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  bool no_advice = false;
  app.add_option("--format", format,
                 "text (file:line:col: diagnostics and a summary line) or json (the diagnostics "
                 "with file, line, column, severity, message and each advice's suggested "
                 "settings, and the compiled scene)")
      ->check(CLI::IsMember({"text", "json"}));
  app.add_flag("--json", json, "the same as --format json");
  app.add_flag("--no-advice", no_advice, "skip the capture advice (coverage, focus, exposure)");
  double scale = 1;
  app.add_option("--scale", scale,
                 "judge the photos of a render at this scale (`render --scale`): pixels 1/scale "
                 "as wide, so blur in pixels and resolution on the surface are theirs")
      ->check(finite_number())
      ->check(CLI::Range(0.01, 4.0))
      ->capture_default_str();
  if (auto code = parse_options(app, args)) return *code;
  json = json || format == "json";

  DiagnosticEngine diag;
  if (json) diag.set_handler([](const Diagnostic&, const std::string&) {});
  auto scene = compile_scene_file(scene_path, diag);
  std::vector<analysis::Advice> advice;
  const std::size_t first_advice = diag.diagnostics().size();
  if (scene && scale != 1) scene->camera = dslr::camera_at_scale(scene->camera, scale);
  if (scene && !no_advice) {
    advice = analysis::check_advice(*scene);
    for (const analysis::Advice& a : advice) diag.warning(a.loc, a.message);
  }
  if (json) {
    nlohmann::json out{{"ok", scene.has_value()},
                       {"diagnostics", diagnostics_json(diag, advice, first_advice)}};
    if (scene) out["scene"] = ir_to_json(*scene, false);
    std::cout << out.dump(2) << '\n';
    return scene ? kExitOk : kExitUserError;
  }
  if (!scene) {
    std::cerr << fmt::format("{} error{} in {}\n", diag.error_count(),
                             diag.error_count() == 1 ? "" : "s", scene_path);
    return kExitUserError;
  }
  const ir::Camera& c = scene->camera;
  std::cout << fmt::format(
      "{}: ok: '{}', {} shots, object {} ({} triangles, {:.1f} x {:.1f} x {:.1f} cm), {} "
      "{:.0f}mm {} {} ISO {:.0f}, {} lights, {} warning{}\n",
      scene_path, scene->name, scene->shots.size(), scene->object.source,
      scene->object.mesh.triangles.size(),
      100 * (scene->object.bounds_max_object.x() - scene->object.bounds_min_object.x()),
      100 * (scene->object.bounds_max_object.y() - scene->object.bounds_min_object.y()),
      100 * (scene->object.bounds_max_object.z() - scene->object.bounds_min_object.z()),
      c.model.rfind(c.make, 0) == 0 ? c.model : c.make + " " + c.model, c.focal_length_m * 1000,
      format_quantity(c.aperture_f_number, QuantityKind::kFNumber),
      format_quantity(c.shutter_s, QuantityKind::kTime), c.iso, scene->studio.lights.size(),
      diag.warning_count(), diag.warning_count() == 1 ? "" : "s");
  return kExitOk;
}

int run_version_command(std::vector<std::string> args) {
  CLI::App app{"Print the version of rigc and of the scene language."};
  app.footer("\nExample:\n  rigc version");
  if (auto code = parse_options(app, args)) return *code;
  std::cout << fmt::format("rigc {} (scene language 1, IR 1)\n", RIGC_VERSION);
  return kExitOk;
}

}  // namespace rigc::cli
