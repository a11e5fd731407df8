#include "analysis/coverage.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <regex>
#include <stdexcept>

#include "analysis/advice.h"
#include "analysis/coverage_output.h"
#include "assets/mesh_io.h"
#include "compiler/frontend.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::analysis {
namespace {

namespace fs = std::filesystem;

struct Analysed {
  ir::Scene scene;
  CoverageResult coverage;
  std::string warnings;
  int warning_count = 0;
};

Analysed analyse(const std::string& text) {
  Analysed out;
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  auto scene = compile_scene_text(text, "test.yaml", ".", diag);
  EXPECT_TRUE(scene) << messages;
  if (!scene) return out;
  out.scene = *scene;
  const scene::StudioScene studio = scene::prepare_studio_scene(out.scene);
  CoverageOptions options;
  options.visibility_scale = 0.2;
  out.coverage = analyse_coverage(out.scene, studio, options);
  DiagnosticEngine advice;
  rigc::testing::capture_diagnostics(advice, out.warnings);
  report_capture_advice(out.scene, studio, out.coverage, advice);
  out.warning_count = advice.warning_count();
  return out;
}

std::string scene_text(const std::string& object, const std::string& exposure,
                       const std::string& shots, const std::string& extra_camera = "") {
  return "rigc: 1\nobject:\n" + object + R"(
  surface: {pattern: speckle, scale: 3mm}
studio:
  turntable: {diameter: 40cm, height: 75cm}
  lights:
    - {type: area, position: [0.6m, -1.2m, 1.2m], size: [50cm, 50cm], power: 80W}
    - {type: area, position: [-0.6m, -1.2m, 1.2m], size: [50cm, 50cm], power: 80W}
  ambient: 300lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: )" +
         exposure + "\n" + extra_camera + "shots:\n" + shots;
}

const std::string kStatue = "  primitive: {shape: statue, detail: 5}\n  fit: {height: 30cm}";
const std::string kGoodExposure = "{aperture: f/13, shutter: 1/125, iso: 200}";
const std::string kGoodShots =
    "  - turntable: {steps: 18, step: 20deg, camera: {distance: 90cm, height: 15cm}}\n"
    "  - turntable: {steps: 18, step: 20deg, camera: {distance: 90cm, height: 50cm}}\n";

// One far camera sees a spherical cap of (1 - r/D)/2 of a sphere's area.
TEST(Coverage, SphereSeenFromOneCameraMatchesTheCapArea) {
  const std::string sphere = "  primitive: {shape: sphere, detail: 6}\n  fit: {size: 10cm}";
  Analysed a = analyse(scene_text(
      sphere, kGoodExposure, "  - pose: {position: [0, -0.45m, 0.8m], look_at: [0, 0, 0.8m]}\n"));
  ASSERT_EQ(a.coverage.shots.size(), 1u);
  const double expected = (1 - 0.05 / 0.45) / 2;
  EXPECT_NEAR(a.coverage.shots[0].seen_1, expected, 0.01);
  // Two opposite cameras see two such caps, and no face twice.
  Analysed b =
      analyse(scene_text(sphere, kGoodExposure,
                         "  - pose: {position: [0, -0.45m, 0.8m], look_at: [0, 0, 0.8m]}\n"
                         "  - pose: {position: [0, 0.45m, 0.8m], look_at: [0, 0, 0.8m]}\n"));
  EXPECT_NEAR(b.coverage.shots[1].seen_1, 2 * expected, 0.02);
  EXPECT_NEAR(b.coverage.shots[1].seen_2, 0.0, 1e-9);
  EXPECT_NEAR(b.coverage.shots[1].overlap_with_previous, 0.0, 1e-9);
}

// Cameras below the table top see the table's underside, not the box on it.
TEST(Coverage, FacesHiddenBehindTheTurntableAreNotCounted) {
  const std::string box = "  primitive: box\n  fit: {size: 10cm}";
  Analysed below = analyse(scene_text(
      box, kGoodExposure, "  - orbit: {distance: 60cm, rings: [{elevation: -25deg, count: 8}]}\n"));
  EXPECT_LT(below.coverage.shots.back().seen_1, 0.001);
  Analysed above = analyse(scene_text(
      box, kGoodExposure, "  - orbit: {distance: 60cm, rings: [{elevation: 25deg, count: 8}]}\n"));
  // Four sides and the top of the box: 5/6 of its area; the base is never seen.
  EXPECT_NEAR(above.coverage.shots.back().seen_1, 5.0 / 6, 0.01);
  double base = 0, base_seen = 0;
  for (size_t f = 0; f < above.coverage.face_area_m2.size(); ++f) {
    if (!above.coverage.resting[f]) continue;
    base += above.coverage.face_area_m2[f];
    if (above.coverage.views[f]) base_seen += above.coverage.face_area_m2[f];
  }
  EXPECT_NEAR(base / above.coverage.total_area_m2, 1.0 / 6, 1e-6);
  EXPECT_EQ(base_seen, 0);
}

TEST(Coverage, AGoodTurntableCaptureReconstructsMostOfTheObject) {
  Analysed a = analyse(scene_text(kStatue, kGoodExposure, kGoodShots));
  const ShotCoverage& last = a.coverage.shots.back();
  EXPECT_GT(last.seen_2, 0.9);
  EXPECT_GT(last.reconstructable, 0.85);
  EXPECT_LE(last.reconstructable, last.seen_2);
  EXPECT_EQ(a.warning_count, 0) << a.warnings;
  // Cumulative shares never fall, and per-shot overlap is high for 20 degree steps.
  for (size_t s = 1; s < a.coverage.shots.size(); ++s) {
    EXPECT_GE(a.coverage.shots[s].seen_1, a.coverage.shots[s - 1].seen_1);
  }
  EXPECT_GT(a.coverage.shots[1].overlap_with_previous, 0.7);
}

TEST(Coverage, AnOutOfFocusCaptureReconstructsNothing) {
  Analysed a = analyse(scene_text(kStatue, "{aperture: f/1.4, shutter: 1/2000, iso: 100}",
                                  kGoodShots, "  focus: 5m\n"));
  EXPECT_GT(a.coverage.shots.back().seen_2, 0.9);
  EXPECT_EQ(a.coverage.shots.back().reconstructable, 0.0);
  EXPECT_THAT(a.warnings, HasSubstr("warning: depth of field at f/1.4"));
}

struct WarningCase {
  const char* name;
  std::string exposure;
  std::string shots;
  std::string extra_camera;
  const char* expected;
};

TEST(Coverage, EachWarningFiresOnItsCraftedScene) {
  const std::vector<WarningCase> cases = {
      {"shallow focus", "{aperture: f/2, shutter: 1/2000, iso: 100}", kGoodShots, "",
       "depth of field at f/2 is shallower than the object"},
      {"diffraction", "{aperture: f/64, shutter: 1/8, iso: 400}", kGoodShots, "",
       "f/64 is diffraction-limited"},
      {"over-exposure", "{aperture: f/13, shutter: 1/4, iso: 800}", kGoodShots, "",
       "over-exposure"},
      {"under-exposure", "{aperture: f/13, shutter: 1/8000, iso: 100}", kGoodShots, "",
       "under-exposure"},
      {"motion blur", kGoodExposure,
       "  - turntable: {steps: 18, step: 20deg, speed: 20deg/s, camera: {distance: 90cm, "
       "height: 15cm}}\n",
       "", "the turning table smears the object"},
      // Beyond any shutter the language takes (1/8000 s): no 1/147408 s advice.
      {"motion blur, no shutter helps", kGoodExposure,
       "  - turntable: {steps: 18, step: 20deg, speed: 120rpm, camera: {distance: 90cm, "
       "height: 15cm}}\n",
       "", "stop the table for each shot (no shutter is fast enough)"},
      {"unseen top", kGoodExposure,
       "  - turntable: {steps: 18, step: 20deg, camera: {distance: 90cm, height: -5cm}}\n", "",
       "add a ring at a higher elevation"},
      {"low overlap", kGoodExposure,
       "  - turntable: {steps: 3, step: 120deg, camera: {distance: 90cm, height: 15cm}}\n", "",
       "overlaps the previous shot by only"},
      {"too small", kGoodExposure,
       "  - turntable: {steps: 18, step: 20deg, camera: {distance: 6m, height: 15cm}}\n"
       "  - turntable: {steps: 18, step: 20deg, camera: {distance: 6m, height: 2m}}\n",
       "  focus: 6m\n", "the object fills only"},
  };
  for (const auto& c : cases) {
    Analysed a = analyse(scene_text(kStatue, c.exposure, c.shots, c.extra_camera));
    EXPECT_THAT(a.warnings, HasSubstr(c.expected)) << c.name << ":\n" << a.warnings;
  }
}

// A distortion the compiler takes (no fold-over) but that draws the frame's edge from beyond
// the rendered canvas is pointed out at the distortion's line; a usual one is not.
// A scan's vertex colours are the albedo the exposure check sees, face by face: the cube's red
// top and blue bottom, not one mean colour for the whole cube.
TEST(Coverage, VertexColoursAreTheFacesAlbedo) {
  const std::string cube =
      "  mesh: " + rigc::testing::source_path("tests/meshes/cube_quads_big_endian_colors.ply") +
      "\n  fit: {height: 20cm}";
  std::string text = scene_text(cube, kGoodExposure, kGoodShots);
  const std::string speckle = "surface: {pattern: speckle, scale: 3mm}";
  text.replace(text.find(speckle), speckle.size(), "surface: {pattern: none}");
  DiagnosticEngine diag;
  const auto scene = compile_scene_text(text, "test.yaml", ".", diag);
  ASSERT_TRUE(scene);
  const scene::StudioScene studio = scene::prepare_studio_scene(*scene);
  const std::vector<float> albedo = face_albedo(*scene, studio);
  const ir::Mesh& mesh = scene->object.mesh;
  ASSERT_EQ(albedo.size(), mesh.triangles.size());
  int top = 0, bottom = 0;
  for (std::size_t f = 0; f < albedo.size(); ++f) {
    const auto& corners = mesh.triangles[f];
    const bool all_top = mesh.positions[corners[0]].z() > 0 && mesh.positions[corners[1]].z() > 0 &&
                         mesh.positions[corners[2]].z() > 0;
    const bool all_bottom = mesh.positions[corners[0]].z() < 0 &&
                            mesh.positions[corners[1]].z() < 0 &&
                            mesh.positions[corners[2]].z() < 0;
    if (all_top) {
      EXPECT_NEAR(albedo[f], 0.2126, 1e-3) << "face " << f;
    }
    if (all_bottom) {
      EXPECT_NEAR(albedo[f], 0.0722, 1e-3) << "face " << f;
    }
    top += all_top;
    bottom += all_bottom;
  }
  EXPECT_EQ(top, 2);
  EXPECT_EQ(bottom, 2);
}

TEST(Coverage, ADistortionBeyondTheCanvasIsPointedOut) {
  const auto with_lens = [](const std::string& distortion) {
    std::string text = scene_text(kStatue, kGoodExposure, kGoodShots);
    const std::string lens = "lens: {focal_length: 50mm}";
    text.replace(text.find(lens), lens.size(),
                 "lens: {focal_length: 50mm, distortion: " + distortion + "}");
    return text;
  };
  const std::string expected = "the distortion draws part of the frame from beyond the canvas";
  const Analysed strong =
      analyse(with_lens("{k1: 0.056, k2: -0.0025, p1: -0.027, p2: -0.24, k3: 0.046}"));
  EXPECT_THAT(strong.warnings, HasSubstr("test.yaml:14:42: warning: " + expected));
  const Analysed usual = analyse(with_lens("{k1: -0.05, k2: 0.01, p1: 0.001, p2: -0.002}"));
  EXPECT_THAT(usual.warnings, Not(HasSubstr(expected)));
}

// The over-exposure advice names a shutter; taking it, the warning goes, however many stops over
// the exposure is (about nine at 30 s).
TEST(Coverage, TheSuggestedShutterEndsTheOverExposure) {
  for (const char* shutter : {"30", "1/2", "1/15"}) {
    Analysed a = analyse(scene_text(
        kStatue, fmt::format("{{aperture: f/13, shutter: {}, iso: 200}}", shutter), kGoodShots));
    const std::regex advice("over-exposure: .* stops? less light: a shutter of (1/)?([0-9.]+) s");
    std::smatch match;
    ASSERT_TRUE(std::regex_search(a.warnings, match, advice)) << shutter << ":\n" << a.warnings;
    const std::string suggested = match[1].str() + match[2].str();
    Analysed after = analyse(scene_text(
        kStatue, fmt::format("{{aperture: f/13, shutter: {}, iso: 200}}", suggested), kGoodShots));
    EXPECT_THAT(after.warnings, Not(HasSubstr("over-exposure")))
        << shutter << " -> " << suggested << ":\n"
        << after.warnings;
    EXPECT_THAT(after.warnings, Not(HasSubstr("under-exposure")));
  }
}

TEST(Coverage, OptionsCheckTheVisibilityScale) {
  for (const double scale : {0.0, 0.01, 0.2, 1.0}) {
    CoverageOptions options;
    options.visibility_scale = scale;
    EXPECT_TRUE(options.check()) << scale;
  }
  for (const double scale : {-0.5, 1e-9, 0.005, 1.5, std::nan("")}) {
    CoverageOptions options;
    options.visibility_scale = scale;
    std::string error;
    EXPECT_FALSE(options.check(&error)) << scale;
    EXPECT_THAT(error, HasSubstr("visibility_scale"));
  }
  CoverageOptions bad;
  bad.visibility_scale = 2;
  const ir::Scene scene;
  const scene::StudioScene studio;
  EXPECT_THROW(analyse_coverage(scene, studio, bad), std::invalid_argument);
}

TEST(Coverage, WritesColouredMeshesPicturesAndJson) {
  testing::TempDir dir;
  Analysed a = analyse(scene_text(
      "  primitive: box\n  fit: {size: 10cm}", kGoodExposure,
      "  - turntable: {steps: 4, step: 90deg, camera: {distance: 60cm, height: 20cm}}\n"));
  const scene::StudioScene studio = scene::prepare_studio_scene(a.scene);
  std::string error;
  ASSERT_TRUE(write_coverage_outputs(a.scene, studio, a.coverage, dir.path(), 96, &error)) << error;
  for (const char* file :
       {"coverage.ply", "coverage.glb", "views.ply", "views.glb", "coverage.json",
        "pictures/view_front.png", "pictures/after_shot_003.png"}) {
    EXPECT_TRUE(fs::exists(dir.path() / file)) << file;
  }
  // The GLB and PLY load back with one face per box triangle.
  auto glb = load_model((dir.path() / "coverage.glb").string(), &error);
  ASSERT_TRUE(glb) << error;
  EXPECT_EQ(glb->mesh.triangles.size(), a.coverage.face_area_m2.size());
  const std::string ply = testing::read_text((dir.path() / "coverage.ply").string());
  EXPECT_THAT(ply, HasSubstr("property uchar red"));
  // Each face's prediction as scalar fields, in the order of the header, after its colour.
  EXPECT_THAT(ply, HasSubstr("property uchar blue\nproperty ushort views\nproperty ushort "
                             "usable_views\nproperty uchar reconstructable\nend_header\n"));
  const std::size_t faces = a.coverage.views.size();
  const std::size_t face_record = 1 + 3 * 4 + 3 + 2 + 2 + 1;
  ASSERT_GE(ply.size(), faces * face_record);
  const char* last = ply.data() + ply.size() - face_record;
  std::uint16_t views = 0, usable = 0;
  std::memcpy(&views, last + 16, 2);
  std::memcpy(&usable, last + 18, 2);
  EXPECT_EQ(views, a.coverage.views[faces - 1]);
  EXPECT_EQ(usable, a.coverage.usable_views[faces - 1]);
  EXPECT_EQ(static_cast<std::uint8_t>(last[20]), a.coverage.reconstructable[faces - 1]);
  EXPECT_EQ(paper_color(0), Eigen::Vector3f(1, 1, 1));
  EXPECT_GT(paper_color(1).x(), 0.5f);
  EXPECT_GT(paper_color(2).y(), 0.5f);
}

}  // namespace
}  // namespace rigc::analysis
