// What `rigc` writes, under hostile conditions: a full disk, a standard output that cannot be
// written, outputs named like its inputs, run folders holding other runs.
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>

#include "tests/test_support.h"

using ::testing::Not;

extern char** environ;

namespace rigc {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::read_text;
using testing::run_process;
using testing::run_rigc;
using testing::source_path;
using testing::TempDir;
using testing::write_text;

// A sphere on a turntable: `shots` shots, quick at --scale 0.05.
std::string sphere_scene(const std::string& name, int shots, const std::string& extra = "") {
  return "rigc: 1\nname: " + name +
         "\nobject:\n  primitive: sphere\n  fit: {height: 20cm}\ncamera:\n  body: canon-6d\n"
         "  lens: {focal_length: 50mm}\n  exposure: {aperture: f/8, shutter: 1/125, iso: 200}\n" +
         extra + "shots:\n  - turntable: {steps: " + std::to_string(shots) +
         ", step: 30deg, camera: {distance: 80cm, height: 20cm}}\n";
}

std::vector<std::string> files_in(const fs::path& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    names.push_back(it->path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

bool has_temporaries(const fs::path& run) {
  for (const auto& entry : fs::recursive_directory_iterator(run)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos) return true;
  }
  return false;
}

nlohmann::json manifest_of(const fs::path& run) {
  return nlohmann::json::parse(read_text((run / "manifest.json").string()));
}

// rigc with its standard output on /dev/full, or closed (`path` empty); the exit code and
// standard error.
testing::ProcessResult run_rigc_with_stdout(const std::vector<std::string>& args,
                                            const std::string& path, const TempDir& dir) {
  const std::string err_path = dir.file("stderr");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (path.empty()) {
    posix_spawn_file_actions_addclose(&actions, 1);
  } else {
    posix_spawn_file_actions_addopen(&actions, 1, path.c_str(), O_WRONLY, 0);
  }
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  std::vector<std::string> argv = {RIGC_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> raw;
  for (auto& a : argv) raw.push_back(a.data());
  raw.push_back(nullptr);
  pid_t pid = 0;
  testing::ProcessResult result;
  const int rc = posix_spawn(&pid, raw[0], &actions, nullptr, raw.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return result;
  int status = 0;
  waitpid(pid, &status, 0);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.err = read_text(err_path);
  return result;
}

// Row 1 of issue 38: on a full disk libjpeg called exit() from a worker thread (SIGSEGV) and a
// temporary file survived. A file-size limit fails writes the same way, deterministically.
TEST(CliOutputs, RenderWhereFilesCannotBeWrittenFailsCleanly) {
  TempDir dir;
  write_text(dir.file("s.yaml"), sphere_scene("limited", 3));
  const fs::path run = dir.path() / "R";
  fs::create_directories(run / "images");
  write_text((run / "images" / ".shot_002.jpg.tmp.4242.7.1a2b3c").string(), "stale");
  const auto limited = run_process({"prlimit", "--fsize=3000", RIGC_BINARY, "render",
                                    dir.file("s.yaml"), "-o", run.string(), "--scale", "0.05"});
  EXPECT_EQ(limited.exit_code, 2) << limited.err;
  EXPECT_TRUE(
      std::regex_search(limited.err, std::regex("rigc: error: shot_000: cannot write .*/R/images/"
                                                "shot_000.jpg: File too large")))
      << limited.err;
  EXPECT_FALSE(has_temporaries(run));
  EXPECT_TRUE(files_in(run / "images").empty());

  const auto rerun =
      run_rigc({"render", dir.file("s.yaml"), "-o", run.string(), "--scale", "0.05"});
  EXPECT_EQ(rerun.exit_code, 0) << rerun.err;
  EXPECT_EQ(files_in(run / "images"),
            (std::vector<std::string>{"shot_000.jpg", "shot_001.jpg", "shot_002.jpg"}));
  EXPECT_FALSE(has_temporaries(run));
}

// Row 3: output lost on a full or closed standard output was exit 0 with truncated JSON.
TEST(CliOutputs, StandardOutputThatCannotBeWrittenIsAnError) {
  TempDir dir;
  write_text(dir.file("s.yaml"), sphere_scene("stdout", 2));
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"compile", dir.file("s.yaml"), "--target", "ir"},
        std::vector<std::string>{"check", "--json", "--no-advice", dir.file("s.yaml")},
        std::vector<std::string>{"version"}}) {
    const auto full = run_rigc_with_stdout(args, "/dev/full", dir);
    EXPECT_EQ(full.exit_code, 2) << args[0];
    EXPECT_THAT(full.err,
                HasSubstr("rigc: error: cannot write to standard output: No space left on "
                          "device"));
    const auto closed = run_rigc_with_stdout(args, "", dir);
    EXPECT_EQ(closed.exit_code, 2) << args[0];
    EXPECT_THAT(closed.err, HasSubstr("rigc: error: cannot write to standard output"));
  }
}

// A textured cube in dir: cube.obj, cube.mtl naming texture_0.png (the name the Cycles target
// gives its copy of the first texture), and the scene s.yaml.
void write_textured_cube(const TempDir& dir) {
  write_text(dir.file("cube.obj"),
             "mtllib cube.mtl\nusemtl skin\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
             "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "f 1/1 3/3 2/2\nf 1/1 4/4 3/3\nf 5/1 6/2 7/3\nf 5/1 7/3 8/4\nf 1/1 2/2 6/3\n"
             "f 1/1 6/3 5/4\nf 2/1 3/2 7/3\nf 2/1 7/3 6/4\nf 3/1 4/2 8/3\nf 3/1 8/3 7/4\n"
             "f 4/1 1/2 5/3\nf 4/1 5/3 8/4\n");
  write_text(dir.file("cube.mtl"), "newmtl skin\nKd 1 1 1\nmap_Kd texture_0.png\n");
  std::vector<std::uint16_t> pixels(8 * 8 * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint16_t>(i * 997);
  auto out = OIIO::ImageOutput::create(dir.file("texture_0.png"));
  const OIIO::ImageSpec spec(8, 8, 3, OIIO::TypeDesc::UINT16);
  ASSERT_TRUE(out && out->open(dir.file("texture_0.png"), spec) &&
              out->write_image(OIIO::TypeDesc::UINT16, pixels.data()) && out->close());
  write_text(dir.file("s.yaml"),
             "rigc: 1\nname: cube\nobject:\n  mesh: cube.obj\n  fit: {size: 10cm}\ncamera:\n"
             "  body: canon-6d\n  lens: {focal_length: 50mm}\n"
             "  exposure: {aperture: f/8, shutter: 1/60, iso: 400}\nshots:\n"
             "  - turntable: {steps: 2, step: 30deg, camera: {distance: 60cm, height: 10cm}}\n");
}

// Row 5: `compile -o model.obj` wrote the IR over the scene's mesh, and `--target cycles -o .`
// in the mesh's folder replaced a 16-bit texture with an 8-bit copy.
TEST(CliOutputs, NoCommandWritesOverItsInputs) {
  TempDir dir;
  write_textured_cube(dir);
  fs::create_symlink(dir.file("cube.obj"), dir.file("link.obj"));
  fs::create_hard_link(dir.file("cube.mtl"), dir.file("hard.mtl"));
  const std::string mesh = read_text(dir.file("cube.obj")), scene = read_text(dir.file("s.yaml"));
  const std::string material = read_text(dir.file("cube.mtl"));
  const std::string texture = read_text(dir.file("texture_0.png"));
  const std::vector<std::pair<std::string, std::string>> outputs = {
      {dir.file("cube.obj"), "the scene's mesh"},
      {(dir.path() / "." / "cube.obj").string(), "the scene's mesh"},
      {dir.file("link.obj"), "the scene's mesh"},
      {dir.file("hard.mtl"), "the mesh's material library"},
      {dir.file("texture_0.png"), "a texture of the scene"}};
  for (const auto& [output, what] : outputs) {
    const auto result = run_rigc({"compile", dir.file("s.yaml"), "-o", output});
    EXPECT_EQ(result.exit_code, 1) << output;
    EXPECT_THAT(result.err, HasSubstr("rigc: error: cannot write " + output));
    EXPECT_THAT(result.err, HasSubstr("it is " + what + ", an input of this command"));
  }
  const auto cycles =
      run_rigc({"compile", dir.file("s.yaml"), "--target", "cycles", "-o", dir.path().string()});
  EXPECT_EQ(cycles.exit_code, 1) << cycles.err;
  EXPECT_THAT(cycles.err, HasSubstr("it is a texture of the scene"));
  EXPECT_EQ(read_text(dir.file("cube.obj")), mesh);
  EXPECT_EQ(read_text(dir.file("cube.mtl")), material);
  EXPECT_EQ(read_text(dir.file("texture_0.png")), texture);
  EXPECT_EQ(read_text(dir.file("s.yaml")), scene);
  EXPECT_TRUE(fs::is_symlink(dir.file("link.obj")));
}

// Row 6: a run folder held shots of two sizes and cameras.txt claimed one. And `--shots` with
// another seed left manifest.inputs.seed naming one seed for shots rendered with another.
TEST(CliOutputs, ARunFolderHoldsOneScale) {
  TempDir dir;
  write_text(dir.file("s.yaml"), sphere_scene("scales", 3));
  const std::string run = dir.file("R");
  auto render = [&](const std::string& scale, std::vector<std::string> extra) {
    std::vector<std::string> args = {"render", dir.file("s.yaml"), "-o", run, "--scale", scale};
    args.insert(args.end(), extra.begin(), extra.end());
    return run_rigc(args);
  };
  ASSERT_EQ(render("0.05", {}).exit_code, 0);
  const std::string image = read_text(run + "/images/shot_001.jpg");
  const auto other = render("0.1", {"--shots", "0"});
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_THAT(other.err,
              HasSubstr("rigc: error: this run folder holds shot_001 and 1 more rendered at "
                        "--scale 0.05, and a run folder holds one image size"));
  EXPECT_EQ(read_text(run + "/images/shot_001.jpg"), image);
  EXPECT_EQ(render("0.1", {}).exit_code, 0);
  EXPECT_EQ(manifest_of(run)["shots"]["shot_002"]["scale"], 0.1);

  const auto seed = render("0.1", {"--shots", "1", "--seed", "7"});
  EXPECT_EQ(seed.exit_code, 0) << seed.err;
  const auto manifest = manifest_of(run);
  EXPECT_TRUE(manifest["inputs"]["seed"].is_null()) << manifest["inputs"];
  EXPECT_EQ(manifest["shots"]["shot_001"]["seed"], 7);
  EXPECT_EQ(manifest["shots"]["shot_000"]["seed"], 1);
}

// Row 7: a rerun of another scene into a run folder deleted the first scene's shots without a
// word, and images an interrupted run never recorded stayed for `rigc eval` to use.
TEST(CliOutputs, ARunFolderHoldsOneSceneAndOnlyRecordedImages) {
  TempDir dir;
  write_text(dir.file("a.yaml"), sphere_scene("first", 3));
  write_text(dir.file("b.yaml"), sphere_scene("second", 2));
  const std::string run = dir.file("R");
  ASSERT_EQ(run_rigc({"render", dir.file("a.yaml"), "-o", run, "--scale", "0.05"}).exit_code, 0);

  // An interrupted run: shot_002's files are written but the manifest never listed them.
  nlohmann::json manifest = manifest_of(run);
  manifest["shots"].erase("shot_002");
  write_text(run + "/manifest.json", manifest.dump());
  auto other = run_rigc({"render", dir.file("b.yaml"), "-o", run, "--scale", "0.05"});
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_THAT(other.err,
              HasSubstr("holds 2 shots of the scene 'first', not 'second'; choose another "
                        "folder with -o, or pass --force"));
  EXPECT_EQ(files_in(run + "/images"),
            (std::vector<std::string>{"shot_000.jpg", "shot_001.jpg", "shot_002.jpg"}));

  // The same scene again, on shot 0 only: the unrecorded files of shot 2 go, said so.
  auto again =
      run_rigc({"render", dir.file("a.yaml"), "-o", run, "--scale", "0.05", "--shots", "0"});
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.err,
              HasSubstr("rigc: deleted 2 files in '" + run +
                        "' that the manifest does not list (images/shot_002.jpg and 1 more)"));
  EXPECT_EQ(files_in(run + "/images"), (std::vector<std::string>{"shot_000.jpg", "shot_001.jpg"}));

  // A file that is no shot of the scene is named, and deleted only with --force.
  write_text(run + "/images/IMG_0001.jpg", "a photo");
  again = run_rigc({"render", dir.file("a.yaml"), "-o", run, "--scale", "0.05"});
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_THAT(again.err,
              HasSubstr("rigc: warning: the run folder '" + run +
                        "' holds 1 file that no shot of 'first' writes and its manifest does "
                        "not list (images/IMG_0001.jpg)"));
  EXPECT_TRUE(fs::exists(run + "/images/IMG_0001.jpg"));
  other = run_rigc({"render", dir.file("b.yaml"), "-o", run, "--scale", "0.05", "--force"});
  EXPECT_EQ(other.exit_code, 0) << other.err;
  EXPECT_THAT(other.err, HasSubstr("--force: deleted 6 files of the scene 'first'"));
  EXPECT_EQ(files_in(run + "/images"), (std::vector<std::string>{"shot_000.jpg", "shot_001.jpg"}));
  EXPECT_EQ(manifest_of(run)["inputs"]["scene"], "second");
}

// Messages: a symbolic link loop as -o or among --photos was "internal error: filesystem error",
// and -o a dangling link "images: File exists" (render) or the link replaced (compile).
// eval clears its own work folders (OUT/masks, OUT/colmap) each run; it refuses, touching
// nothing, when one of them holds an input: the masks it is given, or the photos themselves.
TEST(CliOutputs, EvalNeverClearsAFolderThatHoldsItsInputs) {
  TempDir dir;
  write_text(dir.file("s.yaml"), sphere_scene("inputs", 3));
  auto result = run_rigc({"render", dir.file("s.yaml"), "--scale", "0.05", "-o", dir.file("run")});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const fs::path out = dir.path() / "out";
  fs::create_directories(out / "masks");
  for (const auto& name : files_in(dir.path() / "run" / "masks")) {
    fs::copy_file(dir.path() / "run" / "masks" / name, out / "masks" / name);
  }
  const auto masks = files_in(out / "masks");
  ASSERT_FALSE(masks.empty());
  result = run_rigc({"eval", "--photos", dir.file("run/images"), "-o", out.string(), "--masks",
                     (out / "masks").string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_THAT(result.err, HasSubstr("will not clear '" + (out / "masks").string()));
  EXPECT_THAT(result.err, HasSubstr("the masks given by --masks"));
  EXPECT_EQ(files_in(out / "masks"), masks);

  fs::create_directories(out / "colmap");
  for (const auto& name : files_in(dir.path() / "run" / "images")) {
    fs::copy_file(dir.path() / "run" / "images" / name, out / "colmap" / name);
  }
  const auto photos = files_in(out / "colmap");
  result = run_rigc({"eval", "--photos", (out / "colmap").string(), "-o", out.string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_THAT(result.err, HasSubstr("will not clear '" + (out / "colmap").string()));
  EXPECT_THAT(result.err, HasSubstr("a photo ("));
  EXPECT_EQ(files_in(out / "colmap"), photos);
}

// eval's reports are JSON: a photo whose name is not UTF-8 is refused, named, before COLMAP runs.
TEST(CliOutputs, APhotoNameThatIsNotUtf8IsRefusedBeforeColmap) {
  TempDir dir;
  write_text(dir.file("s.yaml"), sphere_scene("names", 3));
  auto result = run_rigc({"render", dir.file("s.yaml"), "--scale", "0.05", "-o", dir.file("run")});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  fs::create_directories(dir.path() / "photos");
  int k = 0;
  for (const auto& name : files_in(dir.path() / "run" / "images")) {
    const std::string to = k++ == 0 ? "caf\xe9.jpg" : name;
    fs::copy_file(dir.path() / "run" / "images" / name, dir.path() / "photos" / to);
  }
  result = run_rigc({"eval", "--photos", dir.file("photos"), "-o", dir.file("out")});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_THAT(result.err, HasSubstr("is not valid UTF-8; rename it"));
  EXPECT_THAT(result.err, ::testing::Not(HasSubstr("internal error")));
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "colmap"));
}

TEST(CliOutputs, OutputPathsThatCannotBeFollowedAreUserErrors) {
  TempDir dir;
  write_text(dir.file("s.yaml"), sphere_scene("links", 1));
  fs::create_symlink("loop", dir.file("loop"));
  fs::create_symlink(dir.file("missing/x"), dir.file("dangling"));
  for (const auto& args :
       {std::vector<std::string>{"compile", dir.file("s.yaml"), "-o", dir.file("loop")},
        std::vector<std::string>{"compile", dir.file("s.yaml"), "--target", "povray", "-o",
                                 dir.file("loop")},
        std::vector<std::string>{"render", dir.file("s.yaml"), "--scale", "0.05", "-o",
                                 dir.file("loop")}}) {
    const auto result = run_rigc(args);
    EXPECT_EQ(result.exit_code, 1) << result.err;
    EXPECT_THAT(result.err, HasSubstr("rigc: error:"));
    EXPECT_THAT(result.err, Not(HasSubstr("internal error")));
  }
  auto result =
      run_rigc({"render", dir.file("s.yaml"), "--scale", "0.05", "-o", dir.file("dangling")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("is a symbolic link to '" + dir.file("missing/x") +
                                    "', which does not exist"));
  result = run_rigc({"compile", dir.file("s.yaml"), "-o", dir.file("dangling")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("whose folder does not exist"));
  EXPECT_TRUE(fs::is_symlink(dir.file("dangling")));

  fs::create_directories(dir.path() / "photos");
  fs::create_symlink("a.jpg", dir.path() / "photos" / "a.jpg");
  result = run_rigc({"eval", "--photos", (dir.path() / "photos").string()});
  EXPECT_EQ(result.exit_code, 1) << result.err;
  EXPECT_THAT(result.err, HasSubstr("rigc: error: cannot use '"));
  EXPECT_THAT(result.err, HasSubstr("Too many levels of symbolic links"));
}

}  // namespace
}  // namespace rigc
