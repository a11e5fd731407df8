#include "compiler/frontend.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>

#include "ir/ir_json.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc {
namespace {

namespace fs = std::filesystem;
constexpr double kDeg = std::numbers::pi / 180;

// Compiles a scene file given relative to the repository, capturing diagnostics as text.
struct Compiled {
  std::optional<ir::Scene> scene;
  std::string diagnostics;
  int errors = 0;
  int warnings = 0;
};

Compiled compile_repo_file(const std::string& relative) {
  fs::current_path(RIGC_SOURCE_DIR);
  DiagnosticEngine diag;
  Compiled result;
  rigc::testing::capture_diagnostics(diag, result.diagnostics);
  result.scene = compile_scene_file(relative, diag);
  result.errors = diag.error_count();
  result.warnings = diag.warning_count();
  return result;
}

Compiled compile_text(const std::string& text, const std::string& base_dir = ".") {
  DiagnosticEngine diag;
  Compiled result;
  rigc::testing::capture_diagnostics(diag, result.diagnostics);
  result.scene = compile_scene_text(text, "test.yaml", base_dir, diag);
  result.errors = diag.error_count();
  result.warnings = diag.warning_count();
  return result;
}

const char* kMinimalScene = R"(rigc: 1
object:
  primitive: sphere
  fit: {height: 20cm}
  surface: {pattern: speckle}
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
shots:
  - turntable: {steps: 12, step: 30deg, camera: {distance: 80cm, height: 20cm}}
)";

// Each file in tests/bad_scenes has its exact expected diagnostics beside it. Set
// RIGC_UPDATE_GOLDEN=1 to rewrite them after an intended change (then read the diff).
TEST(Frontend, BadScenesGiveTheirGoldenDiagnostics) {
  const fs::path folder = fs::path(RIGC_SOURCE_DIR) / "tests" / "bad_scenes";
  int checked = 0;
  for (const auto& entry : fs::directory_iterator(folder)) {
    if (entry.path().extension() != ".yaml") continue;
    const std::string relative = "tests/bad_scenes/" + entry.path().filename().string();
    Compiled compiled = compile_repo_file(relative);
    EXPECT_FALSE(compiled.scene) << relative;
    EXPECT_GT(compiled.errors, 0) << relative;
    fs::path expected_path = entry.path();
    expected_path.replace_extension(".expected");
    if (std::getenv("RIGC_UPDATE_GOLDEN")) {
      testing::write_text(expected_path.string(), compiled.diagnostics);
    }
    EXPECT_EQ(compiled.diagnostics, testing::read_text(expected_path.string())) << relative;
    ++checked;
  }
  EXPECT_GE(checked, 10);
}

TEST(Frontend, AllErrorsOfAFileAreReported) {
  Compiled compiled = compile_repo_file("tests/bad_scenes/unknown_keys.yaml");
  EXPECT_EQ(compiled.errors, 3);
  EXPECT_THAT(compiled.diagnostics, HasSubstr("did you mean 'aperture'?"));
  EXPECT_THAT(compiled.diagnostics, HasSubstr("did you mean 'height'?"));
  EXPECT_THAT(compiled.diagnostics, HasSubstr("did you mean 'studio'?"));
}

TEST(Frontend, EveryExampleSceneCompiles) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(RIGC_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".yaml") continue;
    Compiled compiled = compile_repo_file("scenes/" + entry.path().filename().string());
    EXPECT_TRUE(compiled.scene) << entry.path() << "\n" << compiled.diagnostics;
    EXPECT_EQ(compiled.warnings, 0) << compiled.diagnostics;
    ++count;
  }
  EXPECT_GE(count, 3);
}

// The paper's rig, checked against intrinsics and poses computed by hand.
TEST(Frontend, PaperSceneHasHandComputedIntrinsicsAndPoses) {
  Compiled compiled = compile_repo_file("scenes/paper-turntable.yaml");
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  const ir::Scene& scene = *compiled.scene;
  const ir::Camera& camera = scene.camera;
  EXPECT_EQ(camera.make, "Canon");
  EXPECT_EQ(camera.model, "Canon EOS 6D");
  EXPECT_EQ(camera.width_px, 5472);
  EXPECT_EQ(camera.height_px, 3648);
  // fx = 50 mm * 5472 px / 35.8 mm; fy = 50 mm * 3648 px / 23.9 mm.
  EXPECT_NEAR(camera.fx, 7642.458100558659, 1e-6);
  EXPECT_NEAR(camera.fy, 7631.799163179916, 1e-6);
  EXPECT_DOUBLE_EQ(camera.cx, 2736);
  EXPECT_DOUBLE_EQ(camera.cy, 1824);
  EXPECT_DOUBLE_EQ(camera.distortion.k1, -0.02);
  EXPECT_DOUBLE_EQ(camera.aperture_f_number, 13);
  EXPECT_DOUBLE_EQ(camera.shutter_s, 1.0 / 125);
  EXPECT_DOUBLE_EQ(camera.iso, 200);

  // The statue is 30 cm tall, resting on the 75 cm high turntable.
  EXPECT_NEAR(scene.object.bounds_min_object.z(), 0, 1e-9);
  EXPECT_NEAR(scene.object.bounds_max_object.z(), 0.30, 1e-9);

  ASSERT_EQ(scene.shots.size(), 18u);
  // Camera fixed at 90 cm in front (-Y), 15 cm above the table top, looking horizontally at the
  // axis at the statue's mid height (0.75 + 0.15 = 0.90 m).
  ir::Mat4 expected = ir::Mat4::Identity();
  expected.block<3, 1>(0, 0) = ir::Vec3(1, 0, 0);   // camera +X: world +X
  expected.block<3, 1>(0, 1) = ir::Vec3(0, 0, -1);  // camera +Y (down): world -Z
  expected.block<3, 1>(0, 2) = ir::Vec3(0, 1, 0);   // camera +Z (forward): world +Y
  expected.block<3, 1>(0, 3) = ir::Vec3(0, -0.9, 0.9);
  for (const auto& shot : scene.shots) {
    EXPECT_TRUE(shot.world_from_camera.isApprox(expected, 1e-9)) << shot.name;
    EXPECT_NEAR(shot.turntable_angle_rad, shot.index * 20 * kDeg, 1e-12);
    EXPECT_NEAR(shot.focus_distance_m, 0.9, 1e-9);
  }
  EXPECT_EQ(scene.shots[17].name, "shot_017");
  // In the object's frame (what SfM recovers) the camera circles the statue: after a turn of
  // angle a it stands at (-0.9 sin a, -0.9 cos a, 0.15); shot 4 is at 80 degrees.
  const ir::Vec3 eye_shot4 = scene.shots[4].object_from_camera.block<3, 1>(0, 3);
  EXPECT_NEAR(eye_shot4.x(), -0.9 * std::sin(80 * kDeg), 1e-9);
  EXPECT_NEAR(eye_shot4.y(), -0.9 * std::cos(80 * kDeg), 1e-9);
  EXPECT_NEAR(eye_shot4.z(), 0.15, 1e-9);
  // Two lights behind the camera, aimed at the statue.
  ASSERT_EQ(scene.studio.lights.size(), 2u);
  for (const auto& light : scene.studio.lights) {
    EXPECT_EQ(light.type, ir::LightType::kArea);
    EXPECT_LT(light.position.y(), -0.9);
    const ir::Vec3 to_statue = (ir::Vec3(0, 0, 0.9) - light.position).normalized();
    EXPECT_GT(light.direction.dot(to_statue), 0.999);
  }
  EXPECT_TRUE(scene.studio.backdrop.green_screen);
  EXPECT_GT(scene.studio.backdrop.direction.y(), 0.99);  // behind the object
}

TEST(Frontend, OrbitRingsExpandAroundTheObject) {
  Compiled compiled = compile_repo_file("scenes/multi-ring.yaml");
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  const ir::Scene& scene = *compiled.scene;
  ASSERT_EQ(scene.shots.size(), 16u + 12u + 2u + 6u);
  const ir::Vec3 center =
      (ir::world_from_object(scene, 0) *
       ((scene.object.bounds_min_object + scene.object.bounds_max_object) / 2).homogeneous())
          .head<3>();
  int orbit_shots = 0;
  for (const auto& shot : scene.shots) {
    const ir::Vec3 eye = shot.world_from_camera.block<3, 1>(0, 3);
    // Every camera looks at its aim; orbit cameras stand 1.2 m from the object's centre.
    if (shot.kind == ir::ShotKind::kOrbit) {
      ++orbit_shots;
      EXPECT_NEAR((eye - center).norm(), 1.2, 1e-9) << shot.name;
      const ir::Vec3 forward = shot.world_from_camera.block<3, 1>(0, 2);
      EXPECT_GT(forward.dot((center - eye).normalized()), 1 - 1e-9);
    }
    // Rotation is orthonormal and right-handed.
    const Eigen::Matrix3d r = shot.world_from_camera.block<3, 3>(0, 0);
    EXPECT_TRUE((r.transpose() * r).isApprox(Eigen::Matrix3d::Identity(), 1e-9));
    EXPECT_NEAR(r.determinant(), 1, 1e-9);
  }
  EXPECT_EQ(orbit_shots, 34);
  EXPECT_EQ(scene.shots[28].kind, ir::ShotKind::kPose);
  const double elevation_ring3 =
      std::asin((scene.shots[30].world_from_camera(2, 3) - center.z()) / 1.2);
  EXPECT_NEAR(elevation_ring3, 65 * kDeg, 1e-9);
  // The detail shot looks at the point it names.
  const ir::Shot& detail = scene.shots[29];
  const ir::Vec3 to_target =
      (ir::Vec3(0, 0, 0.9) - detail.world_from_camera.block<3, 1>(0, 3)).normalized();
  const double alignment = detail.world_from_camera.block<3, 1>(0, 2).dot(to_target);
  EXPECT_GT(alignment, 1 - 1e-9);
}

// Directions of any length are directions: norm() overflows to inf on [1e200, 0, 0], which
// would give the pose's camera zero right and down axes (and a non-unit quaternion in
// images.txt).
TEST(Frontend, HugeDirectionVectorsStayDirections) {
  std::string text = kMinimalScene;
  text.replace(text.find("  - turntable:"), std::string::npos,
               "  - pose: {position: [0.5m, -0.6m, 1.1m], look_at: object, up: [1e200, 0, 0]}\n");
  text.replace(text.find("camera:"), 7,
               "studio:\n  lights:\n    - {type: directional, direction: [1e300, 1e300, -1e300], "
               "illuminance: 1000lx}\ncamera:");
  Compiled compiled = compile_text(text);
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  const ir::Mat4& world_from_camera = compiled.scene->shots.at(0).world_from_camera;
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR((world_from_camera.block<3, 1>(0, axis).norm()), 1, 1e-9) << axis;
  }
  EXPECT_NEAR(compiled.scene->studio.lights.at(0).direction.norm(), 1, 1e-9);
}

// Real lenses (a few percent of barrel or pincushion, a 24 mm's stronger barrel) pass; a
// mapping that folds the frame over, or never reaches its edge, is no lens.
TEST(Frontend, DistortionThatFoldsTheFrameOverIsAnError) {
  struct Case {
    std::string lens;
    bool valid;
  };
  const std::vector<Case> cases = {
      {"{focal_length: 50mm, distortion: {k1: -0.02}}", true},
      {"{focal_length: 24mm, distortion: {k1: -0.12, k2: 0.05, p1: 0.001}}", true},
      {"{focal_length: 50mm, distortion: {k1: 1, k2: 0.5}}", true},
      {"{focal_length: 50mm, distortion: {k1: -0.5}}", true},
      {"{focal_length: 50mm, distortion: {k1: -1}}", false},  // folds at 89 % of the corner
      {"{focal_length: 50mm, distortion: {p1: 1}}", false},
      {"{focal_length: 24mm, distortion: {k1: -0.3}}", false},
      {"{focal_length: 50mm, distortion: {k1: -1, k2: -1, k3: -1, p1: -1, p2: -1}}", false},
  };
  for (const Case& c : cases) {
    std::string text = kMinimalScene;
    text.replace(text.find("{focal_length: 50mm}"), 20, c.lens);
    Compiled compiled = compile_text(text);
    EXPECT_EQ(compiled.scene.has_value(), c.valid) << c.lens << "\n" << compiled.diagnostics;
    if (!c.valid) {
      EXPECT_THAT(compiled.diagnostics, HasSubstr("the distortion folds the image over"));
    }
  }
}

TEST(Frontend, BareNumbersTakeDocumentedUnits) {
  std::string text = kMinimalScene;
  text.replace(text.find("80cm"), 4, "0.8");
  text.replace(text.find("30deg"), 5, "30");
  Compiled compiled = compile_text(text);
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  EXPECT_NEAR(compiled.scene->shots[1].turntable_angle_rad, 30 * kDeg, 1e-12);
  EXPECT_NEAR(compiled.scene->shots[0].world_from_camera(1, 3), -0.8, 1e-12);
}

TEST(Frontend, UntexturedObjectGetsACaptureWarning) {
  std::string text = kMinimalScene;
  text.erase(text.find("  surface: {pattern: speckle}\n"), 30);
  Compiled compiled = compile_text(text);
  ASSERT_TRUE(compiled.scene);
  EXPECT_EQ(compiled.warnings, 1);
  EXPECT_THAT(compiled.diagnostics, HasSubstr("warning: the object has no texture"));
  // Where the scene writes a surface without a pattern, the warning is at that surface.
  text = kMinimalScene;
  text.replace(text.find("{pattern: speckle}"), 18, "{pattern: none}");
  compiled = compile_text(text);
  ASSERT_TRUE(compiled.scene);
  EXPECT_THAT(compiled.diagnostics,
              HasSubstr("test.yaml:5:12: warning: the object has no texture"));
}

// A scan's vertex colours are its base colour in the IR (red on the cube's top, blue below):
// they count as a texture, the scene's own colour replaces them, and the IR JSON carries them.
TEST(Frontend, VertexColoursReachTheIrUnlessTheSceneGivesAColour) {
  std::string text = kMinimalScene;
  text.replace(
      text.find("primitive: sphere"), 17,
      "mesh: " + rigc::testing::source_path("tests/meshes/cube_quads_big_endian_colors.ply"));
  text.erase(text.find("  surface: {pattern: speckle}\n"), 30);
  Compiled coloured = compile_text(text);
  ASSERT_TRUE(coloured.scene) << coloured.diagnostics;
  EXPECT_THAT(coloured.diagnostics, Not(HasSubstr("no texture")));
  const ir::Mesh& mesh = coloured.scene->object.mesh;
  ASSERT_EQ(mesh.colors.size(), mesh.positions.size());
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    EXPECT_EQ(mesh.colors[i],
              mesh.positions[i].z() > 0 ? Eigen::Vector3f(1, 0, 0) : Eigen::Vector3f(0, 0, 1));
  }
  const nlohmann::json ir = ir_to_json(*coloured.scene);
  EXPECT_EQ(ir["object"]["mesh"]["has_vertex_colors"], true);
  EXPECT_EQ(ir["object"]["mesh"]["vertex_colors"].size(), 3 * mesh.positions.size());

  text.insert(text.find("camera:"), "  surface: {color: [0.5, 0.5, 0.5], pattern: none}\n");
  Compiled painted = compile_text(text);
  ASSERT_TRUE(painted.scene) << painted.diagnostics;
  EXPECT_TRUE(painted.scene->object.mesh.colors.empty());
  EXPECT_THAT(painted.diagnostics, HasSubstr("no texture"));
}

TEST(Frontend, ManualFocusAndEffectsReachTheIr) {
  std::string text = kMinimalScene;
  text.insert(text.find("shots:"),
              "  focus: 75cm\n  effects: {noise: false, depth_of_field: off}\n"
              "  white_balance: 3200K\n  output: {format: png16}\n");
  Compiled compiled = compile_text(text);
  ASSERT_TRUE(compiled.scene) << compiled.diagnostics;
  const ir::Scene& scene = *compiled.scene;
  EXPECT_DOUBLE_EQ(scene.shots[0].focus_distance_m, 0.75);
  EXPECT_FALSE(scene.camera.effects.noise);
  EXPECT_FALSE(scene.camera.effects.depth_of_field);
  EXPECT_TRUE(scene.camera.effects.distortion);
  EXPECT_EQ(scene.camera.white_balance, ir::WhiteBalanceMode::kKelvin);
  EXPECT_EQ(scene.camera.format, ir::ImageFormat::kPng16);
}

TEST(Frontend, IrJsonCarriesGeometryAndLocations) {
  Compiled compiled = compile_text(kMinimalScene);
  ASSERT_TRUE(compiled.scene);
  nlohmann::json ir = ir_to_json(*compiled.scene);
  const auto& mesh = ir["object"]["mesh"];
  EXPECT_EQ(mesh["triangles"].size(), 3 * compiled.scene->object.mesh.triangles.size());
  EXPECT_EQ(mesh["positions"].size(), 3 * compiled.scene->object.mesh.positions.size());
  EXPECT_EQ(ir["shots"].size(), 12u);
  EXPECT_EQ(ir["shots"][3]["loc"]["line"], 11);
  EXPECT_EQ(ir["shots"][3]["loc"]["col"], 5);
  EXPECT_EQ(ir["camera"]["model_name"], "OPENCV");
  EXPECT_EQ(ir["camera"]["loc"]["line"], 7);
}

}  // namespace
}  // namespace rigc
