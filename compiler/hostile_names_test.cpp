// File, material and texture names that are not UTF-8: every JSON output stays valid JSON.
#include <OpenImageIO/imageio.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "compiler/frontend.h"
#include "ir/utf8_text.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::run_rigc;
using testing::TempDir;
using testing::write_text;

TEST(Utf8Text, StrayBytesBecomeReplacementCharacters) {
  EXPECT_TRUE(valid_utf8("plain, é, 日本, 😀"));
  EXPECT_FALSE(valid_utf8("a\xff"));
  EXPECT_FALSE(valid_utf8("\xc0\xaf"));          // overlong '/'
  EXPECT_FALSE(valid_utf8("\xed\xa0\x80"));      // a surrogate
  EXPECT_FALSE(valid_utf8("\xf4\x90\x80\x80"));  // past U+10FFFF
  EXPECT_EQ(valid_utf8_text("mat\xff"), "mat\xEF\xBF\xBD");
  EXPECT_EQ(valid_utf8_text("\xe6\x97"), "\xEF\xBF\xBD\xEF\xBF\xBD");  // cut short
  EXPECT_EQ(valid_utf8_text("é"), "é");
}

// A cube with a textured material; `odd` is a byte that is not UTF-8.
void write_cube(const TempDir& dir, const std::string& odd) {
  write_text(dir.file("cube.mtl"),
             "newmtl mat" + odd + "\nKd 0.8 0.2 0.2\nmap_Kd tex" + odd + ".png\n");
  std::string obj = "mtllib cube.mtl\n";
  for (const char* v :
       {"-1 -1 -1", "1 -1 -1", "1 1 -1", "-1 1 -1", "-1 -1 1", "1 -1 1", "1 1 1", "-1 1 1"}) {
    obj += std::string("v ") + v + "\n";
  }
  obj += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl mat" + odd + "\n";
  for (const char* f :
       {"1/1 3/3 2/2", "1/1 4/4 3/3", "5/1 6/2 7/3", "5/1 7/3 8/4", "1/1 2/2 6/3", "1/1 6/3 5/4",
        "2/1 3/2 7/3", "2/1 7/3 6/4", "3/1 4/2 8/3", "3/1 8/3 7/4", "4/1 1/2 5/3", "4/1 5/3 8/4"}) {
    obj += std::string("f ") + f + "\n";
  }
  write_text(dir.file("cube.obj"), obj);
  const std::string texture = dir.file("tex" + odd + ".png");
  const OIIO::ImageSpec spec(16, 16, 3, OIIO::TypeDesc::UINT8);
  const std::vector<unsigned char> pixels(16 * 16 * 3, 180);
  auto out = OIIO::ImageOutput::create(texture);
  ASSERT_TRUE(out && out->open(texture, spec)) << texture;
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, pixels.data()));
  ASSERT_TRUE(out->close());
}

// json::parse throws on text that is not UTF-8, as json::dump did when writing it.
json parsed(const std::string& text) {
  try {
    return json::parse(text);
  } catch (const std::exception& e) {
    ADD_FAILURE() << e.what() << "\n" << text.substr(0, 500);
    return {};
  }
}

TEST(HostileNames, NamesThatAreNotUtf8GiveValidJsonEverywhere) {
  TempDir dir;
  const std::string odd = "\xff";
  write_cube(dir, odd);
  const std::string scene = dir.file("scene" + odd + ".yaml");
  write_text(scene, R"(rigc: 1
name: bytes
object:
  mesh: cube.obj
  fit: {size: 10cm}
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/8, shutter: 1/60, iso: 400}
shots:
  - turntable: {steps: 2, step: 20deg, camera: {distance: 60cm, height: 10cm}}
)");
  const auto check = run_rigc({"check", "--json", scene});
  EXPECT_EQ(check.exit_code, 0) << check.err;
  const json checked = parsed(check.out);
  EXPECT_EQ(checked.value("ok", false), true);

  const auto ir = run_rigc({"compile", scene, "--target", "ir", "--no-geometry"});
  ASSERT_EQ(ir.exit_code, 0) << ir.err;
  const json document = parsed(ir.out);
  EXPECT_EQ(document.value("source_file", ""), dir.file("scene\xEF\xBF\xBD.yaml"));
  EXPECT_THAT(ir.out, HasSubstr("mat\xEF\xBF\xBD"));
  EXPECT_THAT(ir.out, HasSubstr("tex\xEF\xBF\xBD.png"));

  const std::string run = dir.file("run");
  const auto render = run_rigc({"render", scene, "-o", run, "--scale", "0.05"});
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const json manifest = parsed(testing::read_text(run + "/manifest.json"));
  EXPECT_EQ(manifest["shots"].size(), 2u);
  EXPECT_TRUE(fs::exists(run + "/images/shot_001.jpg"));
}

// A diagnostic quoting a name that is not UTF-8 is still one `check --json` can print.
TEST(HostileNames, DiagnosticsQuotingBytesAreValidJson) {
  TempDir dir;
  const std::string scene = dir.file("bad\xfe.yaml");
  write_text(scene, "rigc: 1\nobject: {mesh: \"gone\\xff.obj\", fit: {size: 1cm}}\n");
  const auto check = run_rigc({"check", "--json", scene});
  EXPECT_EQ(check.exit_code, 1) << check.err;
  const json checked = parsed(check.out);
  ASSERT_TRUE(checked.contains("diagnostics"));
  EXPECT_EQ(checked["diagnostics"][0].value("file", ""), dir.file("bad\xEF\xBF\xBD.yaml"));
}

std::string compile_messages(const std::string& path) {
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  EXPECT_FALSE(compile_scene_file(path, diag)) << path;
  return messages;
}

// "cannot read the scene file" said nothing of why.
TEST(HostileNames, AnUnreadableSceneFileSaysWhy) {
  TempDir dir;
  fs::create_directories(dir.path() / "folder.yaml");
  fs::create_symlink("loop.yaml", dir.path() / "loop.yaml");
  fs::create_symlink("gone.yaml", dir.path() / "dangling.yaml");
  EXPECT_THAT(compile_messages(dir.file("none.yaml")),
              HasSubstr("cannot read the scene file: it does not "
                        "exist"));
  EXPECT_THAT(compile_messages(dir.file("folder.yaml")), HasSubstr(": it is a folder"));
  EXPECT_THAT(compile_messages(dir.file("loop.yaml")),
              HasSubstr(": it is a loop of symbolic links"));
  EXPECT_THAT(compile_messages(dir.file("dangling.yaml")),
              HasSubstr(": it is a symbolic link to nothing"));
  EXPECT_THAT(compile_messages("/dev/null"), HasSubstr(": it is not a regular file"));
}

std::string text_messages(const std::string& text) {
  DiagnosticEngine diag;
  std::string messages;
  rigc::testing::capture_diagnostics(diag, messages);
  EXPECT_FALSE(compile_scene_text(text, "s.yaml", ".", diag));
  return messages;
}

// A mesh that is a symbolic link loop said "does not exist".
TEST(HostileNames, AnUnreadableMeshSaysWhy) {
  TempDir dir;
  fs::create_symlink("loop.obj", dir.path() / "loop.obj");
  fs::create_directories(dir.path() / "folder.obj");
  fs::create_symlink("/dev/zero", dir.path() / "zero.obj");
  const auto messages = [&](const std::string& mesh) {
    DiagnosticEngine diag;
    std::string out;
    rigc::testing::capture_diagnostics(diag, out);
    EXPECT_FALSE(compile_scene_text("rigc: 1\nobject: {mesh: " + mesh + ", fit: {size: 1cm}}\n",
                                    "s.yaml", dir.path().string(), diag));
    return out;
  };
  EXPECT_THAT(messages("loop.obj"), HasSubstr("loop.obj' is a loop of symbolic links"));
  EXPECT_THAT(messages("folder.obj"), HasSubstr("folder.obj' is a folder"));
  EXPECT_THAT(messages("zero.obj"), HasSubstr("zero.obj' is not a regular file"));
  EXPECT_THAT(messages("gone.obj"), HasSubstr("gone.obj' does not exist"));
}

// A NUL byte was "unknown escape character".
TEST(HostileNames, ANulByteIsNamedAtItsPlace) {
  const std::string messages = text_messages(std::string("rigc: 1\nname: \"ab\0c\"\n", 21));
  EXPECT_EQ(messages.rfind("s.yaml:2:10: error: a NUL byte", 0), 0u) << messages;
}

// C1 controls and U+202E (right-to-left override) were accepted in names, and so in folders.
TEST(HostileNames, ControlAndBidiCharactersAreRefusedInTheName) {
  for (const std::string name : {"a\xC2\x85"
                                 "b",
                                 "evil\xE2\x80\xAEgpj.exe", "x\xE2\x81\xA6y"}) {
    const std::string messages = text_messages("rigc: 1\nname: \"" + name + "\"\n");
    EXPECT_THAT(messages, HasSubstr("the scene's name cannot name a folder (it holds a"));
  }
  EXPECT_THAT(text_messages("rigc: 1\nname: \"caf\xC3\xA9\"\n"), Not(HasSubstr("name cannot")));
}

}  // namespace
}  // namespace rigc
