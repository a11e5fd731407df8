// The front end's entry points: read a scene file, parse and check it, lower it to the IR.
#include "compiler/frontend.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <tuple>

#include "compiler/check.h"
#include "compiler/limits.h"
#include "io/bounded_file.h"

namespace rigc {

namespace fs = std::filesystem;

std::optional<ir::Scene> compile_scene_text(const std::string& text, const std::string& file,
                                            const std::string& base_dir, DiagnosticEngine& diag) {
  diag.add_source(file, text);
  // Checking walks the tree section by section; its diagnostics are reported in file order.
  DiagnosticEngine checking;
  checking.set_handler([](const Diagnostic&, const std::string&) {});
  std::optional<spec::SceneSpec> checked;
  if (auto root = parse_yaml(text, file, checking)) {
    checked = check_scene(*root, file, base_dir, checking);
  }
  std::vector<Diagnostic> found = checking.diagnostics();
  std::stable_sort(found.begin(), found.end(), [](const Diagnostic& a, const Diagnostic& b) {
    return std::tie(a.loc.line, a.loc.col) < std::tie(b.loc.line, b.loc.col);
  });
  for (auto& d : found) diag.report(std::move(d));
  if (!checked || checking.has_errors()) return std::nullopt;
  return lower_scene(*checked, diag);
}

std::optional<std::string> read_scene_file(const std::string& path, DiagnosticEngine& diag) {
  std::string why;
  auto file = read_bounded_file(path, limits::kMostSceneFileBytes, &why);
  if (!file) {
    diag.error({path, 0, 0},
               why.starts_with("is larger")
                   ? fmt::format("the scene file {} (a scene is text; meshes and textures are "
                                 "files of their own)",
                                 why)
                   : fmt::format("cannot read the scene file: it {}", why));
    return std::nullopt;
  }
  return std::move(file->bytes);
}

std::optional<ir::Scene> compile_scene_file(const std::string& path, DiagnosticEngine& diag) {
  const auto text = read_scene_file(path, diag);
  if (!text) return std::nullopt;
  std::string base_dir = fs::path(path).parent_path().string();
  if (base_dir.empty()) base_dir.push_back('.');  // (GCC 12 warns, falsely, on = ".")
  return compile_scene_text(*text, path, base_dir, diag);
}

}  // namespace rigc
