// The `rigc compare` verb: renders a scene with several backends from the registry, evaluates
// each run (and real photos, if given), and writes the fast-versus-reference table.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
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
#include "run/scene_inputs.h"

namespace rigc::cli {

namespace {

namespace fs = std::filesystem;
using eval::EvalOptions;
using eval::EvalSummary;

// One row of the table: a backend's run, the photos, or another tool's reconstruction.
struct Row {
  std::string name;
  int render_status = 0, eval_status = 0;
  double render_s = 0;
  EvalSummary summary;
  fs::path run_dir;
  bool reconstruction = false;  // measured from a file: no render, no COLMAP
};

// A --reconstruction NAME=FILE, with its --reconstruction-cameras NAME=FILE when given.
struct ReconstructionArg {
  std::string name, file, cameras;
};

// Splits the NAME=FILE options; nullopt after an error on standard error.
std::optional<std::vector<ReconstructionArg>> reconstruction_args(
    const std::vector<std::string>& files, const std::vector<std::string>& cameras) {
  std::vector<ReconstructionArg> args;
  auto split = [](const std::string& text, const char* option, std::string* name,
                  std::string* value) {
    const auto eq = text.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
      std::cerr << fmt::format("rigc compare: error: {} '{}' is not NAME=FILE\n", option, text);
      return false;
    }
    *name = text.substr(0, eq);
    *value = text.substr(eq + 1);
    return true;
  };
  for (const auto& text : files) {
    ReconstructionArg a;
    if (!split(text, "--reconstruction", &a.name, &a.file)) return std::nullopt;
    // The name names the output folder NAME_eval and a column: no path, no markdown.
    const bool plain =
        a.name.front() != '.' && std::all_of(a.name.begin(), a.name.end(), [](char c) {
          return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.';
        });
    if (!plain) {
      std::cerr << fmt::format(
          "rigc compare: error: reconstruction name '{}': use letters, digits, '-', '_' and '.'\n",
          a.name);
      return std::nullopt;
    }
    for (const auto& other : args) {
      if (other.name == a.name) {
        std::cerr << fmt::format("rigc compare: error: two reconstructions named '{}'\n", a.name);
        return std::nullopt;
      }
    }
    args.push_back(a);
  }
  for (const auto& text : cameras) {
    std::string name, file;
    if (!split(text, "--reconstruction-cameras", &name, &file)) return std::nullopt;
    auto it = std::find_if(args.begin(), args.end(), [&](const auto& a) { return a.name == name; });
    if (it == args.end()) {
      std::cerr << fmt::format(
          "rigc compare: error: --reconstruction-cameras names '{}', which no --reconstruction "
          "does\n",
          name);
      return std::nullopt;
    }
    it->cameras = file;
  }
  return args;
}

// Another tool's reconstruction, measured against the scene with the run in `run_dir` (the first
// backend's) as the ground-truth cameras.
Row evaluate_reconstruction(const ReconstructionArg& arg, const fs::path& run_dir,
                            const std::string& scene_path, const fs::path& out,
                            const EvalOptions& base) {
  Row row;
  row.name = arg.name;
  row.run_dir = run_dir;
  row.reconstruction = true;
  EvalOptions o = base;
  o.run_dir = run_dir.string();
  o.scene = scene_path;
  o.imported.reconstruction = arg.file;
  o.imported.cameras = arg.cameras;
  o.output_dir = (out / (arg.name + "_eval")).string();
  std::cerr << fmt::format("rigc compare: measuring {} ({}) ...\n", arg.name, arg.file);
  row.eval_status = eval::evaluate(o, std::cerr, &row.summary);
  return row;
}

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
    o.photos.masks_dir.clear();  // the photos' options
    o.photos.camera.clear();
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
    if (r.reconstruction) {
      const bool measured = s.report.is_object() && s.report.contains("signed_distance_mm");
      table += measured
                   ? fmt::format("| {} | {} | - | {} | {} | {:+.3f} ± {:.3f} | {:.3f} | - |\n",
                                 r.name, s.images,
                                 s.registered ? std::to_string(s.registered) : std::string("-"),
                                 s.points, s.mean_mm, s.std_mm, s.fscore)
                   : fmt::format("| {} | {} | - | | {} | failed: {} | | - |\n", r.name, s.images,
                                 s.points, s.failure);
    } else if (r.render_status != 0) {
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

// (Seven parameters: the parts of the report, each made by the caller.)
std::string compare_markdown(const ir::Scene& scene, const std::string& scene_path, double scale,
                             const EvalOptions& base, const std::vector<Row>& rows,
                             const std::string& table, const fs::path& out) {
  std::string md = fmt::format("# {}: reconstruction accuracy by renderer\n\n", scene.name);
  md += fmt::format(
      "Scene `{}`, render scale {}, COLMAP {} (CPU). Signed distance: reconstructed "
      "points to the scene's mesh in the object frame, after a similarity "
      "alignment on the camera centres and ICP.\n\n",
      scene_path, scale, base.metrics.poisson ? "+ Poisson meshing" : "sparse points");
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
    firsts.push_back(r.reconstruction ? "" : first_image(r.run_dir));
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
  app.footer(
      "\nExample:\n  rigc compare scenes/paper-turntable.yaml --backends preview,cycles --scale "
      "0.25");
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
  std::vector<std::string> reconstruction_files, reconstruction_cameras;
  app.add_option("--reconstruction", reconstruction_files,
                 "NAME=FILE: another tool's point cloud or mesh of the first backend's images, "
                 "measured as one more row (repeatable)");
  app.add_option("--reconstruction-cameras", reconstruction_cameras,
                 "NAME=FILE: that reconstruction's cameras (COLMAP, Bundler, Meshroom); without, "
                 "global registration");
  add_eval_options(app, base);
  if (auto code = parse_options(app, args)) return *code;
  const auto reconstructions = reconstruction_args(reconstruction_files, reconstruction_cameras);
  if (!reconstructions) return 1;

  DiagnosticEngine diag;
  auto scene = compile_scene_file(scene_path, diag);
  if (!scene) return 1;
  run::protect_scene_inputs(scene_path, *scene);
  const auto chosen = chosen_backends(backends_text);
  if (!chosen) return 1;
  if (chosen->empty() && photos.empty()) {
    std::cerr << "rigc compare: error: no backend to compare (--backends preview,...)\n";
    return 1;
  }
  if (chosen->empty() && !reconstructions->empty()) {
    std::cerr << "rigc compare: error: --reconstruction is measured with a backend's run as the "
                 "ground-truth cameras; name one with --backends\n";
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
  for (const ReconstructionArg& arg : *reconstructions) {
    rows.push_back(evaluate_reconstruction(arg, rows.front().run_dir, scene_path, out, base));
  }
  int worst = 0;
  for (const Row& r : rows) worst = std::max({worst, r.render_status, r.eval_status});

  const std::string table = results_table(rows, base.metrics.tau_mm);
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
