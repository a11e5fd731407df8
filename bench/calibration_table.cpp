// Coverage calibration (measured, not asserted; issue #55): does `coverage`'s reconstructable
// prediction say where a reconstruction has points? For each run folder (a sweep variant: its
// scene.yaml and eval/), the object's surface is cut into patches of PATCH mm cubes (a sparse
// cloud has a point every few mm, so a lone triangle is no unit to observe); a patch is predicted
// when most of its area is reconstructable, and observed when a point of the evaluation's cloud
// within tau of the ground truth falls in it. Prints precision and recall of the prediction and
// the reliability table: patches by their mean usable views against the share observed.
// Usage: calibration_table [--patch MM] RUN_DIR ...
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/coverage.h"
#include "compiler/frontend.h"
#include "eval/geometry.h"
#include "eval/reconstruction.h"
#include "scene/studio_scene.h"

namespace {

namespace fs = std::filesystem;
using Cell = std::array<long, 3>;

struct Patch {
  double area = 0, reconstructable_area = 0, usable_views_area = 0;
  bool observed = false;
};

Cell cell_of(const Eigen::Vector3d& p, double size) {
  return {std::lround(std::floor(p.x() / size)), std::lround(std::floor(p.y() / size)),
          std::lround(std::floor(p.z() / size))};
}

// The patches of one run: the prediction from a coverage of its scene, the observation from its
// evaluation's cloud. Empty with `error` set when something cannot be read.
std::map<Cell, Patch> patches_of(const fs::path& run, double patch_m, std::string* error) {
  rigc::DiagnosticEngine diag;
  diag.set_handler([](const rigc::Diagnostic&, const std::string&) {});
  const auto scene = rigc::compile_scene_file((run / "scene.yaml").string(), diag);
  if (!scene) {
    *error = "its scene.yaml does not compile";
    return {};
  }
  const rigc::scene::StudioScene studio = rigc::scene::prepare_studio_scene(*scene);
  const rigc::analysis::CoverageResult coverage = rigc::analysis::analyse_coverage(*scene, studio);
  const auto& mesh = studio.object;
  std::map<Cell, Patch> patches;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (coverage.resting[f]) continue;  // on the table: no camera can see it
    Eigen::Vector3d center = Eigen::Vector3d::Zero();
    for (const std::uint32_t v : mesh.triangles[f]) center += mesh.positions[v].cast<double>() / 3;
    Patch& patch = patches[cell_of(center, patch_m)];
    const double area = coverage.face_area_m2[f];
    patch.area += area;
    patch.reconstructable_area += coverage.reconstructable[f] ? area : 0;
    patch.usable_views_area += coverage.usable_views[f] * area;
  }
  std::ifstream eval_json(run / "eval" / "eval.json");
  const nlohmann::json report = nlohmann::json::parse(eval_json, nullptr, false);
  const bool has_fscore =
      report.is_object() && report.contains("fscore") && report["fscore"].is_object();
  const double tau_m = has_fscore ? report["fscore"].value("tau_mm", 1.0) / 1000 : 1e-3;
  const auto cloud =
      rigc::eval::load_reconstruction(run / "eval" / "cloud_signed_distance.ply", error);
  if (!cloud) return {};
  const rigc::eval::Surface truth(mesh.positions, mesh.triangles);
  const std::vector<double> distance = truth.signed_distance(cloud->points);
  for (std::size_t i = 0; i < cloud->points.size(); ++i) {
    if (!(std::abs(distance[i]) <= tau_m)) continue;
    const auto found = patches.find(cell_of(cloud->points[i], patch_m));
    if (found != patches.end()) found->second.observed = true;
  }
  return patches;
}

// "sweep/variant": the run folder with its parent's name.
std::string run_name(const fs::path& run) {
  return (run.parent_path().filename() / run.filename()).string();
}

}  // namespace

int main(int argc, char** argv) {
  double patch_mm = 10;
  std::vector<fs::path> runs;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--patch" && i + 1 < argc) {
      patch_mm = std::atof(argv[++i]);
    } else {
      fs::path run = fs::path(arg).lexically_normal();
      if (run.filename().empty()) run = run.parent_path();  // "DIR/" names DIR
      runs.push_back(run);
    }
  }
  if (runs.empty() || !(patch_mm > 0)) {
    std::cerr << "usage: calibration_table [--patch MM] RUN_DIR ...\n";
    return 1;
  }
  std::cout << fmt::format(
      "patches of {} mm; a patch predicted when half its area is "
      "reconstructable\n",
      patch_mm);
  std::cout << "run | patches | predicted | observed | precision | recall | observed share by "
               "mean usable views (0-1, 1-2, 2-3, 3-4, 4-6, 6+)\n";
  for (const fs::path& run : runs) {
    std::string error;
    const auto patches = patches_of(run, patch_mm / 1000, &error);
    if (patches.empty()) {
      std::cout << fmt::format("{} | {}\n", run_name(run), error);
      continue;
    }
    long predicted = 0, observed = 0, both = 0;
    std::array<long, 6> in_bin{}, observed_in_bin{};
    for (const auto& [cell, p] : patches) {
      const bool yes = p.reconstructable_area >= 0.5 * p.area;
      predicted += yes;
      observed += p.observed;
      both += yes && p.observed;
      const double views = p.area > 0 ? p.usable_views_area / p.area : 0;
      const int bin = views < 4 ? static_cast<int>(views) : views < 6 ? 4 : 5;
      ++in_bin[bin];
      observed_in_bin[bin] += p.observed;
    }
    std::string bins;
    for (int b = 0; b < 6; ++b) {
      bins += in_bin[b]
                  ? fmt::format(" {:.2f} ({})", double(observed_in_bin[b]) / in_bin[b], in_bin[b])
                  : " -";
    }
    std::cout << fmt::format("{} | {} | {} | {} | {:.3f} | {:.3f} |{}\n", run_name(run),
                             patches.size(), predicted, observed,
                             predicted ? double(both) / predicted : 0.0,
                             observed ? double(both) / observed : 0.0, bins);
  }
  return 0;
}
