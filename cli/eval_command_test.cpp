// Tests of the `rigc eval` verb, and end-to-end evaluations of runs rendered with the preview
// backend: they need a renderer or the command line, which eval/ does not depend on.
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "backends/preview/preview_backend.h"
#include "cli/verbs.h"
#include "compiler/frontend.h"
#include "eval/eval.h"
#include "eval/eval_test_support.h"
#include "run/run_loop.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;
using test_inputs::write_cube_ply;
using test_inputs::write_small_image;

// eval registered no inputs: evaluating an earlier evaluation's cloud into the same folder wrote
// the new cloud over the one being measured.
TEST(EvalCommand, NeverWritesOverItsInputs) {
  rigc::testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  for (const char* name : {"a.jpg", "b.jpg"}) write_small_image(dir.file("photos/") + name);
  write_cube_ply(dir.file("cube.ply"));
  fs::create_directories(dir.path() / "eval");
  const std::string cloud = dir.file("eval/cloud_signed_distance.ply");
  fs::copy_file(dir.file("cube.ply"), cloud);
  const std::string before = rigc::testing::read_text(cloud);
  const auto result = rigc::testing::run_rigc(
      {"eval", "--photos", dir.file("photos"), "--ground-truth", dir.file("cube.ply"),
       "--reconstruction", cloud, "--no-align", "--mesh-samples", "1000", "-o", dir.file("eval")});
  EXPECT_THAT(result.err, HasSubstr("it is the reconstruction, an input of this command"));
  EXPECT_EQ(rigc::testing::read_text(cloud), before);
}

TEST(EvalCommand, MissingRunIsUserErrorAndMissingColmapIsToolError) {
  rigc::testing::TempDir dir;
  EXPECT_EQ(cli::run_eval_command({"rigc eval", dir.file("nothing")}), 1);
  // A run folder with images but a COLMAP that does not exist.
  fs::create_directories(dir.path() / "run" / "images");
  for (const char* name : {"a.jpg", "b.jpg"}) write_small_image(dir.file("run/images/") + name);
  write_cube_ply(dir.file("cube.ply"));
  EvalOptions o;
  o.run_dir = dir.file("run");
  o.ground_truth = dir.file("cube.ply");
  o.sfm.colmap = dir.file("no-such-colmap");
  o.quiet = true;
  std::ostringstream log;
  EvalSummary s;
  EXPECT_EQ(evaluate(o, log, &s), 2);
  EXPECT_THAT(log.str(), HasSubstr("COLMAP is not available"));
  std::ifstream report(dir.file("run/eval/eval.json"));
  ASSERT_TRUE(report.good());
  EXPECT_EQ(nlohmann::json::parse(report)["reconstruction"]["status"], "failed");
}

// ---------------------------------------------------------------------------------------------
// End to end: render with the preview, then evaluate with COLMAP. SLOW (each runs COLMAP; the
// textured turntable for minutes). Skipped without colmap. Filter them out with -EvalEndToEnd.*

bool have_colmap() {
  return std::system("colmap -h > /dev/null 2>&1") == 0;
}

struct RenderedRun {
  fs::path scene_file, run_dir;
};

RenderedRun render(const rigc::testing::TempDir& dir, const std::string& text, double scale) {
  RenderedRun r;
  r.scene_file = dir.path() / "scene.yaml";
  r.run_dir = dir.path() / "run";
  rigc::testing::write_text(r.scene_file.string(), text);
  DiagnosticEngine diag;
  rigc::testing::silence_diagnostics(diag);
  auto scene = compile_scene_file(r.scene_file.string(), diag);
  EXPECT_TRUE(scene.has_value());
  if (!scene) return r;
  run::RunOptions options;
  options.output_dir = r.run_dir;
  options.settings.scale = scale;
  std::ostringstream log;
  preview::PreviewBackend backend;
  EXPECT_EQ(run::run_backend(*scene, backend, options, log), 0) << log.str();
  return r;
}

TEST(EvalEndToEnd, SlowTexturedTurntableRegistersEveryImageAndIsAccurate) {
  RIGC_REQUIRE_TOOL(have_colmap(), "colmap");
  rigc::testing::TempDir dir;
  // 16 shots, 656 x 437 px, a speckled statue against a green screen.
  const RenderedRun run = render(dir, R"(rigc: 1
name: eval-e2e
object:
  primitive: {shape: statue, detail: 5, seed: 3}
  fit: {height: 25cm}
  surface: {pattern: speckle, scale: 5mm, contrast: 0.8}
studio:
  backdrop: {green_screen: true}
  lights:
    - {type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}
    - {type: area, position: [-0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}
  ambient: 50lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/11, shutter: 1/125, iso: 200}
  effects: {motion_blur: false}
shots:
  - turntable: {steps: 16, step: 22.5deg, camera: {distance: 70cm, height: 15cm}}
)",
                                 0.12);
  EvalOptions o;
  o.run_dir = run.run_dir.string();
  o.quiet = true;
  std::ostringstream log;
  EvalSummary s;
  ASSERT_EQ(evaluate(o, log, &s), 0) << log.str();
  EXPECT_EQ(s.images, 16);
  EXPECT_EQ(s.registered, 16);
  EXPECT_GT(s.points, 1000);
  const auto& d = s.report["signed_distance_mm"];
  EXPECT_LT(d["mean_abs"].get<double>(), 0.5) << s.report.dump(2);
  EXPECT_LT(std::abs(d["median"].get<double>()), 0.2);
  // Camera centres: depth along a 50 mm lens's axis is the weak direction (0.7 % of 70 cm).
  EXPECT_LT(s.report["cameras"]["position_error_mm"]["median"].get<double>(), 5.0);
  std::cout << "[ eval     ] " << s.registered << "/" << s.images << " registered, " << s.points
            << " points, " << s.mean_mm << " ± " << s.std_mm << " mm, mean |d| "
            << d["mean_abs"].get<double>() << " mm, COLMAP " << s.colmap_s << " s, RigC "
            << s.rigc_s << " s\n";
  EXPECT_TRUE(fs::exists(run.run_dir / "eval" / "cloud_signed_distance.ply"));
  EXPECT_TRUE(fs::exists(run.run_dir / "eval" / "heatmap.png"));
  EXPECT_TRUE(fs::exists(run.run_dir / "eval" / "histogram.png"));
  // Every file was renamed into place: no hidden temporary is left beside them.
  for (const auto& entry : fs::directory_iterator(run.run_dir / "eval")) {
    EXPECT_NE(entry.path().filename().string().front(), '.') << entry.path();
  }
}

// A small speckled statue on a turntable, `steps` shots 20 degrees apart, 656 px wide at the
// tests' 0.12 scale; `camera_extra` lines go into the camera section.
std::string small_statue_ring(const std::string& name, int steps, const std::string& camera_extra) {
  return fmt::format(R"(rigc: 1
name: {}
object:
  primitive: {{shape: statue, detail: 4, seed: 3}}
  fit: {{height: 25cm}}
  surface: {{pattern: speckle, scale: 2mm, contrast: 0.8}}
studio:
  backdrop: {{green_screen: true}}
  lights:
    - {{type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}}
  ambient: 50lx
camera:
  body: canon-6d
  lens: {{focal_length: 50mm}}
  exposure: {{aperture: f/11, shutter: 1/125, iso: 200}}
  effects: {{motion_blur: false}}
{}shots:
  - turntable: {{steps: {}, step: 20deg, camera: {{distance: 70cm, height: 15cm}}}}
)",
                     name, camera_extra, steps);
}

// Evaluates a small rendered run quietly (20000 ground-truth samples); false, with the log
// printed, if eval does not exit 0.
bool evaluate_small_run(const RenderedRun& run, EvalSummary* s) {
  EvalOptions o;
  o.run_dir = run.run_dir.string();
  o.quiet = true;
  o.metrics.ground_truth_samples = 20000;
  std::ostringstream log;
  const int code = evaluate(o, log, s);
  if (code != 0) ADD_FAILURE() << "eval exited " << code << ":\n" << log.str();
  return code == 0;
}

// COLMAP 3.8 reads 8-bit images only: a run in 16-bit PNG (the language's png16 output) goes to
// it as 8-bit copies.
TEST(EvalEndToEnd, SlowSixteenBitRunIsEvaluated) {
  RIGC_REQUIRE_TOOL(have_colmap(), "colmap");
  rigc::testing::TempDir dir;
  const RenderedRun run =
      render(dir, small_statue_ring("eval-e2e-png16", 8, "  output: {format: png16}\n"), 0.12);
  ASSERT_TRUE(fs::exists(run.run_dir / "images" / "shot_000.png"));
  EvalSummary s;
  ASSERT_TRUE(evaluate_small_run(run, &s));
  EXPECT_EQ(s.registered, 8);
  EXPECT_TRUE(fs::exists(run.run_dir / "eval" / "colmap" / "images_8bit" / "shot_000.png"));
}

// A ring with a gap (one of ten photos lost) registers in part, and that part is measured
// (COLMAP 3.8 drops models smaller than min(images, 10) unless told otherwise).
TEST(EvalEndToEnd, SlowCaptureWithAGapReportsThePartItReconstructs) {
  RIGC_REQUIRE_TOOL(have_colmap(), "colmap");
  rigc::testing::TempDir dir;
  const RenderedRun run = render(dir, small_statue_ring("eval-e2e-gap", 10, ""), 0.12);
  ASSERT_TRUE(fs::remove(run.run_dir / "images" / "shot_005.jpg"));
  EvalSummary s;
  ASSERT_TRUE(evaluate_small_run(run, &s));
  EXPECT_EQ(s.images, 9);
  EXPECT_GE(s.registered, 3);
  EXPECT_LT(s.registered, 9) << "the gap splits the ring";
}

TEST(EvalEndToEnd, SlowUntexturedObjectReportsTheFailure) {
  RIGC_REQUIRE_TOOL(have_colmap(), "colmap");
  rigc::testing::TempDir dir;
  const RenderedRun run = render(dir, R"(rigc: 1
name: eval-e2e-plain
object:
  primitive: sphere
  fit: {height: 20cm}
studio:
  backdrop: {green_screen: true}
  lights:
    - {type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 60W}
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/11, shutter: 1/125, iso: 200}
  effects: {motion_blur: false}
shots:
  - turntable: {steps: 8, step: 45deg, camera: {distance: 70cm, height: 15cm}}
)",
                                 0.1);
  EvalOptions o;
  o.run_dir = run.run_dir.string();
  o.quiet = true;
  std::ostringstream log;
  EvalSummary s;
  EXPECT_EQ(evaluate(o, log, &s), 2);
  EXPECT_FALSE(s.reconstructed);
  EXPECT_THAT(log.str(), HasSubstr("texture"));
  std::ifstream report(run.run_dir / "eval" / "eval.json");
  ASSERT_TRUE(report.good());
  EXPECT_EQ(nlohmann::json::parse(report)["reconstruction"]["status"], "failed");
}

}  // namespace
}  // namespace rigc::eval
