// `rigc studio` from the command line: what it refuses before serving. The served page and
// Ctrl-C are tested in a browser (StudioBrowser.*, tests/studio_browser.py).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "studio/scene_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;

namespace rigc::cli {
namespace {

using testing::run_rigc;

TEST(CliStudio, AMissingOrBrokenSceneOrABadPortIsAUserError) {
  testing::TempDir dir;
  auto result = run_rigc({"studio", dir.file("none.yaml")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("rigc: error: cannot read"));

  std::string text = studio::kStudioTestScene;
  text.replace(text.find("iso: 200"), 8, "iso: 20");
  testing::write_text(dir.file("broken.yaml"), text);
  result = run_rigc({"studio", dir.file("broken.yaml")});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(
      result.err,
      HasSubstr("broken.yaml:" + std::to_string(studio::kStudioTestSceneExposureLine) + ":"));
  EXPECT_THAT(result.err, HasSubstr("ISO 20 is outside"));

  testing::write_text(dir.file("good.yaml"), studio::kStudioTestScene);
  result = run_rigc({"studio", dir.file("good.yaml"), "--port", "70000"});
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_TRUE(result.out.empty()) << "nothing served: " << result.out;
}

}  // namespace
}  // namespace rigc::cli
