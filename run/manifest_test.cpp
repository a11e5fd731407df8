#include "run/manifest.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/scene_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::run {
namespace {

namespace fs = std::filesystem;
using ::rigc::testing::TempDir;
using ::rigc::testing::write_text;

ShotRecord sample_record(const std::string& key) {
  ShotRecord record;
  record.name = "shot_000";
  record.key = key;
  record.render_ms = 812.5;
  record.stage_ms = {{"raster", 500.25}, {"develop", 312.25}};
  record.files = {"images/shot_000.jpg", "masks/shot_000.png"};
  return record;
}

void write_outputs(const fs::path& run) {
  fs::create_directories(run / "images");
  fs::create_directories(run / "masks");
  write_text((run / "images/shot_000.jpg").string(), "jpeg");
  write_text((run / "masks/shot_000.png").string(), "png");
}

TEST(BackendManifest, SaveLoadAndIsDone) {
  TempDir run;
  write_outputs(run.path());
  Manifest manifest;
  manifest.set_backend("preview");
  manifest.set_inputs({{"scene", "test"}, {"scale", 0.25}, {"seed", 7}});
  manifest.record(sample_record("abc"));
  const fs::path path = run.path() / "manifest.json";
  std::string error;
  ASSERT_TRUE(manifest.save(path, &error)) << error;

  const Manifest loaded = Manifest::load(path);
  EXPECT_EQ(loaded.backend(), "preview");
  EXPECT_EQ(loaded.rigc_version(), RIGC_VERSION);
  EXPECT_EQ(loaded.inputs()["seed"], 7);
  ASSERT_NE(loaded.find("shot_000"), nullptr);
  EXPECT_EQ(loaded.find("shot_000")->render_ms, 812.5);
  EXPECT_EQ(loaded.find("shot_000")->stage_ms.at("develop"), 312.25);
  EXPECT_EQ(loaded.find("shot_000")->files.size(), 2u);
  ShotRecord second = sample_record("def");
  second.name = "shot_001";
  second.render_ms = 187.5;
  Manifest two = loaded;
  two.record(second);
  EXPECT_DOUBLE_EQ(two.render_seconds(), 1.0);
  EXPECT_TRUE(loaded.is_done("shot_000", "abc", run.path()));
  EXPECT_FALSE(loaded.is_done("shot_000", "abd", run.path()));  // changed key
  EXPECT_FALSE(loaded.is_done("shot_001", "abc", run.path()));  // no entry

  // An emptied output (a full disk, a file truncated by hand) is no output.
  write_text((run.path() / "images/shot_000.jpg").string(), "");
  EXPECT_FALSE(loaded.is_done("shot_000", "abc", run.path()));
  write_outputs(run.path());
  EXPECT_TRUE(loaded.is_done("shot_000", "abc", run.path()));

  fs::remove(run.path() / "masks/shot_000.png");  // a deleted output
  EXPECT_FALSE(loaded.is_done("shot_000", "abc", run.path()));
}

// Bytes that are not UTF-8 in a name made nlohmann::json throw at save.
TEST(BackendManifest, SavesTextThatIsNotUtf8) {
  TempDir run;
  Manifest manifest;
  manifest.set_inputs({{"scene", "bad\xff.yaml"}});
  ShotRecord record = sample_record("abc");
  record.files = {"images/shot\xfe.jpg"};
  manifest.record(record);
  std::string error;
  ASSERT_TRUE(manifest.save(run.path() / "manifest.json", &error)) << error;
  const Manifest loaded = Manifest::load(run.path() / "manifest.json");
  EXPECT_EQ(loaded.inputs()["scene"], "bad\xEF\xBF\xBD.yaml");
  ASSERT_NE(loaded.find("shot_000"), nullptr);
  EXPECT_EQ(loaded.find("shot_000")->files.at(0), "images/shot\xEF\xBF\xBD.jpg");
}

TEST(BackendManifest, MissingOrCorruptFileGivesAnEmptyManifest) {
  TempDir run;
  EXPECT_TRUE(Manifest::load(run.path() / "missing.json").shots().empty());
  const std::string path = run.file("manifest.json");
  for (const char* text : {"", "{", "not json", "[1, 2]", "\xff\xfe", "{\"shots\": 3}",
                           "{\"shots\": {\"shot_000\": {\"key\": 5, \"files\": []}}}"}) {
    write_text(path, text);
    Manifest manifest;
    EXPECT_NO_THROW(manifest = Manifest::load(path)) << text;
    EXPECT_TRUE(manifest.shots().empty()) << text;
  }
  // A good entry survives next to a malformed one.
  write_text(path, R"({"shots": {"shot_000": {"key": "k", "files": ["a"]}, "shot_001": []}})");
  EXPECT_EQ(Manifest::load(path).shots().size(), 1u);
  EXPECT_NO_THROW(Manifest::load(run.file("")));  // a folder, not a file
}

TEST(BackendManifest, SaveIntoMissingFolderFails) {
  TempDir run;
  Manifest manifest;
  std::string error;
  EXPECT_FALSE(manifest.save(run.path() / "nope" / "manifest.json", &error));
  EXPECT_THAT(error, HasSubstr("manifest.json"));
}

TEST(BackendManifest, ShotKeysChangeOnlyWithTheirInputs) {
  const ir::Scene scene = testing::small_scene();
  const std::string content = scene_content_hash(scene);
  EXPECT_EQ(content.size(), 64u);
  auto key = [&](const ir::Scene& s, int shot) {
    return shot_key(s, scene_content_hash(s), s.shots[shot], "preview", 0.25, 1, "");
  };
  const std::string k0 = key(scene, 0), k1 = key(scene, 1);
  EXPECT_NE(k0, k1);
  EXPECT_EQ(k0, shot_key(scene, content, scene.shots[0], "preview", 0.25, 1, ""));
  EXPECT_NE(k0, shot_key(scene, content, scene.shots[0], "povray", 0.25, 1, ""));
  EXPECT_NE(k0, shot_key(scene, content, scene.shots[0], "preview", 0.5, 1, ""));
  EXPECT_NE(k0, shot_key(scene, content, scene.shots[0], "preview", 0.25, 2, ""));
  EXPECT_NE(k0, shot_key(scene, content, scene.shots[0], "preview", 0.25, 1, "quality=high"));

  {  // Moving one shot's camera changes that shot's key only.
    ir::Scene changed = scene;
    changed.shots[1].object_from_camera(0, 3) += 1e-6;
    EXPECT_EQ(key(changed, 0), k0);
    EXPECT_NE(key(changed, 1), k1);
  }
  {  // Adding a shot, renaming the scene or moving source lines changes nothing.
    ir::Scene changed = scene;
    changed.shots.push_back(changed.shots.back());
    changed.name = "renamed";
    changed.camera.loc.line += 3;
    changed.shots[0].loc.line += 3;
    EXPECT_EQ(key(changed, 0), k0);
  }
  {  // The camera, the lights and the mesh change every shot.
    ir::Scene changed = scene;
    changed.camera.iso = 400;
    EXPECT_NE(key(changed, 0), k0);
    changed = scene;
    changed.studio.ambient_lx += 1;
    EXPECT_NE(key(changed, 1), k1);
    changed = scene;
    changed.object.mesh.positions[0].x() += 1e-4f;
    EXPECT_NE(scene_content_hash(changed), content);
    EXPECT_NE(key(changed, 0), k0);
    changed = scene;
    changed.object.mesh.normals[0].y() *= -1;
    EXPECT_NE(key(changed, 0), k0);
  }
}

}  // namespace
}  // namespace rigc::run
