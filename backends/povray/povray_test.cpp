#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "backends/external/process.h"
#include "backends/external/script_text.h"
#include "backends/povray/povray_backend.h"
#include "compiler/frontend.h"
#include "run/run_loop.h"
#include "scene/studio_scene.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::povray {
namespace {

namespace fs = std::filesystem;

// The run loop with this backend, as `rigc render` runs it.
int render_run(const ir::Scene& scene, const run::RunOptions& options, std::ostream& log,
               std::vector<run::ShotTiming>* timings = nullptr) {
  PovrayBackend backend;
  return run::run_backend(scene, backend, options, log, timings);
}

// The backend's scripts for the scene, as `rigc compile --target` writes them.
bool emit(const ir::Scene& scene, const fs::path& dir, double scale, std::string* error) {
  run::RenderSettings settings;
  settings.scale = scale;
  return PovrayBackend().emit(scene, scene::prepare_studio_scene(scene), dir, settings, error);
}
using ::rigc::testing::read_text;
using ::rigc::testing::TempDir;

ir::Scene paper_scene() {
  DiagnosticEngine diag;
  auto scene = compile_scene_file(rigc::testing::source_path("scenes/paper-turntable.yaml"), diag);
  EXPECT_TRUE(scene);
  return scene ? *scene : ir::Scene{};
}

// Sets an environment variable for the lifetime of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (old_)
      setenv(name_, old_->c_str(), 1);
    else
      unsetenv(name_);
  }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

// POV-Ray samples deterministically, so no converged setting is measured for it yet: asking for
// one is an error, not a silent default.
TEST(PovrayEmit, ConvergedSamplingIsRefusedWithAReason) {
  run::RenderSettings settings;
  settings.samples = run::kConvergedSamples;
  std::string error;
  EXPECT_FALSE(PovrayBackend().check_settings(settings, &error));
  EXPECT_THAT(error, HasSubstr("POV-Ray has no converged sampling"));
  settings.samples = 16;
  EXPECT_TRUE(PovrayBackend().check_settings(settings, &error));
}

TEST(PovrayEmit, WritesSceneAndOneIniPerShot) {
  const ir::Scene scene = paper_scene();
  TempDir dir;
  std::string error;
  ASSERT_TRUE(emit(scene, dir.path() / "pov", 0.05, &error)) << error;
  const std::string inc = read_text((dir.path() / "pov" / "scene.inc").string());
  EXPECT_THAT(inc, HasSubstr("#declare RigcObject = mesh2 {"));
  EXPECT_THAT(inc, HasSubstr("uv_vectors"));
  EXPECT_THAT(inc, HasSubstr("area_light"));
  EXPECT_THAT(inc, HasSubstr("rigc_speckle(x, y, z"));  // the speckle pattern
  for (const auto& shot : scene.shots) {
    EXPECT_TRUE(fs::exists(dir.path() / "pov" / (shot.name + ".pov")));
    EXPECT_TRUE(fs::exists(dir.path() / "pov" / (shot.name + "_mask.ini")));
    const std::string ini = read_text((dir.path() / "pov" / (shot.name + ".ini")).string());
    EXPECT_THAT(ini, HasSubstr("Output_File_Type=E"));
  }
  const std::string pov = read_text((dir.path() / "pov" / "shot_000.pov").string());
  EXPECT_THAT(pov, HasSubstr("aperture"));  // f-number mapped to focal blur
  EXPECT_THAT(pov, HasSubstr("focal_point"));
}

// The object's highlight peaks as the preview's GGX lobe does with light and view along the
// normal: F0 · D(1) / 4 · E, D(1) = 1 / (π α²), α = roughness², so POV's specular (which adds
// specular · E/π at the peak) is F0 / (4 α²); its width is the lobe's (exponent 2/α² - 2).
TEST(PovrayEmit, HighlightPeaksAsThePreviewsGgxLobe) {
  const ir::Scene scene = paper_scene();
  TempDir dir;
  std::string error;
  ASSERT_TRUE(emit(scene, dir.path() / "pov", 0.05, &error)) << error;
  const std::string inc = read_text((dir.path() / "pov" / "scene.inc").string());
  const double roughness = static_cast<float>(scene.materials[0].roughness);  // as shaded
  const double alpha = roughness * roughness;
  ASSERT_GT(alpha, 0.05);  // above POV's clamp
  const std::string finish =
      fmt::format("specular {} roughness {}", external::number_text(0.04 / (4 * alpha * alpha)),
                  external::number_text(1 / (2 / (alpha * alpha) - 2)));
  EXPECT_THAT(inc, HasSubstr(finish)) << finish;
  // The highlight of an area light comes from its whole panel, as Cycles' does.
  EXPECT_THAT(inc, HasSubstr("area_illumination on"));
}

// Vertex colours become a texture per colour, made by the material's macro, and each face names
// the textures of its three corners, which POV-Ray interpolates.
TEST(PovrayEmit, VertexColoursBecomeInterpolatedVertexTextures) {
  ir::Scene scene = paper_scene();
  ir::Mesh& mesh = scene.object.mesh;
  const Eigen::Vector3f palette[3] = {{0.8f, 0.1f, 0.1f}, {0.1f, 0.8f, 0.1f}, {0.1f, 0.1f, 0.8f}};
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) mesh.colors.push_back(palette[i % 3]);
  TempDir dir;
  std::string error;
  ASSERT_TRUE(emit(scene, dir.path() / "pov", 0.05, &error)) << error;
  const std::string inc = read_text((dir.path() / "pov" / "scene.inc").string());
  EXPECT_THAT(inc, HasSubstr("#macro RigcVertexTexture0(RigcColor)"));
  EXPECT_THAT(inc, Not(HasSubstr("#declare RigcMaterial0 =")))
      << "the object's material is the macro alone";
  EXPECT_THAT(inc, HasSubstr("#declare RigcMaterial1 =")) << "the studio's stay";
  const auto object = inc.find("#declare RigcObject = mesh2 {");
  ASSERT_NE(object, std::string::npos);
  EXPECT_NE(inc.find("texture_list { 3,\n    RigcVertexTexture0(<0.8, 0.1, 0.1>)", object),
            std::string::npos);
  const auto& t = mesh.triangles[0];
  EXPECT_NE(inc.find(fmt::format("<{}, {}, {}>, 0, ", t[0], t[1], t[2]), object), std::string::npos)
      << "the first face names a texture per corner";
}

TEST(PovrayEmit, AnEmitWithFewerShotsRemovesOnlyTheFilesOfTheShotsItNoLongerHas) {
  ir::Scene scene = paper_scene();
  ASSERT_EQ(scene.shots.size(), 18u);
  TempDir dir;
  const fs::path out = dir.path() / "pov";
  std::string error;
  ASSERT_TRUE(emit(scene, out, 0.05, &error)) << error;
  EXPECT_TRUE(fs::exists(out / "shot_017.ini"));
  // The user's own files in the folder stay, whatever their names.
  fs::create_directories(out);
  std::ofstream(out / "notes.ini") << "mine\n";
  std::ofstream(out / "shot_099.pov") << "mine\n";
  scene.shots.resize(4);
  ASSERT_TRUE(emit(scene, out, 0.05, &error)) << error;
  for (int i = 0; i < 18; ++i) {
    const std::string stem = fmt::format("shot_{:03d}", i);
    for (const char* suffix : {".pov", ".ini", "_mask.ini"}) {
      EXPECT_EQ(fs::exists(out / (stem + suffix)), i < 4) << stem << suffix;
    }
  }
  EXPECT_TRUE(fs::exists(out / "notes.ini"));
  EXPECT_TRUE(fs::exists(out / "shot_099.pov"));
  EXPECT_EQ(read_text((out / "rigc-shots.txt").string()),
            "shot_000\nshot_001\nshot_002\nshot_003\n");
}

TEST(PovrayEmit, TurningTableGetsMotionBlurSubframes) {
  DiagnosticEngine diag;
  auto scene = compile_scene_text(R"(rigc: 1
object:
  primitive: sphere
  fit: {size: 20cm}
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/8, shutter: 1/15, iso: 400}
shots:
  - turntable: {steps: 2, step: 90deg, speed: 30deg/s, camera: {distance: 60cm, height: 10cm}}
)",
                                  "test.yaml", ".", diag);
  ASSERT_TRUE(scene);
  TempDir dir;
  std::string error;
  ASSERT_TRUE(emit(*scene, dir.path(), 0.1, &error)) << error;
  const std::string ini = read_text((dir.path() / "shot_000.ini").string());
  EXPECT_THAT(ini, HasSubstr("Initial_Frame=1"));
  EXPECT_THAT(ini, HasSubstr("Final_Frame="));
  const std::string pov = read_text((dir.path() / "shot_000.pov").string());
  EXPECT_THAT(pov, HasSubstr("RigcDelta = 0.0349"));  // 30 deg/s over 1/15 s
}

TEST(PovrayRun, MissingExecutableNamesThePackage) {
  const ir::Scene scene = paper_scene();
  TempDir dir;
  ScopedEnv path("PATH", (dir.path() / "empty").string());
  run::RunOptions options;
  options.output_dir = (dir.path() / "out").string();
  options.settings.scale = 0.01;
  std::ostringstream log;
  EXPECT_EQ(render_run(scene, options, log), 2);
  EXPECT_THAT(log.str(), HasSubstr("apt-get install povray"));
}

// A povray that fails for shot_001 (a wrapper in front of the real one): the run names the shot
// and its log, finishes the others and exits 2; the rerun renders only the failed shot.
TEST(PovrayRun, FailedShotIsNamedAndRerunRendersOnlyIt) {
  const auto real = external::find_executable("povray");
  RIGC_REQUIRE_TOOL(real, "povray");
  ir::Scene scene = paper_scene();
  scene.camera.effects.depth_of_field = false;
  TempDir dir;
  fs::create_directories(dir.path() / "bin");
  const fs::path wrapper = dir.path() / "bin" / "povray";
  rigc::testing::write_text(wrapper.string(),
                            "#!/bin/sh\ncase \"$1\" in shot_001*) echo broken >&2; exit 7;; esac\n"
                            "exec " +
                                real->string() + " \"$@\"\n");
  fs::permissions(wrapper, fs::perms::owner_all);
  run::RunOptions options;
  options.output_dir = (dir.path() / "out").string();
  options.settings.scale = 0.012;
  options.settings.samples = 1;
  options.shots = {0, 1};
  {
    ScopedEnv path("PATH", (dir.path() / "bin").string() + ":" + std::getenv("PATH"));
    std::ostringstream log;
    EXPECT_EQ(render_run(scene, options, log), 2);
    EXPECT_THAT(log.str(), HasSubstr("shot_001: povray shot_001.ini failed with exit code 7"));
    EXPECT_THAT(log.str(), HasSubstr("render/shot_001.log"));
    EXPECT_TRUE(fs::exists(dir.path() / "out" / "images" / "shot_000.jpg"));
    EXPECT_FALSE(fs::exists(dir.path() / "out" / "images" / "shot_001.jpg"));
  }
  std::ostringstream log;
  std::vector<run::ShotTiming> timings;
  EXPECT_EQ(render_run(scene, options, log, &timings), 0) << log.str();
  ASSERT_EQ(timings.size(), 2u);
  EXPECT_TRUE(timings[0].skipped);
  EXPECT_FALSE(timings[1].skipped);
  for (const char* file : {"images/shot_001.jpg", "masks/shot_001.png", "sparse/images.txt",
                           "transforms.json", "manifest.json"}) {
    EXPECT_TRUE(fs::exists(dir.path() / "out" / file)) << file;
  }
}

}  // namespace
}  // namespace rigc::povray
