// A scene whose mesh path and name would break out of any unescaped string in a script or a
// shell: for the tests that prove no user text ever becomes code.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "compiler/frontend.h"
#include "tests/test_support.h"

namespace rigc::testing {

// A mesh file whose name would break out of any unescaped string in a script: quotes,
// backslashes, a newline and Python code.
inline const char* kHostileName = "a\"b\\c'd\n\"); import os; os.system(\"touch PWNED\") #.obj";

inline ir::Scene hostile_scene(const TempDir& dir) {
  const std::filesystem::path mesh = dir.path() / kHostileName;
  rigc::testing::write_text(mesh.string(),
                            "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\n"
                            "v 1 1 1\nv -1 1 1\nf 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\n"
                            "f 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  // YAML double-quoted escapes for the same name.
  const std::string yaml_name =
      "a\\\"b\\\\c'd\\n\\\"); import os; os.system(\\\"touch PWNED\\\") #.obj";
  const std::string text = R"(rigc: 1
name: "evil\"); import os; os.system(\"touch PWNED\") #"
object:
  mesh: ")" + yaml_name + R"("
  fit: {size: 10cm}
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/8, shutter: 1/60, iso: 400}
shots:
  - turntable: {steps: 1, step: 20deg, camera: {distance: 60cm, height: 10cm}}
)";
  DiagnosticEngine diag;
  std::string messages;
  diag.set_handler([&](const Diagnostic&, const std::string& m) { messages += m; });
  auto scene =
      compile_scene_text(text, (dir.path() / "scene.yaml").string(), dir.path().string(), diag);
  EXPECT_TRUE(scene) << messages;
  if (scene) {
    EXPECT_NE(scene->object.source.find("os.system"), std::string::npos);
  }
  return scene ? *scene : ir::Scene{};
}

inline bool pwned_anywhere(const std::filesystem::path& root) {
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root)) {
    if (entry.path().filename() == "PWNED") return true;
  }
  return std::filesystem::exists("PWNED");
}

}  // namespace rigc::testing
