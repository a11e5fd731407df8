#include "plan/plan_scene.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "compiler/frontend.h"
#include "plan/report.h"
#include "scene/studio_scene.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::plan {
namespace {

using testing::TempDir;
using testing::write_text;

// A primitive on the turntable, lit all round, four turntable shots at the object's height.
std::string primitive_scene(const std::string& object, const std::string& coverage) {
  return "rigc: 1\nname: plan-test\nobject:\n  " + object +
         "\n  surface: {pattern: speckle, scale: 2mm}\nstudio:\n"
         "  turntable: {diameter: 40cm, height: 75cm}\n  lights:\n"
         "    - {type: directional, direction: [0, 1, -1], illuminance: 2000lx}\n"
         "  ambient: 1500lx\ncamera:\n  body: canon-6d\n  lens: {focal_length: 50mm}\n"
         "  exposure: {aperture: f/16, shutter: 1/125, iso: 400}\n  focus: auto\n"
         "coverage: " +
         coverage +
         "\nshots:\n  - turntable: {steps: 4, step: 90deg, camera: {distance: 90cm, height: "
         "10cm}}\n";
}

struct Planned {
  std::unique_ptr<PlanOutcome> outcome;
  std::string error, diagnostics;
};

Planned plan_text(const TempDir& dir, const std::string& text, PlanRequest request) {
  request.scene_path = dir.file("scene.yaml");
  request.output_path = dir.file("planned.yaml");
  if (request.visibility_scale == 0) request.visibility_scale = 0.15;
  write_text(request.scene_path, text);
  DiagnosticEngine diag;
  std::ostringstream diagnostics;
  diag.set_handler([&](const Diagnostic&, const std::string& r) { diagnostics << r; });
  Planned planned;
  planned.outcome = plan_scene(request, diag, &planned.error);
  planned.diagnostics = diagnostics.str();
  return planned;
}

// A lower bound on any plan's shot count: each reconstructable face needs two usable views, and
// no candidate gives more usable area than the best one.
int lower_bound_on_shots(const PlanOutcome& outcome, double target) {
  const analysis::CoverageResult& c = outcome.candidate_coverage;
  double best_usable = 0;
  for (const analysis::ShotSight& sight : c.sights) {
    double usable = 0;
    for (const std::uint32_t f : sight.usable) usable += c.face_area_m2[f];
    best_usable = std::max(best_usable, usable / c.total_area_m2);
  }
  return static_cast<int>(std::ceil(2 * target / best_usable - 1e-9));
}

TEST(Plan, ACubeNeedsTheFourCornerViewsOnly) {
  TempDir dir;
  PlanRequest request;
  request.target = 0.8;                     // of 5/6: the bottom rests on the table
  request.max_step_rad = std::numbers::pi;  // coverage alone
  request.candidates.ring_elevations_rad = {35.26 * kDegree};
  request.candidates.azimuth_step_rad = 15 * kDegree;
  const Planned planned = plan_text(
      dir, primitive_scene("primitive: {shape: box}\n  fit: {size: 20cm}", "{min_overlap: 0}"),
      request);
  ASSERT_TRUE(planned.outcome) << planned.error << planned.diagnostics;
  const Plan& plan = planned.outcome->plan;
  EXPECT_TRUE(plan.target_reached);
  // Each of five faces needs two views and a view sees at most three faces: 4 is the optimum.
  EXPECT_EQ(lower_bound_on_shots(*planned.outcome, request.target), 4);
  EXPECT_EQ(plan.shots.size(), 4u);
}

TEST(Plan, ASphereNeedsFewShotsMoreThanTheLowerBound) {
  TempDir dir;
  PlanRequest request;
  request.target = 0.7;
  request.max_step_rad = std::numbers::pi;  // coverage alone
  request.candidates.azimuth_step_rad = 20 * kDegree;
  const Planned planned = plan_text(
      dir, primitive_scene("primitive: {shape: sphere}\n  fit: {size: 20cm}", "{min_overlap: 0}"),
      request);
  ASSERT_TRUE(planned.outcome) << planned.error << planned.diagnostics;
  const Plan& plan = planned.outcome->plan;
  EXPECT_TRUE(plan.target_reached);
  const int bound = lower_bound_on_shots(*planned.outcome, request.target);
  // The stated bound: at most 1.5 times the lower bound, plus one.
  EXPECT_LE(static_cast<double>(plan.shots.size()), 1.5 * bound + 1) << "lower bound " << bound;
}

// A hemispherical bowl, open at the top: its inside faces the sky.
std::string bowl_obj() {
  std::ostringstream obj;
  const int rings = 8, segments = 24;
  const double outer = 0.1, inner = 0.09;
  // Vertices: outer shell then inner shell, ring 0 at the rim down to the pole.
  for (const double radius : {outer, inner}) {
    for (int r = 0; r <= rings; ++r) {
      const double polar = std::numbers::pi / 2 * r / rings;  // 0 at the rim
      for (int s = 0; s < segments; ++s) {
        const double azimuth = 2 * std::numbers::pi * s / segments;
        obj << "v " << radius * std::cos(polar) * std::cos(azimuth) << ' '
            << -radius * std::sin(polar) << ' ' << radius * std::cos(polar) * std::sin(azimuth)
            << '\n';
      }
    }
  }
  auto index = [&](int shell, int r, int s) {
    return 1 + shell * (rings + 1) * segments + r * segments + (s % segments);
  };
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      // Outside facing out (+Y up in OBJ), inside facing the bowl's axis.
      obj << "f " << index(0, r, s) << ' ' << index(0, r, s + 1) << ' ' << index(0, r + 1, s + 1)
          << ' ' << index(0, r + 1, s) << '\n';
      obj << "f " << index(1, r, s) << ' ' << index(1, r + 1, s) << ' ' << index(1, r + 1, s + 1)
          << ' ' << index(1, r, s + 1) << '\n';
    }
  }
  for (int s = 0; s < segments; ++s) {  // the rim
    obj << "f " << index(0, 0, s) << ' ' << index(1, 0, s) << ' ' << index(1, 0, s + 1) << ' '
        << index(0, 0, s + 1) << '\n';
  }
  return obj.str();
}

TEST(Plan, ABowlGetsShotsFromAbove) {
  TempDir dir;
  write_text(dir.file("bowl.obj"), bowl_obj());
  PlanRequest request;
  request.target = 0.6;
  const Planned planned = plan_text(
      dir, primitive_scene("mesh: bowl.obj\n  fit: {width: 20cm}", "{min_overlap: 0.3}"), request);
  ASSERT_TRUE(planned.outcome) << planned.error << planned.diagnostics;
  const PlanOutcome& outcome = *planned.outcome;
  EXPECT_TRUE(outcome.plan.target_reached);
  // The inside (normals up) is reconstructable only from high rings.
  double inside = 0, inside_reconstructable = 0;
  const analysis::CoverageResult& c = outcome.candidate_coverage;
  for (size_t f = 0; f < c.face_area_m2.size(); ++f) {
    if (c.face_normal[f].z() < 0.7) continue;
    inside += c.face_area_m2[f];
    if (outcome.plan.face_reconstructable[f]) inside_reconstructable += c.face_area_m2[f];
  }
  EXPECT_GT(inside_reconstructable, 0.8 * inside);
  double highest = 0;
  for (const PlannedShot& shot : outcome.plan.shots) {
    const Candidate* candidate = planned_candidate(outcome, shot);
    ASSERT_NE(candidate, nullptr);
    highest = std::max(highest, outcome.candidates.stations[candidate->station].elevation_rad);
  }
  EXPECT_GE(highest, 40 * kDegree);
}

std::string statue_scene() {
  return primitive_scene("primitive: {shape: statue, detail: 4}\n  fit: {height: 25cm}",
                         "{min_overlap: 0.6}");
}

// A plan written where the scene's relative mesh path does not resolve is refused before the
// analysis, not after it.
TEST(Plan, AnOutputWhereTheMeshDoesNotResolveIsRefusedFirst) {
  TempDir dir;
  write_text(dir.file("tetra.ply"),
             "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
             "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
             "end_header\n0 0 0\n0.1 0 0\n0 0.1 0\n0 0 0.1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n"
             "3 1 2 3\n");
  std::filesystem::create_directories(dir.path() / "elsewhere");
  PlanRequest request;
  request.scene_path = dir.file("scene.yaml");
  request.output_path = dir.file("elsewhere/planned.yaml");
  write_text(request.scene_path, primitive_scene("mesh: tetra.ply", "{min_overlap: 0.6}"));
  DiagnosticEngine diag;
  std::string error;
  EXPECT_EQ(plan_scene(request, diag, &error), nullptr);
  EXPECT_THAT(error, HasSubstr("would not compile at " + request.output_path));
  EXPECT_THAT(error, HasSubstr("tetra.ply"));
  EXPECT_THAT(error, HasSubstr("beside the scene"));
}

TEST(Plan, AnUnreachableTargetSaysWhatStaysUnseen) {
  TempDir dir;
  PlanRequest request;
  request.target = 0.99;
  request.candidates.turntable_only = true;
  const Planned planned = plan_text(dir, statue_scene(), request);
  ASSERT_TRUE(planned.outcome) << planned.error << planned.diagnostics;
  EXPECT_FALSE(planned.outcome->plan.target_reached);
  std::ostringstream report;
  print_plan_report(*planned.outcome, report);
  EXPECT_THAT(report.str(), HasSubstr("cannot be reached"));
  EXPECT_THAT(report.str(), HasSubstr("rests on the turntable"));
  EXPECT_THAT(report.str(), HasSubstr("faces up, seen by no candidate"));
}

TEST(Plan, ThePlannedSceneCompilesAndItsCoverageIsThePlans) {
  TempDir dir;
  PlanRequest request;
  request.target = 0.85;
  const Planned planned = plan_text(dir, statue_scene(), request);
  ASSERT_TRUE(planned.outcome) << planned.error << planned.diagnostics;
  const PlanOutcome& outcome = *planned.outcome;
  ASSERT_TRUE(outcome.plan.target_reached);
  // Every shot chains to the one before it.
  EXPECT_TRUE(outcome.plan.weak_links.empty());
  for (size_t i = 1; i < outcome.plan.shots.size(); ++i) {
    EXPECT_GE(outcome.plan.shots[i].overlap_with_previous, 0.6) << i;
    EXPECT_LE(outcome.plan.shots[i].step_rad, 30 * kDegree + 1e-9) << i;
  }
  // The file keeps the rest of the scene and compiles to the plan's shots and coverage.
  EXPECT_THAT(outcome.planned_text, HasSubstr("fit: {height: 25cm}"));
  DiagnosticEngine diag;
  const auto planned_scene =
      compile_scene_text(outcome.planned_text, request.output_path, dir.path().string(), diag);
  ASSERT_TRUE(planned_scene);
  ASSERT_EQ(planned_scene->shots.size(), outcome.plan.shots.size());
  analysis::CoverageOptions options;
  options.visibility_scale = 0.15;
  const analysis::CoverageResult coverage = analysis::analyse_coverage(
      *planned_scene, scene::prepare_studio_scene(*planned_scene), options);
  EXPECT_NEAR(coverage.shots.back().reconstructable, outcome.plan.reconstructable, 0.002);
  for (size_t i = 1; i < coverage.shots.size(); ++i) {
    EXPECT_NEAR(coverage.shots[i].overlap_with_previous,
                outcome.plan.shots[i].overlap_with_previous, 0.01)
        << i;
  }
}

TEST(Plan, KeptShotsComeFirstAndTheNextShotAddsMost) {
  TempDir dir;
  PlanRequest request;
  request.keep_scene_shots = true;
  request.next_shot_only = true;
  request.target = 1;
  const Planned planned = plan_text(dir, statue_scene(), request);
  ASSERT_TRUE(planned.outcome) << planned.error << planned.diagnostics;
  const PlanOutcome& outcome = *planned.outcome;
  ASSERT_EQ(outcome.kept, 4);
  ASSERT_EQ(outcome.plan.shots.size(), 5u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(outcome.plan.shots[i].candidate, i);
  const double scene_share = outcome.coverage.shots.back().reconstructable;
  EXPECT_NEAR(outcome.plan.shots[3].reconstructable, scene_share, 0.002);
  // No single candidate adds more reconstructable surface than the one suggested.
  const double suggested = outcome.plan.shots.back().gain;
  EXPECT_GT(suggested, 0);
  std::vector<int> shots = {0, 1, 2, 3, 0};
  for (int c = 4; c < static_cast<int>(outcome.candidate_coverage.sights.size()); ++c) {
    shots.back() = c;
    EXPECT_LE(reconstructable_share(outcome.problem, shots) - outcome.plan.shots[3].reconstructable,
              suggested + 1e-6)
        << c;
  }
  // The scene keeps its own shots entry; the suggestion is appended to it.
  const std::string& text = outcome.planned_text;
  EXPECT_THAT(text, HasSubstr("steps: 4, step: 90deg"));
  EXPECT_THAT(text, HasSubstr("# Suggested by `rigc plan --next`"));
  DiagnosticEngine diag;
  const auto planned_scene =
      compile_scene_text(text, request.output_path, dir.path().string(), diag);
  ASSERT_TRUE(planned_scene);
  EXPECT_EQ(planned_scene->shots.size(), 5u);
}

}  // namespace
}  // namespace rigc::plan
