#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <sstream>

#include "backends/cycles/cycles_backend.h"
#include "backends/external/process.h"
#include "compiler/frontend.h"
#include "run/renderer_noise.h"
#include "run/run_loop.h"
#include "scene/studio_scene.h"
#include "tests/hostile_scene.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::cycles {
namespace {

namespace fs = std::filesystem;

// The run loop with this backend, as `rigc render` runs it.
int render_run(const ir::Scene& scene, const run::RunOptions& options, std::ostream& log,
               std::vector<run::ShotTiming>* timings = nullptr) {
  CyclesBackend backend;
  return run::run_backend(scene, backend, options, log, timings);
}

// The backend's scripts for the scene, as `rigc compile --target` writes them.
bool emit(const ir::Scene& scene, const fs::path& dir, double scale, std::string* error) {
  run::RenderSettings settings;
  settings.scale = scale;
  return CyclesBackend().emit(scene, scene::prepare_studio_scene(scene), dir, settings, error);
}
using ::rigc::testing::hostile_scene;
using ::rigc::testing::read_text;
using ::rigc::testing::source_path;
using ::rigc::testing::TempDir;

TEST(CyclesEmit, ScriptCarriesUserTextOnlyAsEscapedData) {
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  ASSERT_FALSE(scene.shots.empty());
  std::string error;
  ASSERT_TRUE(emit(scene, dir.path() / "cycles", 0.02, &error)) << error;
  const std::string script = read_text((dir.path() / "cycles" / "scene.py").string());
  // The hostile text never appears verbatim, and the script is valid Python.
  EXPECT_THAT(script, Not(HasSubstr("os.system(\"touch")));
  const auto python = external::find_executable("python3");
  if (python) {
    const auto result = rigc::testing::run_process(
        {python->string(), "-c", "import ast, sys; ast.parse(open(sys.argv[1]).read())",
         (dir.path() / "cycles" / "scene.py").string()});
    EXPECT_EQ(result.exit_code, 0) << result.err;
  }
  EXPECT_TRUE(fs::exists(dir.path() / "cycles" / "geometry.bin"));
}

// Direct light only reaches the script, and the shot keys: a run folder never mixes the two.
TEST(CyclesEmit, MaxBouncesReachTheScriptAndTheShotKey) {
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  CyclesBackend direct;
  direct.max_bounces = 0;
  run::RenderSettings settings;
  settings.scale = 0.02;
  std::string error;
  ASSERT_TRUE(direct.emit(scene, scene::prepare_studio_scene(scene), dir.path() / "direct",
                          settings, &error))
      << error;
  const std::string script = read_text((dir.path() / "direct" / "scene.py").string());
  EXPECT_THAT(script, HasSubstr(R"(\"max_bounces\":0)"));
  EXPECT_THAT(script, HasSubstr(R"(DATA["max_bounces"])"));
  EXPECT_EQ(CyclesBackend().options_key(), "");
  EXPECT_EQ(direct.options_key(), "max_bounces=0");
}

// Vertex colours reach Blender as a colour attribute of the object's mesh that its materials
// read in place of their base colour.
TEST(CyclesEmit, VertexColoursReachTheScript) {
  TempDir dir;
  ir::Scene scene = hostile_scene(dir);
  for (std::size_t i = 0; i < scene.object.mesh.positions.size(); ++i) {
    scene.object.mesh.colors.push_back({0.2f, 0.4f, 0.6f});
  }
  std::string error;
  ASSERT_TRUE(emit(scene, dir.path() / "cycles", 0.02, &error)) << error;
  const std::string script = read_text((dir.path() / "cycles" / "scene.py").string());
  EXPECT_THAT(script, HasSubstr(R"(\"vertex_colors\":true)"));
  EXPECT_THAT(script, HasSubstr(R"(\"vertex_colors\":false)")) << "the studio's";
  EXPECT_THAT(script, HasSubstr(R"(attribute.attribute_name = "RigcColor")"));
  // Four floats a vertex more in the geometry than without the colours.
  ir::Scene plain = scene;
  plain.object.mesh.colors.clear();
  ASSERT_TRUE(emit(plain, dir.path() / "plain", 0.02, &error)) << error;
  EXPECT_EQ(fs::file_size(dir.path() / "cycles" / "geometry.bin") -
                fs::file_size(dir.path() / "plain" / "geometry.bin"),
            4 * sizeof(float) * scene.object.mesh.positions.size());
}

TEST(CyclesRun, MissingExecutableNamesThePackage) {
  TempDir dir;
  const ir::Scene scene = hostile_scene(dir);
  const char* old = std::getenv("PATH");
  const std::string saved = old ? old : "";
  setenv("PATH", (dir.path() / "empty").c_str(), 1);
  run::RunOptions options;
  options.output_dir = (dir.path() / "out").string();
  std::ostringstream log;
  const int code = render_run(scene, options, log);
  setenv("PATH", saved.c_str(), 1);
  EXPECT_EQ(code, 2);
  EXPECT_THAT(log.str(), HasSubstr("apt-get install blender"));
}

// Shot 0 of the paper's scene rendered twice at 0.03, the renderer's seed changed.
dslr::RenderNoise noise_of_two_seeds(const ir::Scene& scene, int samples, const fs::path& dir) {
  CyclesBackend backend;
  run::RenderSettings settings;
  settings.scale = 0.03;
  settings.samples = samples;
  std::string error;
  const auto noise = run::measure_renderer_noise(scene, backend, settings, 0, dir, &error);
  EXPECT_TRUE(noise) << error;
  return noise.value_or(dslr::RenderNoise{});
}

TEST(CyclesRun, ConvergedSamplingHoldsItsNoiseToAQuarterOfTheSensors) {
  DiagnosticEngine diag;
  const auto scene = compile_scene_file(source_path("scenes/paper-turntable.yaml"), diag);
  ASSERT_TRUE(scene);
  TempDir dir;
  const dslr::RenderNoise converged =
      noise_of_two_seeds(*scene, run::kConvergedSamples, dir.path() / "auto");
  const dslr::RenderNoise fixed = noise_of_two_seeds(*scene, 16, dir.path() / "16");
  ASSERT_GT(converged.pixels, 500);
  EXPECT_LE(converged.ratio(), 0.25);
  // The measurement sees the noise it bounds: 16 samples a pixel are well above it.
  EXPECT_GT(fixed.ratio(), 0.5);
}

}  // namespace
}  // namespace rigc::cycles
