// The `rigc eval` and `rigc compare` verbs.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <iostream>
#include <sstream>

#include "backends/cycles/cycles_backend.h"
#include "backends/povray/povray_backend.h"
#include "backends/preview/preview_backend.h"
#include "cli/options.h"
#include "cli/verbs.h"
#include "compiler/frontend.h"
#include "eval/eval.h"
#include "io/files.h"
#include "run/manifest.h"
#include "run/shots.h"

namespace rigc::cli {

using eval::EvalOptions;
using eval::EvalSummary;
using eval::evaluate;

namespace fs = std::filesystem;

namespace {

using cli::finite_number;
using cli::parse_options;
using cli::positive_number;

void add_eval_options(CLI::App& app, EvalOptions& o) {
  app.add_option("--colmap", o.colmap, "COLMAP executable")->capture_default_str();
  app.add_option("--matcher", o.matcher,
                 "feature matching: exhaustive, sequential, neighbours (views whose planned "
                 "optical axes are close, from the run's sparse/images.txt), or auto (neighbours "
                 "for a run folder, else exhaustive; sequential above 100 images)")
      ->check(CLI::IsMember({"auto", "exhaustive", "sequential", "neighbours"}))
      ->capture_default_str();
  app.add_option("--neighbour-angle", o.neighbour_angle_deg,
                 "neighbours: the widest angle (deg) between the optical axes of a matched pair")
      ->check(finite_number())
      ->check(CLI::Range(1.0, 180.0))
      ->capture_default_str();
  app.add_flag("!--no-masks", o.use_masks, "ignore the run's masks/ (object masks)");
  app.add_flag("--refine-intrinsics", o.refine_intrinsics,
               "let COLMAP refine the run's known camera (default: keep it fixed)");
  app.add_flag("--reuse-colmap", o.reuse_colmap,
               "reuse the COLMAP model already in the output folder");
  app.add_flag("!--no-icp", o.icp, "skip the ICP refinement after the camera alignment");
  app.add_flag("--poisson", o.poisson,
               "also mesh the points (screened Poisson) and compare the mesh, as the paper did");
  app.add_option("--poisson-depth", o.poisson_depth, "octree depth of the Poisson meshing")
      ->check(CLI::Range(5, 12))
      ->capture_default_str();
  app.add_option("--tau", o.tau_mm, "F-score distance threshold in mm")
      ->check(positive_number())
      ->capture_default_str();
  app.add_option("--samples", o.ground_truth_samples,
                 "ground-truth surface samples before the visibility test")
      ->check(CLI::Range(1000, 20000000))
      ->capture_default_str();
  app.add_option("--color-range", o.color_range_mm,
                 "heat-map range in mm, ± (default: 3 x the RMS distance)")
      ->check(positive_number());
}

// A renderer for `rigc compare`: renders every shot of `scene` into run_dir; returns 0, 1, 2.
struct RenderBackend {
  std::string name;
  std::function<int(const ir::Scene& scene, const std::string& run_dir, double scale,
                    std::ostream& log)>
      render;
};

// Adding a backend to `rigc compare` is one entry here.
const std::vector<RenderBackend>& render_backends() {
  static const std::vector<RenderBackend> table = {
      {"preview",
       [](const ir::Scene& scene, const std::string& run_dir, double scale, std::ostream& log) {
         preview::RenderOptions options;
         options.output_dir = run_dir;
         options.scale = scale;
         return preview::run_preview(scene, options, log);
       }},
      {"povray",
       [](const ir::Scene& scene, const std::string& run_dir, double scale, std::ostream& log) {
         external::ReferenceOptions options;
         options.output_dir = run_dir;
         options.scale = scale;
         return povray::run(scene, options, log);
       }},
      {"cycles",
       [](const ir::Scene& scene, const std::string& run_dir, double scale, std::ostream& log) {
         external::ReferenceOptions options;
         options.output_dir = run_dir;
         options.scale = scale;
         return cycles::run(scene, options, log);
       }},
  };
  return table;
}

// Sum of the manifest's per-shot render times (seconds): the cost of the images even when a
// rerun reused them.
double manifest_render_seconds(const fs::path& run_dir) {
  const auto manifest = run::Manifest::load(run_dir / "manifest.json");
  double ms = 0;
  for (const auto& [name, shot] : manifest.shots()) ms += shot.render_ms;
  return ms / 1000;
}

}  // namespace

int run_eval_command(std::vector<std::string> args) {
  CLI::App app{
      "Reconstruct a run's images with COLMAP (CPU) and measure the result against the ground "
      "truth: signed point-to-mesh distance (mm), F-score, camera errors; eval.json, a coloured "
      "PLY, a histogram and a heat map."};
  EvalOptions o;
  app.add_option("run", o.run_dir, "run folder (images/, sparse/, manifest.json)");
  app.add_option("--photos", o.photos_dir,
                 "a folder of real photos instead (no ground-truth poses: global registration)");
  app.add_option("--ground-truth", o.ground_truth,
                 "ground-truth mesh (glTF, OBJ, PLY, STL; in its own frame; default: the run's "
                 "scene object in the object frame)");
  app.add_option("--scene", o.scene, "scene file for the ground truth (default: the run's)");
  app.add_option("-o,--output", o.output_dir, "output folder (default: RUN/eval)");
  add_eval_options(app, o);
  if (auto code = parse_options(app, args)) return *code;
  if (o.run_dir.empty() == o.photos_dir.empty()) {
    std::cerr << "rigc eval: error: give a run folder or --photos DIR (one of them)\n";
    return 1;
  }
  EvalSummary summary;
  return evaluate(o, std::cerr, &summary);
}

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
  std::vector<const RenderBackend*> chosen;
  {
    std::stringstream s(backends_text);
    std::string name;
    while (std::getline(s, name, ',')) {
      if (name.empty()) continue;
      const RenderBackend* found = nullptr;
      for (const auto& b : render_backends()) {
        if (b.name == name) found = &b;
      }
      if (!found) {
        std::string known;
        for (const auto& b : render_backends()) known += (known.empty() ? "" : ", ") + b.name;
        std::cerr << fmt::format("rigc compare: error: unknown backend '{}' (available: {})\n",
                                 name, known);
        return 1;
      }
      // Twice the same backend rendered and evaluated it twice into one folder.
      if (std::find(chosen.begin(), chosen.end(), found) != chosen.end()) {
        std::cerr << fmt::format("rigc compare: error: --backends names '{}' twice\n", name);
        return 1;
      }
      chosen.push_back(found);
    }
  }
  if (chosen.empty() && photos.empty()) {
    std::cerr << "rigc compare: error: no backend to compare (--backends preview,...)\n";
    return 1;
  }
  const fs::path out =
      output.empty() ? fs::path("out") / scene->name / "compare" : fs::path(output);
  std::error_code ec;
  fs::create_directories(out, ec);

  struct Row {
    std::string name;
    int render_status = 0, eval_status = 0;
    double render_s = 0;
    EvalSummary summary;
    fs::path run_dir;
  };
  std::vector<Row> rows;
  int worst = 0;
  for (const RenderBackend* b : chosen) {
    Row row;
    row.name = b->name;
    row.run_dir = out / b->name;
    std::cerr << fmt::format("rigc compare: rendering with {} ...\n", b->name);
    row.render_status = b->render(*scene, row.run_dir.string(), scale, std::cerr);
    row.render_s = manifest_render_seconds(row.run_dir);
    if (row.render_status == 0) {
      EvalOptions o = base;
      o.run_dir = row.run_dir.string();
      o.scene = scene_path;
      o.output_dir = (row.run_dir / "eval").string();
      row.eval_status = evaluate(o, std::cerr, &row.summary);
    }
    worst = std::max({worst, row.render_status, row.eval_status});
    rows.push_back(std::move(row));
  }
  if (!photos.empty()) {
    Row row;
    row.name = "photos";
    row.run_dir = photos;
    EvalOptions o = base;
    o.photos_dir = photos;
    o.scene = scene_path;
    o.output_dir = (out / "photos_eval").string();
    row.eval_status = evaluate(o, std::cerr, &row.summary);
    worst = std::max(worst, row.eval_status);
    rows.push_back(std::move(row));
  }

  // The table, on standard output and in compare.md.
  std::string table = fmt::format(
      "| source | images | render (s) | registered | points | signed distance mean ± std (mm) "
      "| F-score (τ = {} mm) | COLMAP (s) |\n|---|---|---|---|---|---|---|---|\n",
      base.tau_mm);
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
  std::cout << table;
  std::string md = fmt::format("# {}: reconstruction accuracy by renderer\n\n", scene->name);
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
  auto rel = [&](const std::string& p) { return fs::relative(p, out, ec).string(); };
  md += "\n| first image |";
  for (const Row& r : rows) {
    std::string first;
    const fs::path images = r.run_dir / "images";
    if (fs::is_directory(images, ec)) {
      std::vector<std::string> names;
      for (const auto& e : fs::directory_iterator(images, ec)) names.push_back(e.path().string());
      std::sort(names.begin(), names.end());
      if (!names.empty()) first = names.front();
    }
    md += first.empty() ? " |" : fmt::format(" ![{}]({}) |", r.name, rel(first));
  }
  md += "\n| heat map |";
  for (const Row& r : rows) {
    md += r.summary.heatmap_png.empty() ? " |"
                                        : fmt::format(" ![]({}) |", rel(r.summary.heatmap_png));
  }
  md += "\n| histogram |";
  for (const Row& r : rows) {
    md += r.summary.histogram_png.empty() ? " |"
                                          : fmt::format(" ![]({}) |", rel(r.summary.histogram_png));
  }
  md += "\n";
  std::string error;
  if (!rigc::write_file_atomically(out / "compare.md", md, &error)) {
    std::cerr << "rigc compare: error: " << error << "\n";
    return 2;
  }
  std::cerr << fmt::format("rigc compare: wrote {}\n", (out / "compare.md").string());
  return worst;
}

}  // namespace rigc::cli
