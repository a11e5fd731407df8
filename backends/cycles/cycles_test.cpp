#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "backends/cycles/cycles_backend.h"
#include "backends/external/process.h"
#include "backends/povray/povray_backend.h"
#include "compiler/frontend.h"
#include "tests/test_support.h"

namespace rigc::cycles {
namespace {

namespace fs = std::filesystem;
using ::rigc::testing::read_text;
using ::rigc::testing::TempDir;

// A mesh file whose name would break out of any unescaped string in a script: quotes,
// backslashes, a newline and Python code.
const char* kHostileName = "a\"b\\c'd\n\"); import os; os.system(\"touch PWNED\") #.obj";

ir::Scene hostile_scene(const TempDir& dir) {
  const fs::path mesh = dir.path() / kHostileName;
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

bool pwned_anywhere(const fs::path& root) {
  for (const auto& entry : fs::recursive_directory_iterator(root)) {
    if (entry.path().filename() == "PWNED") return true;
  }
  return fs::exists("PWNED");
}

TEST(CyclesEmit, ScriptCarriesUserTextOnlyAsEscapedData) {
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  ASSERT_FALSE(scene.shots.empty());
  std::string error;
  ASSERT_TRUE(emit(scene, dir.path() / "cycles", 0.02, &error)) << error;
  const std::string script = read_text((dir.path() / "cycles" / "scene.py").string());
  // The hostile text never appears verbatim, and the script is valid Python.
  EXPECT_EQ(script.find("os.system(\"touch"), std::string::npos);
  const auto python = external::find_executable("python3");
  if (python) {
    const auto result = rigc::testing::run_process(
        {python->string(), "-c", "import ast, sys; ast.parse(open(sys.argv[1]).read())",
         (dir.path() / "cycles" / "scene.py").string()});
    EXPECT_EQ(result.exit_code, 0) << result.err;
  }
  EXPECT_TRUE(fs::exists(dir.path() / "cycles" / "geometry.bin"));
}

TEST(CyclesRun, HostileMeshPathRendersWithoutRunningAnything) {
  if (!external::find_executable("blender")) GTEST_SKIP() << "blender is not installed";
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  ASSERT_FALSE(scene.shots.empty());
  ReferenceOptions options;
  // The output folder is hostile too: Blender gets it only as an argument.
  options.output_dir = (dir.path() / "out \"'; touch PWNED #").string();
  options.scale = 0.02;
  options.samples = 2;
  std::ostringstream log;
  EXPECT_EQ(run(scene, options, log), 0) << log.str();
  EXPECT_TRUE(fs::exists(fs::path(options.output_dir) / "images" / "shot_000.jpg"));
  EXPECT_FALSE(pwned_anywhere(dir.path()));
}

TEST(PovrayRun, HostileMeshPathRendersWithoutRunningAnything) {
  if (!external::find_executable("povray")) GTEST_SKIP() << "povray is not installed";
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  ASSERT_FALSE(scene.shots.empty());
  ReferenceOptions options;
  options.output_dir = (dir.path() / "out \"'; touch PWNED #").string();
  options.scale = 0.02;
  options.samples = 1;
  std::ostringstream log;
  EXPECT_EQ(povray::run(scene, options, log), 0) << log.str();
  EXPECT_TRUE(fs::exists(fs::path(options.output_dir) / "masks" / "shot_000.png"));
  EXPECT_FALSE(pwned_anywhere(dir.path()));
}

TEST(CyclesRun, MissingExecutableNamesThePackage) {
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  setenv("PATH", (dir.path() / "empty").c_str(), 1);
  ReferenceOptions options;
  options.output_dir = (dir.path() / "out").string();
  std::ostringstream log;
  const int code = run(scene, options, log);
  setenv("PATH", saved.c_str(), 1);
  EXPECT_EQ(code, 2);
  EXPECT_NE(log.str().find("apt-get install blender"), std::string::npos) << log.str();
}

}  // namespace
}  // namespace rigc::cycles
