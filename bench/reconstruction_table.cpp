// `rigc eval --reconstruction` speed (issue #40's target: 5 million reconstructed points against a
// 1-million-triangle ground truth in under 10 s). Builds a run folder without rendering (the
// statue at 1M triangles, 18 shots, grey images of the camera's size, the ground truth `rigc
// render` writes), samples the surface 5M times with 0.3 mm of noise into a binary PLY, and times
// evaluate() with each alignment. Prints a table; asserts nothing.
//
// Usage: reconstruction_table [POINTS] [DETAIL] [MODES]   (default 5000000, 8, nca: --no-align,
// --cameras, registration)
//        reconstruction_table 0 0 - SCENE   (the ground-truth points' cost in a full-size render)
#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <sstream>

#include "compiler/frontend.h"
#include "eval/eval.h"
#include "eval/geometry.h"
#include "run/bundler.h"
#include "run/colmap_text.h"
#include "run/ground_truth_points.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// User + system CPU time of this process so far.
double cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

std::string scene_text(int detail) {
  return fmt::format(R"(rigc: 1
name: reconstruction-bench
object:
  primitive: {{shape: statue, detail: {}, seed: 7}}
  fit: {{height: 30cm}}
  surface: {{pattern: speckle, scale: 2mm, contrast: 0.8}}
studio:
  lights:
    - {{type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}}
camera:
  body: canon-6d
  lens: {{focal_length: 50mm}}
  exposure: {{aperture: f/11, shutter: 1/125, iso: 200}}
shots:
  - turntable: {{steps: 18, step: 20deg, camera: {{distance: 90cm, height: 15cm}}}}
)",
                     detail);
}

}  // namespace

int main(int argc, char** argv) {
  const long points = argc > 1 ? std::atol(argv[1]) : 5000000;
  const int detail = argc > 2 ? std::atoi(argv[2]) : 8;
  if (argc > 4) {
    // What the ground-truth points add to `rigc render` of SCENE at full size.
    rigc::DiagnosticEngine diag;
    auto scene = rigc::compile_scene_file(argv[4], diag);
    if (!scene) return 2;
    std::vector<int> shots;
    for (const auto& s : scene->shots) shots.push_back(s.index);
    std::string error;
    const auto camera = rigc::run::output_camera(scene->camera, 1.0, &error);
    for (int run = 0; run < 3; ++run) {
      const auto t = Clock::now();
      const double cpu0 = cpu_seconds();
      const auto gt = rigc::run::sample_ground_truth_points(*scene, shots, *camera, 20000);
      std::cout << fmt::format(
          "{}: {} triangles, {} shots at {}x{}: ground-truth points {} in {:.3f} s ({:.3f} s "
          "CPU)\n",
          argv[4], scene->object.mesh.triangles.size(), shots.size(), camera->width, camera->height,
          gt.points.size(), seconds_since(t), cpu_seconds() - cpu0);
    }
    return 0;
  }
  const fs::path dir = fs::temp_directory_path() / fmt::format("rigc_recon_bench_{}", getpid());
  fs::create_directories(dir);
  auto t0 = Clock::now();
  std::ofstream(dir / "scene.yaml") << scene_text(detail);
  rigc::DiagnosticEngine diag;
  auto scene = rigc::compile_scene_file((dir / "scene.yaml").string(), diag);
  if (!scene) return 2;
  std::cout << fmt::format("ground truth: statue detail {}, {} triangles (compiled in {:.2f} s)\n",
                           detail, scene->object.mesh.triangles.size(), seconds_since(t0));
  std::vector<int> shots;
  for (const auto& s : scene->shots) shots.push_back(s.index);
  std::string error;
  const auto camera = rigc::run::output_camera(scene->camera, 0.05, &error);
  t0 = Clock::now();
  const auto gt = rigc::run::sample_ground_truth_points(*scene, shots, *camera, 20000);
  std::cout << fmt::format("ground-truth points for sparse/: {} of 20000 seen, {:.3f} s\n",
                           gt.points.size(), seconds_since(t0));
  const fs::path run = dir / "run";
  fs::create_directories(run / "images");
  if (!rigc::run::write_colmap_sparse(run / "sparse", *scene, shots, 0.05, &error, &gt) ||
      !rigc::run::write_bundler(run / "bundle.out", run / "bundle.list.txt", *scene, shots, 0.05,
                                gt, &error)) {
    std::cerr << error << "\n";
    return 2;
  }
  const OIIO::ImageSpec spec(camera->width, camera->height, 3, OIIO::TypeDesc::UINT8);
  const std::vector<unsigned char> grey(
      static_cast<std::size_t>(camera->width) * camera->height * 3, 128);
  for (const auto& shot : scene->shots) {
    const std::string path =
        (run / "images" / rigc::run::image_file_name(scene->camera, shot)).string();
    auto out = OIIO::ImageOutput::create(path);
    out->open(path, spec);
    out->write_image(OIIO::TypeDesc::UINT8, grey.data());
    out->close();
  }
  // The reconstruction: samples of the surface, 0.3 mm of noise along the normal.
  t0 = Clock::now();
  const rigc::eval::Surface surface(rigc::ir::object_frame_positions(scene->object),
                                    scene->object.mesh.triangles);
  std::vector<rigc::ir::Vec3> samples, normals;
  surface.sample(static_cast<int>(points), 21, &samples, &normals);
  std::mt19937_64 random(1);
  std::normal_distribution<double> noise(0, 0.3e-3);
  open3d::geometry::PointCloud cloud;
  cloud.points_.resize(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    cloud.points_[i] = samples[i] + noise(random) * normals[i];
  }
  open3d::io::WritePointCloud((dir / "cloud.ply").string(), cloud);
  std::cout << fmt::format("reconstruction: {} points, {:.1f} MB binary PLY ({:.1f} s to make)\n",
                           samples.size(), fs::file_size(dir / "cloud.ply") / 1e6,
                           seconds_since(t0));

  std::cout
      << "\n| alignment | eval s | cpu s | mean ± std (mm) | F-score | load s | align+metrics s | "
         "files s |\n"
         "|---|---|---|---|---|---|---|---|\n";
  const std::string modes = argc > 3 ? argv[3] : "nca";  // n: --no-align, c: --cameras, a: auto
  for (const char* how : {"--no-align", "--cameras bundle.out", "registration"}) {
    if (modes.find(how[2] == 'n' ? 'n' : how[2] == 'c' ? 'c' : 'a') == std::string::npos) continue;
    rigc::eval::EvalOptions o;
    o.run_dir = run.string();
    o.scene = (dir / "scene.yaml").string();
    o.imported.reconstruction = (dir / "cloud.ply").string();
    o.output_dir = (dir / "eval").string();
    o.quiet = true;
    if (std::string(how) == "--no-align") o.imported.align = false;
    if (std::string(how) == "--cameras bundle.out")
      o.imported.cameras = (run / "bundle.out").string();
    std::ostringstream log;
    rigc::eval::EvalSummary s;
    t0 = Clock::now();
    const double cpu0 = cpu_seconds();
    const int code = rigc::eval::evaluate(o, log, &s);
    const double total = seconds_since(t0), cpu = cpu_seconds() - cpu0;
    if (code != 0) {
      std::cout << fmt::format("| {} | failed ({}): {} |\n", how, code, log.str());
      continue;
    }
    const auto& t = s.report["timing_s"];
    std::cout << fmt::format(
        "| {} | {:.2f} | {:.2f} | {:+.3f} ± {:.3f} | {:.3f} | {:.2f} | {:.2f} | {:.2f} |\n", how,
        total, cpu, s.mean_mm, s.std_mm, s.fscore, t["load_reconstruction"].get<double>(),
        t["rigc_alignment_and_metrics"].get<double>(), t["files"].get<double>());
  }
  fs::remove_all(dir);
  return 0;
}
