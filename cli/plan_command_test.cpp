// `rigc plan` as a user runs it: the planned file, the report, the errors.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::cli {
namespace {

using testing::read_text;
using testing::run_rigc;
using testing::source_path;
using testing::TempDir;
using testing::write_text;

std::string small_paper_scene() {
  std::string text = read_text(source_path("scenes/paper-turntable.yaml"));
  const std::string detail = "detail: 6";
  text.replace(text.find(detail), detail.size(), "detail: 4");
  return text;
}

TEST(CliPlan, WritesThePlannedSceneBesideTheScene) {
  TempDir dir;
  write_text(dir.file("paper.yaml"), small_paper_scene());
  const auto result = run_rigc({"plan", dir.file("paper.yaml"), "--target", "85%",
                                "--visibility-scale", "0.15", "--rings", "20,40deg"});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("the scene's 18 shots reach"));
  const std::string planned = read_text(dir.file("paper-plan.yaml"));
  // Everything but the shots is the user's text, comments included.
  EXPECT_THAT(planned, HasSubstr("# Elinchrom D-Lite RX4 softboxes"));
  EXPECT_THAT(planned, HasSubstr("# Planned by `rigc plan`"));
  EXPECT_THAT(planned, Not(HasSubstr("steps: 18")));
  const auto check = run_rigc({"check", dir.file("paper-plan.yaml"), "--no-advice"});
  EXPECT_EQ(check.exit_code, 0) << check.err;
}

// plan registered only its scene file as an input: -o the scene's mesh wrote the plan over it.
TEST(CliPlan, NeverWritesOverTheScenesMesh) {
  TempDir dir;
  const std::string cube =
      "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
      "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\n"
      "f 3 8 7\nf 4 1 5\nf 4 5 8\n";
  write_text(dir.file("cube.obj"), cube);
  std::string text = small_paper_scene();
  const std::string primitive = "primitive: {shape: statue, detail: 4, seed: 7}";
  ASSERT_THAT(text, HasSubstr(primitive));
  text.replace(text.find(primitive), primitive.size(), "mesh: cube.obj");
  write_text(dir.file("s.yaml"), text);
  const auto result = run_rigc({"plan", dir.file("s.yaml"), "-o", dir.file("cube.obj"),
                                "--visibility-scale", "0.1", "--rings", "30deg"});
  EXPECT_THAT(result.err, HasSubstr("it is the scene's mesh, an input of this command"));
  EXPECT_EQ(read_text(dir.file("cube.obj")), cube);
}

TEST(CliPlan, BadRequestsAreUserErrors) {
  TempDir dir;
  write_text(dir.file("paper.yaml"), small_paper_scene());
  const std::string scene = dir.file("paper.yaml");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"plan", scene, "--target", "150%"}, "--target '150%'"},
      {{"plan", scene, "--target", "nan"}, "--target 'nan'"},
      {{"plan", scene, "--rings", "20,95deg"}, "--rings '95deg' is outside"},
      {{"plan", scene, "--distances", "1m,fast"}, "--distances 'fast'"},
      {{"plan", scene, "--azimuth-step", "0.1deg"}, "--azimuth-step"},
      {{"plan", scene, "--max-step", "1deg"}, "--max-step '1deg'"},
      {{"plan", scene, "-o", scene}, "is the scene itself"},
      {{"plan", scene, "-o", dir.file("no/such/folder/p.yaml")}, "does not exist"},
      {{"plan", dir.file("missing.yaml")}, "cannot read the scene file"},
  };
  for (const auto& [args, message] : cases) {
    const auto result = run_rigc(args);
    EXPECT_EQ(result.exit_code, 1) << args.back() << result.err;
    EXPECT_THAT(result.err, HasSubstr(message));
  }
  EXPECT_EQ(read_text(scene), small_paper_scene());
}

TEST(CliPlan, NextSuggestsOneShotAfterTheScenesOwn) {
  TempDir dir;
  write_text(dir.file("paper.yaml"), small_paper_scene());
  const auto result = run_rigc({"plan", dir.file("paper.yaml"), "--next", "--visibility-scale",
                                "0.15", "-o", dir.file("next.yaml")});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_THAT(result.out, HasSubstr("the next shot:"));
  const std::string planned = read_text(dir.file("next.yaml"));
  const size_t own = planned.find("  - turntable: {steps: 18, step: 20deg");
  const size_t suggested = planned.find("  # Suggested by `rigc plan --next`");
  ASSERT_NE(own, std::string::npos);
  ASSERT_NE(suggested, std::string::npos);
  EXPECT_LT(own, suggested);
  EXPECT_EQ(run_rigc({"check", dir.file("next.yaml"), "--no-advice"}).exit_code, 0);
}

TEST(CliPlan, AnUnreachableTargetExitsOneAndExplains) {
  TempDir dir;
  write_text(dir.file("paper.yaml"), small_paper_scene());
  const auto result = run_rigc({"plan", dir.file("paper.yaml"), "--target", "99.5%",
                                "--turntable-only", "--visibility-scale", "0.15"});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_THAT(result.out, HasSubstr("cannot be reached"));
}

}  // namespace
}  // namespace rigc::cli
