// `rigc new` (plan/starter_scene.h) on Spot, a textured scanned model in scenes/assets, through
// the command.
#include "plan/starter_scene.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/test_support.h"

namespace rigc::plan {
namespace {

namespace fs = std::filesystem;
using rigc::testing::run_rigc;
using rigc::testing::source_path;
using ::testing::HasSubstr;

const std::string kSpot = "scenes/assets/spot/spot.obj";

// The scene `rigc new` writes for Spot at 20 cm into `dir`.
std::string new_spot_scene(const rigc::testing::TempDir& dir) {
  const std::string scene = dir.file("spot.yaml");
  const auto made = run_rigc({"new", source_path(kSpot), "--height", "20cm", "-o", scene});
  EXPECT_EQ(made.exit_code, 0) << made.err;
  return scene;
}

// It checks with no warning, says why at each choice, and its shots are the planner's.
TEST(StarterScene, SpotChecksCleanWithEachChoiceExplained) {
  rigc::testing::TempDir dir;
  const std::string scene = new_spot_scene(dir);
  const auto check = run_rigc({"check", scene});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  EXPECT_THAT(check.out, HasSubstr("0 warnings"));
  const std::string text = rigc::testing::read_text(scene);
  EXPECT_THAT(text, HasSubstr("fills about 60 % of the frame"));
  EXPECT_THAT(text, HasSubstr("depth of field holds the object's"));
  EXPECT_THAT(text, HasSubstr("exposure advice"));
  EXPECT_THAT(text, HasSubstr("fit: {height: 20.0cm}"));
  EXPECT_THAT(text, HasSubstr("# Planned by `rigc plan`"));
  EXPECT_THAT(text, ::testing::Not(HasSubstr("pattern: speckle"))) << "Spot has its texture";
  // The coverage the plan promises: at least 90 % reconstructable.
  const auto coverage = run_rigc({"coverage", scene, "-o", dir.file("coverage")});
  ASSERT_EQ(coverage.exit_code, 0) << coverage.err;
  std::ifstream in(dir.path() / "coverage" / "coverage.json");
  const auto report = nlohmann::json::parse(in);
  EXPECT_GE(report["summary"]["reconstructable"].get<double>(), 0.89) << report["summary"];
}

TEST(StarterScene, BadInputsAreClearErrors) {
  rigc::testing::TempDir dir;
  auto r = run_rigc({"new", dir.file("none.obj"), "-o", dir.file("a.yaml")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("not a model file"));
  // A model in millimetres read as metres, with no --height.
  rigc::testing::write_text(dir.file("big.obj"),
                            "v 0 0 0\nv 50 0 0\nv 0 50 0\nv 0 0 50\n"
                            "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  r = run_rigc({"new", dir.file("big.obj"), "-o", dir.file("b.yaml")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--height"));
  EXPECT_FALSE(fs::exists(dir.file("b.yaml")));
  // An output that exists is not written over.
  rigc::testing::write_text(dir.file("c.yaml"), "mine\n");
  r = run_rigc({"new", source_path(kSpot), "--height", "20cm", "-o", dir.file("c.yaml")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(rigc::testing::read_text(dir.file("c.yaml")), "mine\n");
  r = run_rigc({"new", source_path(kSpot), "--lens", "fifty", "-o", dir.file("d.yaml")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--lens"));
  r = run_rigc({"new", source_path(kSpot), "--target", "95x", "-o", dir.file("e.yaml")});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--target"));
}

// The photos of the new scene, rendered by the preview, all register in COLMAP.
TEST(EvalEndToEnd, ANewScenesPhotosAllRegister) {
  rigc::testing::TempDir dir;
  const std::string scene = new_spot_scene(dir);
  const auto render =
      run_rigc({"render", scene, "--backend", "preview", "--scale", "0.25", "-o", dir.file("run")});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const auto eval = run_rigc({"eval", dir.file("run"), "-o", dir.file("eval")});
  ASSERT_EQ(eval.exit_code, 0) << eval.err;
  std::ifstream in(dir.path() / "eval" / "eval.json");
  const auto report = nlohmann::json::parse(in);
  const auto& rec = report["reconstruction"];
  EXPECT_EQ(rec["registered_images"].get<int>(), rec["images"].get<int>()) << rec;
}

}  // namespace
}  // namespace rigc::plan
