#include "sweep/sweep_spec.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <set>
#include <sstream>

#include "backends/registry.h"
#include "compiler/check.h"
#include "compiler/scene_text.h"
#include "io/bounded_file.h"
#include "run/backend.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kMostSweepBytes = 1 << 20;
constexpr std::size_t kMostValuesPerAxis = 1000;

SourceLoc loc_of(const YAML::Node& node, const std::string& file) {
  const YAML::Mark mark = node.Mark();
  if (mark.line < 0) return {file, 0, 0};
  return {file, mark.line + 1, mark.column + 1};
}

// A scalar or a list of scalars as axis values; reports anything else.
std::optional<std::vector<AxisValue>> read_values(const YAML::Node& node, const std::string& file,
                                                  const std::string& what, DiagnosticEngine& diag) {
  std::vector<AxisValue> values;
  if (node.IsScalar()) return std::vector<AxisValue>{{node.Scalar(), loc_of(node, file)}};
  if (!node.IsSequence()) {
    diag.error(loc_of(node, file), fmt::format("{} must be a value or a list of values", what));
    return std::nullopt;
  }
  for (const auto& item : node) {
    if (!item.IsScalar()) {
      diag.error(loc_of(item, file), fmt::format("each value of {} must be a single value", what));
      return std::nullopt;
    }
    values.push_back({item.Scalar(), loc_of(item, file)});
  }
  return values;
}

void read_vary(const YAML::Node& node, const std::string& file, SweepSpec& spec,
               DiagnosticEngine& diag) {
  if (!node.IsMap()) {
    diag.error(loc_of(node, file), "vary: must map scene paths to lists of values");
    return;
  }
  for (auto it = node.begin(); it != node.end(); ++it) {
    Axis axis{it->first.Scalar(), loc_of(it->first, file), {}};
    std::string error;
    if (!parse_scene_path(axis.path, &error)) {
      diag.error(axis.loc, error);
      continue;
    }
    if (auto values = read_values(it->second, file, "'" + axis.path + "'", diag)) {
      axis.values = std::move(*values);
      spec.axes.push_back(std::move(axis));
    }
  }
}

void read_measure(const YAML::Node& node, const std::string& file, SweepSpec& spec,
                  DiagnosticEngine& diag) {
  const auto values = read_values(node, file, "measure:", diag);
  if (!values) return;
  spec.coverage = spec.eval = false;
  for (const AxisValue& v : *values) {
    if (v.text == "coverage") {
      spec.coverage = true;
    } else if (v.text == "eval") {
      spec.eval = true;
    } else {
      diag.error(v.loc, fmt::format("unknown measure '{}' (coverage, eval)", v.text));
    }
  }
}

void read_zip(const YAML::Node& node, const std::string& file, SweepSpec& spec,
              DiagnosticEngine& diag) {
  const auto values = read_values(node, file, "zip:", diag);
  if (!values) return;
  std::vector<int> group;
  for (const AxisValue& v : *values) {
    const auto found = std::find_if(spec.axes.begin(), spec.axes.end(),
                                    [&](const Axis& a) { return a.path == v.text; });
    if (found == spec.axes.end()) {
      diag.error(v.loc, fmt::format("zip: '{}' is not an axis of vary: (or backend)", v.text));
      continue;
    }
    group.push_back(static_cast<int>(found - spec.axes.begin()));
  }
  if (group.size() >= 2) spec.zip_groups.push_back(group);
}

// The node as one number of type T within [low, high], or nullopt.
template <typename T>
std::optional<T> number_within(const YAML::Node& node, T low, T high) {
  T value{};
  std::istringstream in(node.IsScalar() ? node.Scalar() : "");
  if (!(in >> value) || !in.eof() || !(value >= low && value <= high)) return std::nullopt;
  return value;
}

void read_scale(const YAML::Node& node, const std::string& file, SweepSpec& spec,
                DiagnosticEngine& diag) {
  const auto scale = number_within(node, 0.01, 4.0);
  if (!scale) {
    diag.error(loc_of(node, file), "scale: must be a number within 0.01..4");
    return;
  }
  spec.scale = *scale;
}

void read_samples(const YAML::Node& node, const std::string& file, SweepSpec& spec,
                  DiagnosticEngine& diag) {
  const std::optional<int> samples =
      node.IsScalar() ? run::parse_samples(node.Scalar()) : std::nullopt;
  if (!samples || *samples == 0) {
    diag.error(loc_of(node, file), "samples: must be a whole number within 1..65536, or auto");
    return;
  }
  spec.samples = *samples;
}

// The samples every backend of the sweep can take at its scale (the preview's are a square
// grid no finer than the sensor), reported at the samples line.
void check_samples_for_backends(const YAML::Node& node, const std::string& file,
                                const SweepSpec& spec, DiagnosticEngine& diag) {
  std::vector<std::string> names = {spec.backend};
  for (const Axis& axis : spec.axes) {
    if (!axis.is_backend()) continue;
    names.clear();
    for (const auto& value : axis.values) names.push_back(value.text);
  }
  run::RenderSettings settings;
  settings.scale = spec.scale;
  settings.samples = spec.samples;
  for (const std::string& name : names) {
    const backends::BackendEntry* entry = backends::find_backend(name);
    std::string error;
    const std::unique_ptr<run::Backend> backend = entry ? entry->make() : nullptr;
    if (backend && !backend->check_settings(run::settings_for(*backend, settings), &error)) {
      diag.error(loc_of(node, file), fmt::format("samples: {} (backend {})", error, name));
    }
  }
}

void read_top_level(const YAML::Node& root, const std::string& file, SweepSpec& spec,
                    DiagnosticEngine& diag) {
  static const std::vector<std::string> kKeys = {"rigc-sweep", "name",  "scene",   "vary",   "zip",
                                                 "backend",    "scale", "samples", "measure"};
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = it->first.Scalar();
    if (std::find(kKeys.begin(), kKeys.end(), key) == kKeys.end()) {
      const std::string near = closest_match(key, kKeys);
      diag.error(loc_of(it->first, file),
                 fmt::format("unknown key '{}' in the sweep file{}", key,
                             near.empty() ? "" : fmt::format("; did you mean '{}'?", near)));
    }
  }
  if (const YAML::Node n = root["name"]) spec.name = n.IsScalar() ? n.Scalar() : "";
  if (const YAML::Node n = root["vary"]) read_vary(n, file, spec, diag);
  if (const YAML::Node n = root["backend"]) {
    if (auto values = read_values(n, file, "backend:", diag)) {
      if (n.IsSequence()) {
        spec.axes.push_back({"backend", loc_of(n, file), std::move(*values)});
      } else {
        spec.backend = values->front().text;
        if (!backends::find_backend(spec.backend)) {
          diag.error(loc_of(n, file), fmt::format("unknown backend '{}'", spec.backend));
        }
      }
    }
  }
  if (const YAML::Node n = root["zip"]) read_zip(n, file, spec, diag);
  if (const YAML::Node n = root["scale"]) read_scale(n, file, spec, diag);
  if (const YAML::Node n = root["samples"]) {
    read_samples(n, file, spec, diag);
    if (spec.samples != 0) check_samples_for_backends(n, file, spec, diag);
  }
  if (const YAML::Node n = root["measure"]) read_measure(n, file, spec, diag);
}

}  // namespace

std::string folder_name(const std::string& text, std::size_t max_size) {
  std::string name;
  for (const char c : text) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '+' || c == '-' || c == '_';
    if (name.size() < max_size) name += keep ? c : '-';
  }
  if (name.empty() || name == "." || name == "..") name = "_" + name;
  return name;
}

std::optional<SweepSpec> parse_sweep_text(const std::string& text, const std::string& file,
                                          DiagnosticEngine& diag) {
  diag.add_source(file, text);
  const int errors_before = diag.error_count();
  const auto root = parse_yaml(text, file, diag);
  if (!root) return std::nullopt;
  if (!root->IsMap() || !(*root)["rigc-sweep"]) {
    diag.error({file, 1, 1}, "a sweep file starts with `rigc-sweep: 1`");
    return std::nullopt;
  }
  const YAML::Node version = (*root)["rigc-sweep"];
  if (!version.IsScalar() || version.Scalar() != "1") {
    diag.error(loc_of(version, file), "this rigc reads sweep files of version 1 (rigc-sweep: 1)");
    return std::nullopt;
  }
  SweepSpec spec;
  spec.file = file;
  spec.name = fs::path(file).stem().string();
  read_top_level(*root, file, spec, diag);
  const YAML::Node scene = (*root)["scene"];
  if (!scene || !scene.IsScalar() || scene.Scalar().empty()) {
    diag.error({file, 1, 1}, "the sweep file names no scene (scene: path/to/scene.yaml)");
  } else {
    fs::path path = scene.Scalar();
    if (path.is_relative()) path = fs::path(file).parent_path() / path;
    spec.scene_path = path.lexically_normal().string();
  }
  if (spec.axes.empty()) {
    diag.error({file, 1, 1}, "the sweep varies nothing (vary: {path: [values]})");
  }
  check_axes(spec, diag);
  if (diag.error_count() > errors_before) return std::nullopt;
  return spec;
}

std::optional<SweepSpec> read_sweep_file(const std::string& path, DiagnosticEngine& diag) {
  std::string why;
  const auto file = read_bounded_file(path, kMostSweepBytes, &why);
  if (!file) {
    diag.error({path, 0, 0}, "cannot read the sweep file: it " + why);
    return std::nullopt;
  }
  return parse_sweep_text(file->bytes, path, diag);
}

std::optional<Axis> parse_vary_option(const std::string& text, std::string* error) {
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos || equals == 0 || equals + 1 == text.size()) {
    *error = fmt::format("--vary '{}' is not PATH=V1,V2,...", text);
    return std::nullopt;
  }
  Axis axis{text.substr(0, equals), {"--vary", 0, 0}, {}};
  if (!axis.is_backend() && !parse_scene_path(axis.path, error)) return std::nullopt;
  std::stringstream values(text.substr(equals + 1));
  std::string value;
  while (std::getline(values, value, ',')) {
    if (!value.empty()) axis.values.push_back({value, axis.loc});
  }
  return axis;
}

namespace {

// Each value of a zip group's axes taken together (a configuration) is given once.
void check_zipped_tuples(const SweepSpec& spec, const std::vector<int>& group,
                         DiagnosticEngine& diag) {
  std::set<std::vector<std::string>> seen;
  for (std::size_t i = 0; i < spec.axes[group[0]].values.size(); ++i) {
    std::vector<std::string> tuple;
    for (const int a : group) tuple.push_back(spec.axes[a].values[i].text);
    if (seen.insert(tuple).second) continue;
    diag.error(spec.axes[group[0]].values[i].loc,
               fmt::format("the zipped values ({}) are given twice", fmt::join(tuple, ", ")));
  }
}

}  // namespace

bool check_axes(const SweepSpec& spec, DiagnosticEngine& diag) {
  const int errors_before = diag.error_count();
  std::set<int> zipped;
  for (const auto& group : spec.zip_groups) zipped.insert(group.begin(), group.end());
  std::set<std::string> paths;
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    const Axis& axis = spec.axes[a];
    if (!paths.insert(axis.path).second) {
      diag.error(axis.loc, fmt::format("'{}' is varied twice", axis.path));
    }
    if (axis.values.empty() || axis.values.size() > kMostValuesPerAxis) {
      diag.error(axis.loc, fmt::format("'{}' needs 1 to {} values", axis.path, kMostValuesPerAxis));
    }
    std::set<std::string> seen;
    for (const AxisValue& v : axis.values) {
      // A zipped axis may repeat a value (f/13 with 12 and with 36 steps); its tuples may not.
      if (!seen.insert(v.text).second && !zipped.count(static_cast<int>(a))) {
        diag.error(v.loc, fmt::format("'{}' is given twice for '{}'", v.text, axis.path));
      }
      if (axis.is_backend() && !backends::find_backend(v.text)) {
        diag.error(v.loc, fmt::format("unknown backend '{}'", v.text));
      }
    }
  }
  for (const auto& group : spec.zip_groups) {
    bool same_sizes = true;
    for (const int a : group) {
      if (spec.axes[a].values.size() != spec.axes[group[0]].values.size()) {
        same_sizes = false;
        diag.error(spec.axes[a].loc,
                   fmt::format("zipped axes need as many values: '{}' has {}, '{}' has {}",
                               spec.axes[a].path, spec.axes[a].values.size(),
                               spec.axes[group[0]].path, spec.axes[group[0]].values.size()));
      }
    }
    if (same_sizes) check_zipped_tuples(spec, group, diag);
  }
  return diag.error_count() == errors_before;
}

}  // namespace rigc::sweep
