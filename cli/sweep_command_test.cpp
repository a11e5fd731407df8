// `rigc sweep` as a user runs it, with the local executor: variants, results, reruns, failures.
#include <gtest/gtest.h>

#include <filesystem>

#include "tests/test_support.h"

namespace rigc::cli {
namespace {

namespace fs = std::filesystem;
using testing::read_text;
using testing::run_rigc;
using testing::source_path;
using testing::TempDir;
using testing::write_text;

// The paper scene made small: a coarse statue, four shots.
std::string small_scene() {
  std::string text = read_text(source_path("scenes/paper-turntable.yaml"));
  const auto replace = [&](const std::string& from, const std::string& to) {
    text.replace(text.find(from), from.size(), to);
  };
  replace("detail: 6", "detail: 3");
  replace("steps: 18, step: 20deg", "steps: 4, step: 90deg");
  return text;
}

std::string sweep_file(const std::string& apertures) {
  return "rigc-sweep: 1\nscene: scene.yaml\nvary:\n  camera.exposure.aperture: [" + apertures +
         "]\n  shots[0].turntable.steps: [3, 4]\nscale: 0.05\nmeasure: [coverage]\n";
}

int count_lines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

TEST(CliSweep, RunsEveryVariantAndRerunsOnlyWhatChanged) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  write_text(dir.file("s.yaml"), sweep_file("f/4, f/16"));
  const std::string out = dir.file("out");
  auto first = run_rigc({"sweep", dir.file("s.yaml"), "-o", out});
  ASSERT_EQ(first.exit_code, 0) << first.err;
  EXPECT_NE(first.err.find("4 to run"), std::string::npos) << first.err;
  EXPECT_NE(first.err.find("4/4 done"), std::string::npos) << first.err;
  const std::string csv = read_text(out + "/results.csv");
  EXPECT_EQ(count_lines(csv), 5) << csv;
  EXPECT_NE(csv.find("aperture-f-16_steps-4,f/16,4,ok,"), std::string::npos) << csv;
  const std::string md = read_text(out + "/results.md");
  EXPECT_NE(md.find("Best variant: **"), std::string::npos) << md;
  EXPECT_TRUE(fs::exists(out + "/plots/reconstructable_pct_vs_camera.exposure.aperture.png"));
  // Each variant is an ordinary scene file with its run outputs beside it.
  const std::string variant = out + "/aperture-f-16_steps-3";
  EXPECT_NE(read_text(variant + "/scene.yaml").find("{aperture: f/16, shutter"), std::string::npos);
  EXPECT_TRUE(fs::exists(variant + "/images/shot_002.jpg"));
  EXPECT_FALSE(fs::exists(variant + "/images/shot_003.jpg"));
  EXPECT_TRUE(fs::exists(variant + "/coverage/coverage.json"));
  EXPECT_EQ(run_rigc({"check", variant + "/scene.yaml", "--no-advice"}).exit_code, 0);

  auto again = run_rigc({"sweep", dir.file("s.yaml"), "-o", out});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.err.find("0 to run (4 done already)"), std::string::npos) << again.err;
  EXPECT_EQ(read_text(out + "/results.csv"), csv);

  write_text(dir.file("s.yaml"), sweep_file("f/4, f/11"));
  auto changed = run_rigc({"sweep", dir.file("s.yaml"), "-o", out});
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  EXPECT_NE(changed.err.find("2 to run (2 done already)"), std::string::npos) << changed.err;
  EXPECT_NE(read_text(out + "/results.csv").find("f/11"), std::string::npos);
}

TEST(CliSweep, AFailingVariantIsReportedAndTheOthersComplete) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  const std::string out = dir.file("out");
  // A file where the variant's coverage folder goes: its coverage cannot be written.
  fs::create_directories(out + "/steps-3");
  write_text(out + "/steps-3/coverage", "in the way");
  auto result = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "shots[0].turntable.steps=3,4",
                          "--scale", "0.05", "-o", out});
  EXPECT_EQ(result.exit_code, 2) << result.err;
  EXPECT_NE(result.err.find("variant steps-3 failed: "), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("(log: " + out + "/steps-3/log.txt)"), std::string::npos) << result.err;
  const std::string csv = read_text(out + "/results.csv");
  EXPECT_NE(csv.find("steps-4,4,ok,"), std::string::npos) << csv;
  EXPECT_NE(csv.find("steps-3,3,failed,"), std::string::npos) << csv;
  EXPECT_NE(read_text(out + "/results.md").find("## Failed variants"), std::string::npos);
  auto status = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "shots[0].turntable.steps=3,4",
                          "--scale", "0.05", "-o", out, "--status"});
  EXPECT_NE(status.out.find("steps-4"), std::string::npos);
  EXPECT_NE(status.out.find("1/2 variants done"), std::string::npos) << status.out;
}

TEST(CliSweep, BadSweepsAreUserErrorsBeforeAnythingRuns) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  write_text(dir.file("s.yaml"), sweep_file("f/4, f/99"));
  auto bad_value = run_rigc({"sweep", dir.file("s.yaml"), "-o", dir.file("out")});
  EXPECT_EQ(bad_value.exit_code, 1);
  EXPECT_NE(bad_value.err.find(dir.file("s.yaml") + ":4:35: error: variant 'aperture-f-99_steps-3'"
                                                    " does not compile"),
            std::string::npos)
      << bad_value.err;
  EXPECT_NE(bad_value.err.find(dir.file("scene.yaml") + ":23:"), std::string::npos)
      << bad_value.err;
  EXPECT_FALSE(fs::exists(dir.file("out")));
  auto bad_vary = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "camera.nope=1,2"});
  EXPECT_EQ(bad_vary.exit_code, 1);
  EXPECT_NE(bad_vary.err.find("'camera' has no key 'nope'"), std::string::npos) << bad_vary.err;
  auto no_eq = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "camera.nope"});
  EXPECT_EQ(no_eq.exit_code, 1);
  EXPECT_NE(no_eq.err.find("is not PATH=V1,V2"), std::string::npos) << no_eq.err;
  auto no_scene = run_rigc({"sweep", dir.file("missing.yaml"), "--vary", "a=1"});
  EXPECT_EQ(no_scene.exit_code, 1);
  EXPECT_NE(no_scene.err.find("cannot read the scene file"), std::string::npos) << no_scene.err;
}

}  // namespace
}  // namespace rigc::cli
