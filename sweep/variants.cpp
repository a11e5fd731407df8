#include "sweep/variants.h"

#include <fmt/format.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "compiler/frontend.h"
#include "compiler/scene_text.h"
#include "io/atomic_file.h"
#include "io/files.h"
#include "run/manifest.h"
#include "run/scene_inputs.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMostVariants = 1000;

// The axes in grid order: each zip group once, every other axis alone.
std::vector<std::vector<int>> grid_groups(const SweepSpec& spec) {
  std::vector<std::vector<int>> groups;
  std::set<int> zipped;
  for (const auto& group : spec.zip_groups) zipped.insert(group.begin(), group.end());
  std::set<int> placed;
  for (int a = 0; a < static_cast<int>(spec.axes.size()); ++a) {
    if (placed.count(a)) continue;
    if (!zipped.count(a)) {
      groups.push_back({a});
      placed.insert(a);
      continue;
    }
    for (const auto& group : spec.zip_groups) {
      if (std::find(group.begin(), group.end(), a) == group.end()) continue;
      groups.push_back(group);
      placed.insert(group.begin(), group.end());
    }
  }
  return groups;
}

// The axis's name in folder names: the path's last key.
std::string axis_label(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  std::string label = dot == std::string::npos ? path : path.substr(dot + 1);
  const std::size_t bracket = label.find('[');
  return bracket == std::string::npos ? label : label.substr(0, bracket);
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return in ? text.str() : std::string();
}

// An axis's path in the scene (checked when the sweep was read).
ScenePath axis_scene_path(const Axis& axis) {
  std::string ignored;
  return parse_scene_path(axis.path, &ignored).value_or(ScenePath{});
}

// The (path, YAML text) edits that make a variant's scene text; a relative mesh path becomes
// absolute.
std::vector<std::pair<ScenePath, std::string>> variant_edits(const SweepSpec& spec,
                                                             const std::string& scene_text,
                                                             const Variant& variant) {
  const fs::path scene_dir = fs::absolute(fs::path(spec.scene_path)).parent_path();
  const ScenePath mesh_path = {"object", "mesh"};
  std::vector<std::pair<ScenePath, std::string>> edits;
  bool mesh_varied = false;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    if (spec.axes[a].is_backend()) continue;
    std::string value = variant.values[a];
    if (spec.axes[a].path == "object.mesh") {
      mesh_varied = true;
      if (fs::path(value).is_relative()) value = (scene_dir / value).lexically_normal().string();
    }
    edits.emplace_back(axis_scene_path(spec.axes[a]), yaml_scalar_text(value));
  }
  std::string ignored;
  if (const auto mesh = find_value_span(scene_text, mesh_path, &ignored); mesh && !mesh_varied) {
    const std::string written = scene_text.substr(mesh->begin, mesh->end - mesh->begin);
    const std::string unquoted = written.size() > 1 && (written[0] == '"' || written[0] == '\'')
                                     ? written.substr(1, written.size() - 2)
                                     : written;
    if (fs::path(unquoted).is_relative()) {
      edits.emplace_back(mesh_path,
                         yaml_scalar_text((scene_dir / unquoted).lexically_normal().string()));
    }
  }
  return edits;
}

// The scene's text does not hold its mesh and textures: `content_hash` (run::scene_content_hash)
// stands for them, so editing a model file in place reruns the variants that use it.
std::string variant_key(const SweepSpec& spec, const Variant& v, const std::string& content_hash) {
  const nlohmann::json inputs = {{"scene", v.scene_text},   {"content", content_hash},
                                 {"backend", v.backend},    {"scale", spec.scale},
                                 {"samples", spec.samples}, {"coverage", spec.coverage},
                                 {"eval", spec.eval},       {"rigc", RIGC_VERSION}};
  return sha256_hex(inputs.dump());
}

// Reports a variant's compile errors at the axis value responsible (the one on the error's line,
// else the first) and at the scene's line; each (place, message) once.
void report_compile_errors(const SweepSpec& spec, const Variant& variant,
                           const std::vector<Diagnostic>& errors,
                           const std::vector<int>& axis_lines, std::set<std::string>& reported,
                           DiagnosticEngine& diag) {
  for (const Diagnostic& d : errors) {
    if (d.severity != Severity::kError) continue;
    std::size_t axis = spec.axes.size();
    for (std::size_t a = 0; a < spec.axes.size(); ++a) {
      if (spec.axes[a].is_backend()) continue;
      if (axis == spec.axes.size() || axis_lines[a] == d.loc.line) axis = a;
      if (axis_lines[a] == d.loc.line) break;
    }
    if (axis == spec.axes.size()) axis = 0;
    const AxisValue& value = spec.axes[axis].values[variant.value_index[axis]];
    const std::string once =
        fmt::format("{}:{}:{}:{}", value.loc.line, value.loc.col, d.loc.line, d.message);
    if (!reported.insert(once).second) continue;
    diag.error(value.loc, fmt::format("variant '{}' does not compile ({} = {}): {}", variant.name,
                                      spec.axes[axis].path, value.text, d.message));
    diag.note({spec.scene_path, d.loc.line, d.loc.col},
              fmt::format("the scene's line, in variant '{}'", variant.name));
  }
}

}  // namespace

std::vector<Variant> expand_variants(const SweepSpec& spec) {
  const auto groups = grid_groups(spec);
  // The grid's size, saturated past the bound: 2^64 variants overflowed to 0.
  std::size_t total = 1;
  for (const auto& group : groups) {
    const std::size_t n = spec.axes[group[0]].values.size();
    total = n != 0 && total > kMostVariants / n ? kMostVariants + 1 : total * n;
  }
  std::vector<Variant> variants;
  std::set<std::string> names;
  for (std::size_t i = 0; i < total && i < kMostVariants + 1; ++i) {
    Variant v;
    v.value_index.assign(spec.axes.size(), 0);
    v.values.assign(spec.axes.size(), "");
    std::size_t rest = i;
    for (auto g = groups.rbegin(); g != groups.rend(); ++g) {
      const std::size_t n = spec.axes[(*g)[0]].values.size();
      for (const int a : *g) v.value_index[a] = static_cast<int>(rest % n);
      rest /= n;
    }
    std::string name;
    v.backend = spec.backend;
    for (std::size_t a = 0; a < spec.axes.size(); ++a) {
      v.values[a] = spec.axes[a].values[v.value_index[a]].text;
      if (spec.axes[a].is_backend()) v.backend = v.values[a];
      name += (name.empty() ? "" : "_") + axis_label(spec.axes[a].path) + "-" + v.values[a];
    }
    v.name = folder_name(name, 80);
    for (int n = 2; !names.insert(v.name).second; ++n) {
      v.name = folder_name(name, 72) + fmt::format("_{}", n);
    }
    variants.push_back(std::move(v));
  }
  return variants;
}

bool build_variants(const SweepSpec& spec, const std::string& scene_text, const fs::path& out_dir,
                    std::vector<Variant>& variants, DiagnosticEngine& diag) {
  variants = expand_variants(spec);
  if (variants.size() > kMostVariants) {
    diag.error(spec.axes.front().loc,
               fmt::format("the sweep makes more than {} variants", kMostVariants));
    return false;
  }
  std::vector<int> axis_lines(spec.axes.size(), 0);
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    if (spec.axes[a].is_backend()) continue;
    std::string error;
    const auto span = find_value_span(scene_text, axis_scene_path(spec.axes[a]), &error);
    if (span && !span->scalar) {
      error = fmt::format("'{}' is not a single value in the scene (a sweep varies scalars)",
                          spec.axes[a].path);
    }
    if (!span || !span->scalar) {
      diag.error(spec.axes[a].loc, fmt::format("{} (in {})", error, spec.scene_path));
      return false;
    }
    axis_lines[a] = span->line;
  }
  const fs::path base_dir = fs::absolute(fs::path(spec.scene_path)).parent_path();
  diag.add_source(spec.scene_path, scene_text);
  std::set<std::string> reported;
  bool ok = true;
  for (Variant& v : variants) {
    std::string error;
    const auto text = replace_values(scene_text, variant_edits(spec, scene_text, v), &error);
    if (!text) {
      diag.error(spec.axes.front().loc, error);
      return false;
    }
    v.scene_text = *text;
    DiagnosticEngine local;
    std::vector<Diagnostic> errors;
    local.set_handler([&](const Diagnostic& d, const std::string&) { errors.push_back(d); });
    const fs::path variant_scene = out_dir / v.name / "scene.yaml";
    const auto scene =
        compile_scene_text(v.scene_text, variant_scene.string(), base_dir.string(), local);
    if (!scene) {
      ok = false;
      report_compile_errors(spec, v, errors, axis_lines, reported, diag);
      continue;
    }
    v.key = variant_key(spec, v, run::scene_content_hash(*scene));
    run::protect_scene_files(*scene);
  }
  return ok;
}

nlohmann::json sweep_json(const SweepSpec& spec, const std::vector<Variant>& variants) {
  nlohmann::json axes = nlohmann::json::array(), list = nlohmann::json::array();
  for (const Axis& axis : spec.axes) {
    nlohmann::json values = nlohmann::json::array();
    for (const AxisValue& v : axis.values) values.push_back(v.text);
    axes.push_back({{"path", axis.path}, {"values", values}});
  }
  for (const Variant& v : variants) {
    list.push_back(
        {{"name", v.name}, {"values", v.values}, {"backend", v.backend}, {"key", v.key}});
  }
  return {{"rigc-sweep", 1},          {"name", spec.name},
          {"scene", spec.scene_path}, {"scale", spec.scale},
          {"samples", spec.samples},  {"coverage", spec.coverage},
          {"eval", spec.eval},        {"axes", axes},
          {"variants", list}};
}

bool write_variant_folders(const SweepSpec& spec, const std::vector<Variant>& variants,
                           const fs::path& out_dir, std::string* error) {
  // The tables written once the variants have run: refused now (an input in their place), not
  // after hours of renders.
  for (const char* table : {"results.csv", "timings.csv", "results.md", "sweep.json"}) {
    if (file_to_replace(out_dir / table, error).empty()) return false;
  }
  for (const Variant& v : variants) {
    const fs::path dir = out_dir / v.name;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) {
      *error = fmt::format("cannot make {}: {}", dir.string(), ec.message());
      return false;
    }
    nlohmann::json values;
    for (std::size_t a = 0; a < spec.axes.size(); ++a) values[spec.axes[a].path] = v.values[a];
    const std::string variant_text =
        nlohmann::json{{"name", v.name},          {"values", values},
                       {"backend", v.backend},    {"scale", spec.scale},
                       {"samples", spec.samples}, {"coverage", spec.coverage},
                       {"eval", spec.eval},       {"key", v.key}}
            .dump(2) +
        "\n";
    if (read_text(dir / "scene.yaml") != v.scene_text &&
        !write_file_atomically(dir / "scene.yaml", v.scene_text, error)) {
      return false;
    }
    if (read_text(dir / "variant.json") != variant_text &&
        !write_file_atomically(dir / "variant.json", variant_text, error)) {
      return false;
    }
  }
  return write_file_atomically(out_dir / "sweep.json", sweep_json(spec, variants).dump(2) + "\n",
                               error);
}

}  // namespace rigc::sweep
