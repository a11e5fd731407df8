// `rigc sweep` as a user runs it, with the local executor: variants, results, reruns, failures.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "tests/test_support.h"

using ::testing::HasSubstr;

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
  EXPECT_THAT(first.err, HasSubstr("4 to run"));
  EXPECT_THAT(first.err, HasSubstr("4/4 done"));
  const std::string csv = read_text(out + "/results.csv");
  EXPECT_EQ(count_lines(csv), 5) << csv;
  EXPECT_THAT(csv, HasSubstr("aperture-f-16_steps-4,f/16,4,ok,"));
  const std::string md = read_text(out + "/results.md");
  EXPECT_THAT(md, HasSubstr("Best variant: **"));
  EXPECT_TRUE(fs::exists(out + "/plots/reconstructable_pct_vs_camera.exposure.aperture.png"));
  // Each variant is an ordinary scene file with its run outputs beside it.
  const std::string variant = out + "/aperture-f-16_steps-3";
  EXPECT_THAT(read_text(variant + "/scene.yaml"), HasSubstr("{aperture: f/16, shutter"));
  EXPECT_TRUE(fs::exists(variant + "/images/shot_002.jpg"));
  EXPECT_FALSE(fs::exists(variant + "/images/shot_003.jpg"));
  EXPECT_TRUE(fs::exists(variant + "/coverage/coverage.json"));
  EXPECT_EQ(run_rigc({"check", variant + "/scene.yaml", "--no-advice"}).exit_code, 0);

  auto again = run_rigc({"sweep", dir.file("s.yaml"), "-o", out});
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.err, HasSubstr("0 to run (4 done already)"));
  EXPECT_EQ(read_text(out + "/results.csv"), csv);

  write_text(dir.file("s.yaml"), sweep_file("f/4, f/11"));
  auto changed = run_rigc({"sweep", dir.file("s.yaml"), "-o", out});
  ASSERT_EQ(changed.exit_code, 0) << changed.err;
  EXPECT_THAT(changed.err, HasSubstr("2 to run (2 done already)"));
  EXPECT_THAT(read_text(out + "/results.csv"), HasSubstr("f/11"));
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
  EXPECT_THAT(result.err, HasSubstr("variant steps-3 failed: "));
  EXPECT_THAT(result.err, HasSubstr("(log: " + out + "/steps-3/log.txt)"));
  const std::string csv = read_text(out + "/results.csv");
  EXPECT_THAT(csv, HasSubstr("steps-4,4,ok,"));
  EXPECT_THAT(csv, HasSubstr("steps-3,3,failed,"));
  EXPECT_THAT(read_text(out + "/results.md"), HasSubstr("## Failed variants"));
  auto status = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "shots[0].turntable.steps=3,4",
                          "--scale", "0.05", "-o", out, "--status"});
  EXPECT_THAT(status.out, HasSubstr("steps-4"));
  EXPECT_THAT(status.out, HasSubstr("1/2 variants done"));
}

// The sweep's samples reach each variant's render, which records them in its manifest (POV-Ray:
// the preview takes none).
TEST(CliSweepPovray, SamplesReachEachVariantsRender) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  const std::string out = dir.file("out");
  auto result = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "shots[0].turntable.steps=3",
                          "--backend", "povray", "--scale", "0.05", "--samples", "3", "-o", out});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto manifest = nlohmann::json::parse(read_text(out + "/steps-3/manifest.json"));
  EXPECT_EQ(manifest.at("inputs").at("samples"), 3) << manifest.dump();
}

// sweep registered no inputs: a scene file named like one of its outputs was written over.
TEST(CliSweep, NeverWritesOverItsInputs) {
  TempDir dir;
  const std::string out = dir.file("out");
  fs::create_directories(out);
  write_text(out + "/results.md", small_scene());
  const auto status =
      run_rigc({"sweep", out + "/results.md", "--vary", "shots[0].turntable.steps=3,4", "--scale",
                "0.05", "-o", out, "--status"});
  EXPECT_NE(status.exit_code, 0);
  EXPECT_THAT(status.err, HasSubstr("it is the scene file, an input of this command"));
  EXPECT_EQ(read_text(out + "/results.md"), small_scene());
}

TEST(CliSweep, BadSweepsAreUserErrorsBeforeAnythingRuns) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  write_text(dir.file("s.yaml"), sweep_file("f/4, f/99"));
  auto bad_value = run_rigc({"sweep", dir.file("s.yaml"), "-o", dir.file("out")});
  EXPECT_EQ(bad_value.exit_code, 1);
  EXPECT_THAT(bad_value.err,
              HasSubstr(dir.file("s.yaml") + ":4:35: error: variant 'aperture-f-99_steps-3'"
                                             " does not compile"));
  EXPECT_THAT(bad_value.err, HasSubstr(dir.file("scene.yaml") + ":23:"));
  EXPECT_FALSE(fs::exists(dir.file("out")));
  auto bad_vary = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "camera.nope=1,2"});
  EXPECT_EQ(bad_vary.exit_code, 1);
  EXPECT_THAT(bad_vary.err, HasSubstr("'camera' has no key 'nope'"));
  auto no_eq = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "camera.nope"});
  EXPECT_EQ(no_eq.exit_code, 1);
  EXPECT_THAT(no_eq.err, HasSubstr("is not PATH=V1,V2"));
  auto no_scene = run_rigc({"sweep", dir.file("missing.yaml"), "--vary", "a=1"});
  EXPECT_EQ(no_scene.exit_code, 1);
  EXPECT_THAT(no_scene.err, HasSubstr("cannot read the scene file"));
}

// A sweep file named like a table the sweep writes at the end is refused before any variant runs.
TEST(CliSweep, ASweepFileInTheTablesPlaceIsRefusedBeforeAnythingRuns) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  const std::string out = dir.file("out");
  fs::create_directories(out);
  const std::string sweep =
      "rigc-sweep: 1\nscene: ../scene.yaml\nvary:\n"
      "  shots[0].turntable.steps: [3, 4]\nscale: 0.05\n"
      "measure: [coverage]\n";
  write_text(out + "/results.md", sweep);
  const auto r = run_rigc({"sweep", out + "/results.md", "-o", out});
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_THAT(r.err, HasSubstr("it is the sweep file, an input of this command"));
  EXPECT_EQ(read_text(out + "/results.md"), sweep);
  EXPECT_FALSE(fs::exists(out + "/steps-3"));
}

// The scene is read by the front end: a device, a file past the scene limit, or nesting past the
// language's depth is refused at once, at its line where it has one.
TEST(CliSweep, AScenePastTheLanguagesBoundsIsRefusedAtItsLine) {
  TempDir dir;
  const auto sweep_of = [&](const std::string& scene) {
    return run_rigc({"sweep", scene, "--vary", "camera.exposure.iso=100,200", "-o", dir.file("out"),
                     "--status"});
  };
  auto r = sweep_of("/dev/zero");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("is not a regular file"));
  write_text(dir.file("big.yaml"), small_scene() + std::string(17 << 20, '#'));
  r = sweep_of(dir.file("big.yaml"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("larger than 16 MB"));
  write_text(dir.file("deep.yaml"), "rigc: 1\nname: deep\nobject: " + std::string(100000, '[') +
                                        std::string(100000, ']') + "\n");
  r = sweep_of(dir.file("deep.yaml"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("deep.yaml:3:"));
  EXPECT_THAT(r.err, HasSubstr("nest deeper than"));
  EXPECT_FALSE(fs::exists(dir.file("out")));
}

// `--vary backend=...` is the renderers' axis, as `--backend a,b` is; both at once are refused.
TEST(CliSweep, VaryingTheBackendIsTheBackendsAxis) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  auto r = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "backend=preview,povray", "-o",
                     dir.file("out"), "--status"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir.file("out/backend-preview")));
  EXPECT_TRUE(fs::exists(dir.file("out/backend-povray")));
  r = run_rigc({"sweep", dir.file("scene.yaml"), "--vary", "backend=preview,povray", "--backend",
                "cycles", "-o", dir.file("out2"), "--status"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("the renderers are given twice"));
}

// `--backend` on a sweep file runs only that backend's variants (the fast half first); the others
// stay to run, and a backend the sweep does not render is an error.
TEST(CliSweep, ABackendOnASweepFileRunsOnlyItsVariants) {
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  write_text(dir.file("sweep.yaml"),
             "rigc-sweep: 1\nscene: scene.yaml\nvary:\n  camera.exposure.aperture: [f/8]\n"
             "backend: [preview, povray]\nscale: 0.05\n");
  auto r =
      run_rigc({"sweep", dir.file("sweep.yaml"), "-o", dir.file("out"), "--backend", "preview"});
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_THAT(r.err, HasSubstr("1 to run (0 done already, 1 of other backends left out)"));
  EXPECT_TRUE(fs::exists(dir.file("out/aperture-f-8_backend-preview/result.json")));
  EXPECT_FALSE(fs::exists(dir.file("out/aperture-f-8_backend-povray/result.json")));
  r = run_rigc({"sweep", dir.file("sweep.yaml"), "-o", dir.file("out"), "--status"});
  EXPECT_THAT(r.out, HasSubstr("1/2 variants done"));
  r = run_rigc({"sweep", dir.file("sweep.yaml"), "-o", dir.file("out"), "--backend", "cycles"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_THAT(r.err, HasSubstr("--backend: the sweep renders nothing with 'cycles'"));
}

// True when a Slurm cluster answers (scripts/slurm_cluster.sh start; its slurm.conf is used when
// SLURM_CONF is not set).
bool slurm_cluster_up() {
  const char* default_conf = "/tmp/rigc-slurm/slurm.conf";
  if (!std::getenv("SLURM_CONF") && fs::exists(default_conf)) setenv("SLURM_CONF", default_conf, 1);
  return testing::run_process({"sinfo", "-h"}).exit_code == 0;
}

// The first Slurm task of the sweep in `out` seen running ("123_4"), polled for up to a minute.
std::string first_running_task(const std::string& out) {
  for (int i = 0; i < 600; ++i) {
    const auto queue = testing::run_process({"squeue", "-h", "-r", "-t", "RUNNING", "-o", "%i %o"});
    std::istringstream lines(queue.out);
    for (std::string id, command; lines >> id >> command;) {
      if (command.starts_with(out + "/")) return id;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return "";
}

TEST(CliSweepSlurm, AJobArrayGivesTheSameResultsAsTheLocalExecutor) {
  RIGC_REQUIRE_TOOL(slurm_cluster_up(), "a Slurm cluster (bash scripts/slurm_cluster.sh start)");
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  write_text(dir.file("s.yaml"), sweep_file("f/4, f/16"));
  auto local = run_rigc({"sweep", dir.file("s.yaml"), "-o", dir.file("local")});
  ASSERT_EQ(local.exit_code, 0) << local.err;
  auto slurm = run_rigc({"sweep", dir.file("s.yaml"), "-o", dir.file("slurm"), "--executor",
                         "slurm", "--cpus-per-task", "1", "--time", "10:00"});
  ASSERT_EQ(slurm.exit_code, 0) << slurm.err;
  EXPECT_THAT(slurm.err, HasSubstr("submitted job array"));
  EXPECT_THAT(slurm.err, HasSubstr("4/4 tasks done"));
  EXPECT_EQ(read_text(dir.file("slurm") + "/results.csv"),
            read_text(dir.file("local") + "/results.csv"));
  auto status = run_rigc({"sweep", dir.file("s.yaml"), "-o", dir.file("slurm"), "--status"});
  EXPECT_THAT(status.out, HasSubstr("4/4 variants done"));
}

TEST(CliSweepSlurm, AKilledTaskIsReportedAndRetryFailedCompletesIt) {
  RIGC_REQUIRE_TOOL(slurm_cluster_up(), "a Slurm cluster (bash scripts/slurm_cluster.sh start)");
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  const std::vector<std::string> sweep = {"sweep",      dir.file("scene.yaml"),
                                          "--vary",     "shots[0].turntable.steps=3,4",
                                          "--scale",    "0.05",
                                          "-o",         dir.file("out"),
                                          "--executor", "slurm"};
  testing::ProcessResult waiting;
  std::thread runner([&] { waiting = run_rigc(sweep); });
  const std::string task = first_running_task(dir.file("out"));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const int cancelled = testing::run_process({"scancel", task}).exit_code;
  runner.join();
  ASSERT_FALSE(task.empty()) << waiting.err;
  ASSERT_EQ(cancelled, 0);
  EXPECT_EQ(waiting.exit_code, 2) << waiting.err;
  EXPECT_THAT(waiting.err, HasSubstr("failed (job " + task + "): Slurm: CANCELLED"));
  EXPECT_THAT(waiting.err, HasSubstr(dir.file("out") + "/slurm/" + task + ".log"));

  std::vector<std::string> retry = sweep;
  retry.push_back("--retry-failed");
  auto retried = run_rigc(retry);
  ASSERT_EQ(retried.exit_code, 0) << retried.err;
  EXPECT_THAT(retried.err, HasSubstr("1 to submit"));
  EXPECT_THAT(retried.out, HasSubstr("2/2 variants with results"));
}

TEST(CliSweepSlurm, ABadSbatchOptionIsAClearError) {
  RIGC_REQUIRE_TOOL(slurm_cluster_up(), "a Slurm cluster (bash scripts/slurm_cluster.sh start)");
  TempDir dir;
  write_text(dir.file("scene.yaml"), small_scene());
  const std::vector<std::string> sweep = {
      "sweep", dir.file("scene.yaml"), "--vary",     "shots[0].turntable.steps=3,4",
      "-o",    dir.file("out"),        "--executor", "slurm"};
  auto args = sweep;
  args.push_back("--sbatch=--no-such-option");
  auto bad = run_rigc(args);
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.err, HasSubstr("rigc: error: sbatch refused the job array"));
  EXPECT_THAT(bad.err, HasSubstr("no-such-option"));
  args = sweep;
  args.insert(args.end(), {"--partition", "nosuch"});
  auto partition = run_rigc(args);
  EXPECT_EQ(partition.exit_code, 1);
  EXPECT_THAT(partition.err, HasSubstr("nvalid partition"));
  args = sweep;
  args.push_back("--sbatch=--output=/tmp/x");
  auto own = run_rigc(args);
  EXPECT_EQ(own.exit_code, 1);
  EXPECT_THAT(own.err, HasSubstr("is rigc's own"));
}

// A run's outputs (images, masks, ground truth), relative to it; not the renderer's own scripts
// and logs (render/), the manifest's timings or the Slurm parts.
std::vector<std::string> run_files(const fs::path& run) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(run)) {
    const std::string relative = fs::relative(e.path(), run).string();
    if (e.is_regular_file() && !relative.starts_with(".") && !relative.starts_with("render/") &&
        relative != "manifest.json") {
      files.push_back(relative);
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

TEST(CliSweepSlurm, ACyclesRenderSplitOverSlurmIsByteIdenticalToALocalOne) {
  RIGC_REQUIRE_TOOL(slurm_cluster_up(), "a Slurm cluster (bash scripts/slurm_cluster.sh start)");
  RIGC_REQUIRE_TOOL(testing::run_process({"blender", "--version"}).exit_code == 0, "Blender");
  TempDir dir;
  std::string scene = small_scene();
  scene.replace(scene.find("steps: 4, step: 90deg"), 21, "steps: 6, step: 60deg");
  write_text(dir.file("scene.yaml"), scene);
  const std::vector<std::string> render = {
      "render", dir.file("scene.yaml"), "--backend", "cycles", "--scale", "0.05", "--samples", "4"};
  auto args = render;
  args.insert(args.end(), {"-o", dir.file("local")});
  auto local = run_rigc(args);
  ASSERT_EQ(local.exit_code, 0) << local.err;
  args = render;
  args.insert(args.end(), {"-o", dir.file("slurm"), "--executor", "slurm"});
  auto slurm = run_rigc(args);
  ASSERT_EQ(slurm.exit_code, 0) << slurm.err;
  EXPECT_THAT(slurm.err, HasSubstr("submitted job array"));
  EXPECT_THAT(slurm.err, HasSubstr("6/6 shots done"));
  const auto files = run_files(dir.file("local"));
  ASSERT_EQ(files, run_files(dir.file("slurm")));
  EXPECT_GE(files.size(), 15u);  // 6 images, 6 masks, sparse/, transforms.json
  for (const std::string& f : files) {
    EXPECT_EQ(read_text(dir.file("slurm") + "/" + f), read_text(dir.file("local") + "/" + f)) << f;
  }
}

}  // namespace
}  // namespace rigc::cli
