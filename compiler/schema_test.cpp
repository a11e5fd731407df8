// The JSON Schema in schema/ and the compiler must accept the same language: every example scene
// is validated by a real JSON Schema validator (python3-jsonschema) and compiled; a scene the
// compiler rejects for its shape is rejected by the schema too.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "compiler/frontend.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc {
namespace {

namespace fs = std::filesystem;

testing::ProcessResult validate(const std::vector<std::string>& files) {
  std::vector<std::string> argv = {"/usr/bin/python3",
                                   testing::source_path("scripts/validate_scenes.py"),
                                   testing::source_path("schema/rigc.schema.json")};
  argv.insert(argv.end(), files.begin(), files.end());
  return testing::run_process(argv);
}

TEST(Schema, EveryExampleSceneIsValidAndCompiles) {
  std::vector<std::string> scenes;
  for (const auto& entry : fs::directory_iterator(testing::source_path("scenes"))) {
    if (entry.path().extension() == ".yaml") scenes.push_back(entry.path().string());
  }
  ASSERT_GE(scenes.size(), 3u);
  testing::ProcessResult result = validate(scenes);
  EXPECT_EQ(result.exit_code, 0) << result.out << result.err;
  for (const auto& scene : scenes) {
    EXPECT_THAT(result.out, HasSubstr(scene + ": valid"));
    DiagnosticEngine diag;
    rigc::testing::silence_diagnostics(diag);
    EXPECT_TRUE(compile_scene_file(scene, diag)) << scene;
  }
}

TEST(Schema, RejectsWhatTheCompilerRejectsForItsShape) {
  // Bad scenes whose errors are about the language's shape (keys, units, names) or about a range
  // the schema states (out_of_range.yaml's values are bare numbers), not about files, geometry
  // or ranges of quantities with units, which a schema cannot see.
  const std::vector<std::string> bad = {
      "unknown_keys.yaml",     "wrong_units.yaml",         "unknown_names.yaml",
      "missing_sections.yaml", "not_a_mapping.yaml",       "wrong_shapes.yaml",
      "out_of_range.yaml",     "pose_rotation.yaml",       "intrinsics_values.yaml",
      "intrinsics_size.yaml",  "intrinsics_with_body.yaml"};
  for (const auto& name : bad) {
    const std::string path = testing::source_path("tests/bad_scenes/" + name);
    testing::ProcessResult result = validate({path});
    EXPECT_EQ(result.exit_code, 1) << name << ": " << result.out << result.err;
    EXPECT_THAT(result.out, HasSubstr("invalid")) << name;
  }
}

// A real capture's cameras: poses by rotation (a matrix or a quaternion), a camera by its
// intrinsics with no lens.
TEST(Schema, AcceptsPosesByRotationAndCamerasByIntrinsics) {
  const std::string text = R"(rigc: 1
object: {primitive: sphere, fit: {height: 20cm}, surface: {pattern: speckle}}
camera:
  intrinsics: {width: 640, height: 480, fx: 1520.4, fy: 1525.9, cx: 302.3, cy: 246.9, pixel_pitch: 5um}
  exposure: {aperture: f/8, shutter: 1/125, iso: 200}
shots:
  - pose: {position: [0.31m, -0.62m, 1.07m],
           rotation: [[0.894427, 0.447214, 0], [0.135285, -0.270571, -0.953147], [-0.42626, 0.852521, -0.302507]]}
  - pose: {position: [0.31m, -0.62m, 1.07m], rotation: {quaternion: [0.57475, 0.785415, 0.185411, -0.13568]}, turntable: 30deg}
)";
  testing::TempDir dir;
  const std::string path = dir.file("twin.yaml");
  testing::write_text(path, text);
  testing::ProcessResult result = validate({path});
  EXPECT_EQ(result.exit_code, 0) << result.out << result.err;
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  EXPECT_TRUE(compile_scene_file(path, diag)) << messages;
}

}  // namespace
}  // namespace rigc
