// The COLMAP path and the reconstruction path measure alike: COLMAP's own points, exported to a
// PLY and given with COLMAP's model as the cameras, give eval's figures. SLOW and EXTERNAL: it
// renders a small run with the preview and reconstructs it with COLMAP (about 15 s).
#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include <cstdlib>
#include <sstream>

#include "backends/preview/preview_backend.h"
#include "compiler/frontend.h"
#include "eval/colmap.h"
#include "eval/eval.h"
#include "run/run_loop.h"
#include "tests/test_support.h"

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;

// 12 views 20 degrees apart of a speckled statue: COLMAP registers them all in about 10 s.
const char* kTurntableScene = R"(rigc: 1
name: recon-colmap
object:
  primitive: {shape: statue, detail: 4, seed: 3}
  fit: {height: 25cm}
  surface: {pattern: speckle, scale: 5mm, contrast: 0.8}
studio:
  backdrop: {green_screen: true}
  lights:
    - {type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}
  ambient: 50lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/11, shutter: 1/125, iso: 200}
  effects: {motion_blur: false}
shots:
  - turntable: {steps: 12, step: 20deg, camera: {distance: 70cm, height: 15cm}}
)";

TEST(EvalReconstructionColmap, ColmapsOwnPointsMeasureAsEvalDoes) {
  RIGC_REQUIRE_TOOL(std::system("colmap -h > /dev/null 2>&1") == 0, "colmap");
  rigc::testing::TempDir dir;
  rigc::testing::write_text(dir.file("scene.yaml"), kTurntableScene);
  DiagnosticEngine diag;
  auto scene = compile_scene_file(dir.file("scene.yaml"), diag);
  ASSERT_TRUE(scene);
  run::RunOptions render;
  render.output_dir = dir.path() / "run";
  render.settings.scale = 0.1;
  std::ostringstream render_log;
  preview::PreviewBackend backend;
  ASSERT_EQ(run::run_backend(*scene, backend, render, render_log), 0) << render_log.str();

  EvalOptions o;
  o.run_dir = dir.file("run");
  o.quiet = true;
  o.metrics.ground_truth_samples = 20000;
  std::ostringstream log;
  EvalSummary colmap;
  ASSERT_EQ(evaluate(o, log, &colmap), 0) << log.str();
  const fs::path model = colmap.report["reconstruction"]["model"].get<std::string>();
  std::string error;
  const auto points = read_colmap_points(model / "points3D.txt", &error);
  ASSERT_TRUE(points) << error;
  open3d::geometry::PointCloud cloud;
  // The points eval measures: those seen in at least o.sfm.min_track_length images.
  for (const auto& p : *points) {
    if (p.track_images.size() < static_cast<std::size_t>(o.sfm.min_track_length)) continue;
    cloud.points_.push_back(p.position);
    cloud.colors_.push_back(Eigen::Vector3d(p.rgb[0], p.rgb[1], p.rgb[2]) / 255);
  }
  ASSERT_TRUE(open3d::io::WritePointCloud(dir.file("colmap_points.ply"), cloud));

  o.imported.reconstruction = dir.file("colmap_points.ply");
  o.imported.cameras = model.string();
  o.output_dir = dir.file("recon_eval");
  EvalSummary recon;
  ASSERT_EQ(evaluate(o, log, &recon), 0) << log.str();
  EXPECT_EQ(recon.points, colmap.points);
  const auto &a = colmap.report, &b = recon.report;
  for (const char* key : {"mean", "std", "median", "p90_abs", "mean_abs"}) {
    const double x = a["signed_distance_mm"][key].get<double>();
    const double y = b["signed_distance_mm"][key].get<double>();
    EXPECT_NEAR(y, x, 0.01 * std::abs(x) + 1e-9) << key;
  }
  for (const char* key : {"precision", "recall", "fscore"}) {
    const double x = a["fscore"][key].get<double>(), y = b["fscore"][key].get<double>();
    EXPECT_NEAR(y, x, 0.01 * std::abs(x) + 1e-9) << key;
  }
  std::cout << "[ recon    ] COLMAP path " << colmap.mean_mm << " ± " << colmap.std_mm << " mm, F "
            << colmap.fscore << "; --reconstruction " << recon.mean_mm << " ± " << recon.std_mm
            << " mm, F " << recon.fscore << "\n";
}

}  // namespace
}  // namespace rigc::eval
