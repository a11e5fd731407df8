// The JSON Schema in schema/ and the compiler must accept the same language: every example scene
// is validated by a real JSON Schema validator (python3-jsonschema) and compiled; a scene the
// compiler rejects for its shape is rejected by the schema too.
#include <gtest/gtest.h>

#include <filesystem>

#include "compiler/frontend.h"
#include "tests/test_support.h"

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
    EXPECT_NE(result.out.find(scene + ": valid"), std::string::npos) << result.out;
    DiagnosticEngine diag;
    diag.set_handler([](const Diagnostic&, const std::string&) {});
    EXPECT_TRUE(compile_scene_file(scene, diag)) << scene;
  }
}

TEST(Schema, RejectsWhatTheCompilerRejectsForItsShape) {
  // Bad scenes whose errors are about the language's shape (keys, units, names) or about a range
  // the schema states (out_of_range.yaml's values are bare numbers), not about files, geometry
  // or ranges of quantities with units, which a schema cannot see.
  const std::vector<std::string> bad = {
      "unknown_keys.yaml",  "wrong_units.yaml",  "unknown_names.yaml", "missing_sections.yaml",
      "not_a_mapping.yaml", "wrong_shapes.yaml", "out_of_range.yaml"};
  for (const auto& name : bad) {
    const std::string path = testing::source_path("tests/bad_scenes/" + name);
    testing::ProcessResult result = validate({path});
    EXPECT_EQ(result.exit_code, 1) << name << ": " << result.out << result.err;
    EXPECT_NE(result.out.find("invalid"), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace rigc
