#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc {
namespace {

using testing::run_rigc;
using testing::source_path;

TEST(Cli, CheckAcceptsThePaperScene) {
  auto result = run_rigc({"check", source_path("scenes/paper-turntable.yaml")});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("ok: 'paper-turntable', 18 shots"));
}

// `check --scale` judges the photos of a render at that scale: the paper scene at f/8 blurs 27 % of
// the statue beyond the advice's limit at full size, and 4x less in pixels at 0.25.
TEST(Cli, CheckAtARenderScaleJudgesThatScalesPixels) {
  std::string scene = testing::read_text(source_path("scenes/paper-turntable.yaml"));
  scene.replace(scene.find("aperture: f/13, shutter: 1/125"), 30, "aperture: f/8, shutter: 1/320");
  testing::TempDir dir;
  testing::write_text(dir.file("scene.yaml"), scene);
  auto full = run_rigc({"check", dir.file("scene.yaml")});
  EXPECT_EQ(full.exit_code, 0) << full.err;
  EXPECT_THAT(full.out + full.err, HasSubstr("depth of field at f/8 is shallower"));
  auto quarter = run_rigc({"check", dir.file("scene.yaml"), "--scale", "0.25"});
  EXPECT_EQ(quarter.exit_code, 0) << quarter.err;
  EXPECT_THAT(quarter.out + quarter.err, Not(HasSubstr("depth of field")));
  auto bad = run_rigc({"check", dir.file("scene.yaml"), "--scale", "0"});
  EXPECT_EQ(bad.exit_code, 1);
}

// The command itself (not only the libraries the tests link) reads meshes in every format:
// linking the system libraries in another order once let libdraco's copy of tinygltf's file
// functions take over, and every glTF scene failed with "FS callback not set".
TEST(Cli, CheckReadsGltfObjAndPlyMeshes) {
  const std::string gltf = "/usr/share/assimp/models/glTF2/BoxTextured-glTF/BoxTextured.gltf";
  auto result = run_rigc({"check", source_path("scenes/orbit-textured.yaml")});
  EXPECT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("(12 triangles"));
  std::ifstream in(source_path("scenes/orbit-textured.yaml"));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_THAT(text, HasSubstr(gltf));
  testing::TempDir dir;
  for (const std::string mesh :
       {"/usr/share/assimp/models/OBJ/box.obj", "/usr/share/assimp/models/PLY/cube.ply"}) {
    std::string scene = text;
    scene.replace(scene.find(gltf), gltf.size(), mesh);
    const std::string path = dir.file("scene.yaml");
    std::ofstream(path) << scene;
    result = run_rigc({"check", path});
    EXPECT_EQ(result.exit_code, 0) << mesh << ": " << result.err;
    EXPECT_THAT(result.out, HasSubstr("triangles"));
  }
}

TEST(Cli, CheckReportsErrorsWithExitCodeOne) {
  auto result = run_rigc({"check", source_path("tests/bad_scenes/out_of_range.yaml")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr(":8:24: error: aperture f/0.8 is outside f/1.2..f/64"));
  EXPECT_THAT(result.err, HasSubstr("4 errors in"));
}

TEST(Cli, CheckJsonListsDiagnostics) {
  auto result = run_rigc({"check", "--json", source_path("tests/bad_scenes/unknown_keys.yaml")});
  EXPECT_EQ(result.exit_code, 1);
  auto json = nlohmann::json::parse(result.out);
  EXPECT_FALSE(json["ok"].get<bool>());
  ASSERT_EQ(json["diagnostics"].size(), 3u);
  EXPECT_EQ(json["diagnostics"][0]["line"], 8);
}

// `--format json` is the editors' form: each advice carries the settings it suggests, with the
// values it works out.
TEST(Cli, CheckFormatJsonGivesTheAdvicesSuggestions) {
  testing::TempDir dir;
  std::string text = testing::read_text(source_path("scenes/paper-turntable.yaml"));
  // Six stops more light than the paper's exposure.
  text.replace(text.find("shutter: 1/125"), 14, "shutter: 1/2");
  const std::string path = dir.file("slow.yaml");
  std::ofstream(path) << text;
  auto result = run_rigc({"check", "--format", "json", path});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  bool valued = false;
  for (const auto& d : json["diagnostics"]) {
    EXPECT_EQ(d["file"], path);
    EXPECT_GT(d["line"].get<int>(), 0);
    ASSERT_TRUE(d.contains("suggestions")) << d.dump();
    for (const auto& change : d["suggestions"]) {
      EXPECT_THAT(std::string(change["setting"]),
                  ::testing::AnyOf("shutter", "f-number", "iso", "light"));
      valued = valued || change.contains("value");
    }
  }
  EXPECT_TRUE(valued) << result.out;
  EXPECT_EQ(run_rigc({"check", "--format", "yaml", path}).exit_code, 1);
}

TEST(Cli, MissingSceneFileIsAUserError) {
  auto result = run_rigc({"check", "/nonexistent/rig.yaml"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("/nonexistent/rig.yaml: error: cannot read the scene file"));
}

TEST(Cli, CompileEmitsIrJsonAtomically) {
  testing::TempDir dir;
  const std::string out = dir.file("paper.ir.json");
  auto result = run_rigc(
      {"compile", source_path("scenes/paper-turntable.yaml"), "--target", "ir", "-o", out});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  auto ir = nlohmann::json::parse(testing::read_text(out));
  EXPECT_EQ(ir["shots"].size(), 18u);
  EXPECT_EQ(ir["camera"]["width_px"], 5472);
  // Only the IR itself is left in the folder: no temporary file beside it.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    ++files;
    EXPECT_EQ(entry.path().filename(), "paper.ir.json");
  }
  EXPECT_EQ(files, 1);
  // An unwritable destination is a clear user error, with nothing left behind.
  auto bad = run_rigc({"compile", source_path("scenes/paper-turntable.yaml"), "-o",
                       dir.file("no/such/folder/ir.json")});
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.err, HasSubstr("cannot write"));
}

TEST(Cli, CompileRefusesToOverwriteTheSceneItself) {
  testing::TempDir dir;
  const std::string scene = dir.file("scene.yaml");
  const std::string text = testing::read_text(source_path("scenes/paper-turntable.yaml"));
  testing::write_text(scene, text);
  auto result = run_rigc({"compile", scene, "--target", "ir", "-o", dir.file("./scene.yaml")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("is the scene file itself"));
  EXPECT_EQ(testing::read_text(scene), text);
}

TEST(Cli, UnknownVerbAndTargetAreUserErrors) {
  auto verb = run_rigc({"chekc"});
  EXPECT_EQ(verb.exit_code, 1);
  EXPECT_THAT(verb.err, HasSubstr("did you mean 'check'?"));
  auto target =
      run_rigc({"compile", source_path("scenes/paper-turntable.yaml"), "--target", "vray"});
  EXPECT_EQ(target.exit_code, 1);
}

// CLI11's range checks let NaN through, and it reads "-1" into an unsigned seed as 2^64 - 1:
// every number a verb takes is checked to be finite and in range, with a message that says so.
TEST(Cli, NonFiniteAndNegativeNumbersAreUserErrors) {
  testing::TempDir dir;
  const std::string scene = source_path("scenes/paper-turntable.yaml");
  const std::string run = dir.file("run");
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{"render", scene, "-o", run, "--scale", "nan"}, "--scale: 'nan' is not a finite number"},
      {{"render", scene, "-o", run, "--backend", "povray", "--scale", "NaN"},
       "--scale: 'NaN' is not a finite number"},
      {{"render", scene, "-o", run, "--seed", "-1"}, "--seed: '-1' is negative: give 0 or more"},
      {{"render", scene, "-o", run, "--samples", "-2"},
       "--samples: '-2' is not a count 0..65536 or auto"},
      {{"compile", scene, "--target", "povray", "-o", run, "--samples", "-5"},
       "--samples: '-5' is not a count 0..65536 or auto"},
      {{"compile", scene, "--target", "povray", "-o", run, "--scale", "inf"},
       "--scale: 'inf' is not a finite number"},
      {{"coverage", scene, "-o", run, "--visibility-scale", "nan"},
       "--visibility-scale: 'nan' is not a finite number"},
      {{"coverage", scene, "-o", run, "--visibility-scale", "1e-9"},
       "--visibility-scale: '1e-9' is neither 0 (automatic) nor within 0.01..1"},
      {{"eval", run, "--tau", "nan"}, "--tau: 'nan' is not a finite number"},
      {{"eval", run, "--color-range", "-1"}, "--color-range: '-1' is not above 0"},
      {{"compare", scene, "-o", run, "--scale", "-nan"}, "is not a finite number"},
      // strtod reads hexadecimal: "0x1" was a scale of 1.
      {{"render", scene, "-o", run, "--scale", "0x1"}, "--scale: '0x1' is not a number"},
      {{"render", scene, "-o", run, "--scale", "0.5cm"}, "--scale: '0.5cm' is not a number"},
      // An empty selection (a shell variable that came out empty) is not "every shot".
      {{"render", scene, "-o", run, "--shots", ""}, "--shots: the shot selection is empty"},
  };
  for (const Case& c : cases) {
    auto result = run_rigc(c.args);
    EXPECT_EQ(result.exit_code, 1) << c.args[0] << " " << c.message << "\n" << result.err;
    EXPECT_THAT(result.err, HasSubstr(c.message));
    EXPECT_EQ(result.err.rfind("rigc: error: ", 0), 0u) << "like every error of rigc";
    EXPECT_FALSE(std::filesystem::exists(run)) << c.message;
  }
  // A backend named twice rendered and evaluated twice into one folder.
  auto twice = run_rigc({"compare", scene, "-o", run, "--backends", "preview,preview"});
  EXPECT_EQ(twice.exit_code, 1) << twice.err;
  EXPECT_THAT(twice.err, HasSubstr("--backends names 'preview' twice"));
  EXPECT_FALSE(std::filesystem::exists(run));
  // A seed of 0 and the largest one are seeds.
  auto largest = run_rigc({"render", scene, "-o", run, "--scale", "0.02", "--shots", "0", "--seed",
                           "18446744073709551615"});
  EXPECT_EQ(largest.exit_code, 0) << largest.err;
}

// Whether process `pid` has ended (gone, or a zombie waiting for init to reap it).
bool process_ended(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), std::istreambuf_iterator<char>());
  const std::size_t close = text.rfind(')');
  return text.empty() || close == std::string::npos || text.substr(close + 2, 1) == "Z";
}

// A SIGTERM to rigc alone (`kill`, `timeout`) left POV-Ray rendering on, into the folder that a
// rerun then rendered into too. Here a stand-in "povray" that records its pid and sleeps.
TEST(Cli, StoppingRigcStopsTheRendererItStarted) {
  testing::TempDir dir;
  std::filesystem::create_directories(dir.path() / "bin");
  const std::string pid_file = dir.file("povray.pid");
  const std::string fake = dir.file("bin/povray");
  testing::write_text(fake, "#!/bin/sh\necho $$ > '" + pid_file + "'\nexec sleep 60\n");
  std::filesystem::permissions(fake, std::filesystem::perms::owner_all);
  std::vector<std::string> args = {
      RIGC_BINARY, "render",       source_path("scenes/paper-turntable.yaml"),
      "--backend", "povray",       "--scale",
      "0.02",      "--shots",      "0",
      "-o",        dir.file("run")};
  std::vector<std::string> env = {"PATH=" + dir.file("bin") + ":/usr/bin:/bin",
                                  "HOME=" + dir.path().string()};
  std::vector<char*> argv, envp;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  for (auto& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t rigc = 0;
  ASSERT_EQ(posix_spawn(&rigc, argv[0], &actions, nullptr, argv.data(), envp.data()), 0);
  posix_spawn_file_actions_destroy(&actions);
  // Wait for the stand-in to start (scene preparation and emitting come first).
  pid_t renderer = 0;
  for (int i = 0; i < 600 && renderer <= 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::ifstream(pid_file) >> renderer;
  }
  ASSERT_GT(renderer, 0) << "the stand-in povray never started";
  ASSERT_FALSE(process_ended(renderer));
  kill(rigc, SIGTERM);
  int status = 0;
  ASSERT_EQ(waitpid(rigc, &status, 0), rigc);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM) << "rigc dies of the signal";
  bool ended = false;
  for (int i = 0; i < 50 && !ended; ++i) {
    ended = process_ended(renderer);
    if (!ended) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_TRUE(ended) << "the renderer rigc started still runs";
  if (!ended) kill(renderer, SIGKILL);
}

TEST(Cli, VersionAndHelp) {
  auto version = run_rigc({"version"});
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_THAT(version.out, HasSubstr("rigc "));
  auto help = run_rigc({"check", "--help"});
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_THAT(help.out, HasSubstr("--json"));
  auto top = run_rigc({"--help"});
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_THAT(top.out, HasSubstr("compile"));
  // The verbs under their tasks, the capture's planning after the photos.
  EXPECT_THAT(top.out, HasSubstr("plan the capture:\n  coverage"));
  EXPECT_LT(top.out.find("see its photos:"), top.out.find("plan the capture:"));
  EXPECT_THAT(top.out, HasSubstr("A start: rigc check"));
}

// scripts/completion.sh writes bash completion from rigc's help: verbs, a verb's options and
// the values an option lists.
TEST(Cli, BashCompletionIsMadeFromTheHelp) {
  testing::TempDir dir;
  const auto made =
      testing::run_process({"bash", source_path("scripts/completion.sh"), RIGC_BINARY});
  ASSERT_EQ(made.exit_code, 0) << made.err;
  testing::write_text(dir.file("rigc.bash"), made.out);
  const std::string script =
      "source " + dir.file("rigc.bash") +
      "; complete_of() { COMP_WORDS=(\"$@\"); COMP_CWORD=$(($# - 1)); _rigc; "
      "echo \"${COMPREPLY[*]}\"; }; complete_of rigc pl; complete_of rigc render --ba; "
      "complete_of rigc render --backend c; complete_of rigc new --hei";
  const auto completed = testing::run_process({"bash", "-c", script});
  ASSERT_EQ(completed.exit_code, 0) << completed.err;
  EXPECT_EQ(completed.out, "plan\n--backend\ncycles\n--height\n");
}

// docs/guide.md is written by scripts/guide.sh, which runs every command it shows: here into a
// folder of its own, comparing the preview alone (Cycles takes three minutes of it, POV-Ray five).
TEST(EvalEndToEnd, TheGuideRuns) {
  testing::TempDir dir;
  const auto guide = testing::run_process(
      {"env", std::string("RIGC=") + RIGC_BINARY, "GUIDE_REFERENCE=", "bash",
       source_path("scripts/guide.sh"), dir.file("out"), dir.file("guide.md")});
  ASSERT_EQ(guide.exit_code, 0) << guide.err;
  const std::string text = testing::read_text(dir.file("guide.md"));
  EXPECT_THAT(text, HasSubstr("$ rigc new scenes/assets/spot/spot.obj"));
  EXPECT_THAT(text, HasSubstr("0 warnings"));
  EXPECT_THAT(text, HasSubstr("| preview | 16 |"));
  EXPECT_THAT(text, HasSubstr("relative-pose AUC"));
  for (const char* picture : {"guide-preview.jpg", "guide-coverage.jpg", "guide-twin.jpg"}) {
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "guide" / picture)) << picture;
  }
}

TEST(Cli, RenderCommandRejectsBadShotSelection) {
  auto result = ::rigc::testing::run_rigc(
      {"render", ::rigc::testing::source_path("scenes/paper-turntable.yaml"), "--shots", "3,40",
       "-o", "/tmp/rigc-never-written"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("--shots"));
  EXPECT_FALSE(std::filesystem::exists("/tmp/rigc-never-written"));
}

// `rigc` runs check and version itself and the other verbs in rigc-all beside it: without it,
// those verbs say so, and check still works.
TEST(Cli, TheCoreBinaryNamesAMissingRigcAll) {
  testing::TempDir dir;
  const std::string core = dir.file("rigc");
  std::filesystem::copy_file(RIGC_BINARY, core);
  const auto check =
      testing::run_process({core, "check", source_path("scenes/paper-turntable.yaml")});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  const auto render = testing::run_process({core, "render", "x.yaml"});
  EXPECT_EQ(render.exit_code, 2);
  EXPECT_THAT(render.err, ::testing::HasSubstr("cannot start " + dir.file("rigc-all")));
}

}  // namespace
}  // namespace rigc
