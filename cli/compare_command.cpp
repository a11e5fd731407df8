// The `rigc compare` verb: renders a scene with several backends from the registry, evaluates
// each run (and real photos, if given), and writes the fast-versus-reference table.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>

#include "backends/registry.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/frontend.h"
#include "eval/eval.h"
#include "io/atomic_file.h"
#include "run/manifest.h"
#include "run/run_loop.h"

namespace rigc::cli {

namespace {

namespace fs = std::filesystem;
using eval::EvalOptions;
using eval::EvalSummary;

// One row of the table: a backend's run, or the photos.
struct Row {
  std::string name;
  int render_status = 0, eval_status = 0;
  double render_s = 0;
  EvalSummary summary;
  fs::path run_dir;
};

// The registry entries `--backends` names, in its order. Null after an error on standard error.
std::optional<std::vector<const backends::BackendEntry*>> chosen_backends(const std::string& list) {
  std::vector<const backends::BackendEntry*> chosen;
  std::stringstream names(list);
  std::string name;
  while (std::getline(names, name, ',')) {
    if (name.empty()) continue;
    const backends::BackendEntry* entry = backends::find_backend(name);
    if (!entry) {
      std::string known;
      for (const auto& b : backends::backend_names()) known += (known.empty() ? "" : ", ") + b;
      std::cerr << fmt::format("rigc compare: error: unknown backend '{}' (available: {})\n", name,
                               known);
      return std::nullopt;
    }
    // Twice the same backend would render and evaluate twice into one folder.
    if (std::find(chosen.begin(), chosen.end(), entry) != chosen.end()) {
      std::cerr << fmt::format("rigc compare: error: --backends names '{}' twice\n", name);
      return std::nullopt;
    }
    chosen.push_back(entry);
  }
  return chosen;
}

// Sum of the manifest's per-shot render times (seconds): the cost of the images even when a
// rerun reused them.
double manifest_render_seconds(const fs::path& run_dir) {
  const auto manifest = run::Manifest::load(run_dir / "manifest.json");
  double ms = 0;
  for (const auto& [name, shot] : manifest.shots()) ms += shot.render_ms;
  return ms / 1000;
}

Row render_and_evaluate(const ir::Scene& scene, const std::string& scene_path,
                        const backends::BackendEntry& entry, const fs::path& out, double scale,
                        const EvalOptions& base) {
  Row row;
  row.name = entry.name;
  row.run_dir = out / entry.name;
  std::cerr << fmt::format("rigc compare: rendering with {} ...\n", entry.name);
  run::RunOptions options;
  options.output_dir = row.run_dir;
  options.settings.scale = scale;
  const std::unique_ptr<run::Backend> backend = entry.make();
  row.render_status = run::run_backend(scene, *backend, options, std::cerr);
  row.render_s = manifest_render_seconds(row.run_dir);
  if (row.render_status == 0) {
    EvalOptions o = base;
    o.run_dir = row.run_dir.string();
    o.masks_dir.clear();  // the photos' options
    o.camera.clear();
    o.scene = scene_path;
    o.output_dir = (row.run_dir / "eval").string();
    row.eval_status = eval::evaluate(o, std::cerr, &row.summary);
  }
  return row;
}

Row evaluate_photos(const std::string& photos, const std::string& scene_path, const fs::path& out,
                    const EvalOptions& base) {
  Row row;
  row.name = "photos";
  row.run_dir = photos;
  EvalOptions o = base;
  o.photos_dir = photos;
  o.scene = scene_path;
  o.output_dir = (out / "photos_eval").string();
  row.eval_status = eval::evaluate(o, std::cerr, &row.summary);
  return row;
}

std::string results_table(const std::vector<Row>& rows, double tau_mm) {
  std::string table = fmt::format(
      "| source | images | render (s) | registered | points | signed distance mean ± std (mm) "
      "| F-score (τ = {} mm) | COLMAP (s) |\n|---|---|---|---|---|---|---|---|\n",
      tau_mm);
  for (const Row& r : rows) {
    const EvalSummary& s = r.summary;
    if (r.render_status != 0) {
      table +=
          fmt::format("| {} | render failed (exit {}) | | | | | | |\n", r.name, r.render_status);
    } else if (!s.reconstructed || s.report.is_null() || !s.report.contains("signed_distance_mm")) {
      table += fmt::format("| {} | {} | {:.1f} | {} | {} | failed: {} | | {:.1f} |\n", r.name,
                           s.images, r.render_s, s.registered, s.points, s.failure, s.colmap_s);
    } else {
      table +=
          fmt::format("| {} | {} | {:.1f} | {}/{} | {} | {:+.3f} ± {:.3f} | {:.3f} | {:.1f} |\n",
                      r.name, s.images, r.render_s, s.registered, s.images, s.points, s.mean_mm,
                      s.std_mm, s.fscore, s.colmap_s);
    }
  }
  return table;
}

std::string first_image(const fs::path& run_dir) {
  std::error_code ec;
  const fs::path images = run_dir / "images";
  if (!fs::is_directory(images, ec)) return "";
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(images, ec)) names.push_back(e.path().string());
  return names.empty() ? "" : *std::min_element(names.begin(), names.end());
}

// A row of pictures, one column per source ("" leaves the cell empty).
std::string picture_row(const std::string& title, const std::vector<std::string>& paths,
                        const std::vector<Row>& rows, const fs::path& out, bool alt_names) {
  std::string md = "\n| " + title + " |";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::error_code ec;
    md += paths[i].empty() ? " |"
                           : fmt::format(" ![{}]({}) |", alt_names ? rows[i].name : "",
                                         fs::relative(paths[i], out, ec).string());
  }
  return md;
}

std::string compare_markdown(const ir::Scene& scene, const std::string& scene_path, double scale,
                             const EvalOptions& base, const std::vector<Row>& rows,
                             const std::string& table, const fs::path& out) {
  std::string md = fmt::format("# {}: reconstruction accuracy by renderer\n\n", scene.name);
  md += fmt::format(
      "Scene `{}`, render scale {}, COLMAP {} (CPU). Signed distance: reconstructed "
      "points to the scene's mesh in the object frame, after a similarity "
      "alignment on the camera centres and ICP.\n\n",
      scene_path, scale, base.poisson ? "+ Poisson meshing" : "sparse points");
  md += table;
  md +=
      "\nThe paper's Table 1 for reference (Photoscan + CloudCompare, full resolution): real "
      "DSLR -0.38 ± 2.41 mm, Maya + V-Ray -0.43 ± 2.50 mm, Unity -0.49 ± 3.51 mm.\n\n";
  md += "| |";
  for (const Row& r : rows) md += " " + r.name + " |";
  md += "\n|---|";
  for (std::size_t i = 0; i < rows.size(); ++i) md += "---|";
  std::vector<std::string> firsts, heatmaps, histograms;
  for (const Row& r : rows) {
    firsts.push_back(first_image(r.run_dir));
    heatmaps.push_back(r.summary.heatmap_png);
    histograms.push_back(r.summary.histogram_png);
  }
  md += picture_row("first image", firsts, rows, out, true);
  md += picture_row("heat map", heatmaps, rows, out, false);
  md += picture_row("histogram", histograms, rows, out, false);
  return md + "\n";
}

}  // namespace

int run_compare_command(std::vector<std::string> args) {
  CLI::App app{
      "Render a scene with several backends, evaluate each reconstruction against the scene's "
      "mesh, and print the paper's Table 1 extended (compare.md has the pictures)."};
  std::string scene_path, backends_text = "preview", output, photos;
  double scale = 0.25;
  EvalOptions base;
  app.add_option("scene", scene_path, "scene file (.yaml)")->required();
  app.add_option("--backends", backends_text, "comma-separated renderers")->capture_default_str();
  app.add_option("--photos", photos, "real photos of the same object, evaluated as one more row");
  app.add_option("--scale", scale, "render scale")
      ->check(finite_number())
      ->check(CLI::Range(0.01, 4.0))
      ->capture_default_str();
  app.add_option("-o,--output", output, "output folder (default: out/<scene>/compare)");
  add_eval_options(app, base);
  if (auto code = parse_options(app, args)) return *code;

  DiagnosticEngine diag;
  auto scene = compile_scene_file(scene_path, diag);
  if (!scene) return 1;
  const auto chosen = chosen_backends(backends_text);
  if (!chosen) return 1;
  if (chosen->empty() && photos.empty()) {
    std::cerr << "rigc compare: error: no backend to compare (--backends preview,...)\n";
    return 1;
  }
  const fs::path out =
      output.empty() ? fs::path("out") / scene->name / "compare" : fs::path(output);
  std::error_code ec;
  fs::create_directories(out, ec);

  std::vector<Row> rows;
  for (const backends::BackendEntry* entry : *chosen) {
    rows.push_back(render_and_evaluate(*scene, scene_path, *entry, out, scale, base));
  }
  if (!photos.empty()) rows.push_back(evaluate_photos(photos, scene_path, out, base));
  int worst = 0;
  for (const Row& r : rows) worst = std::max({worst, r.render_status, r.eval_status});

  const std::string table = results_table(rows, base.tau_mm);
  std::cout << table;
  const std::string md = compare_markdown(*scene, scene_path, scale, base, rows, table, out);
  std::string error;
  if (!rigc::write_file_atomically(out / "compare.md", md, &error)) {
    std::cerr << "rigc compare: error: " << error << "\n";
    return 2;
  }
  std::cerr << fmt::format("rigc compare: wrote {}\n", (out / "compare.md").string());
  return worst;
}

}  // namespace rigc::cli
