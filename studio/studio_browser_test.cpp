// rigc studio in a real headless browser: tests/studio_browser.py drives Chromium through
// Selenium (Debian's chromium, chromium-driver, python3-selenium) against `rigc studio`.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "studio/scene_test_support.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::studio {
namespace {

bool browser_installed() {
  return std::filesystem::exists("/usr/bin/chromedriver") &&
         testing::run_process({"/usr/bin/python3", "-c", "import selenium"}).exit_code == 0;
}

TEST(StudioBrowser, ExposureFocusCaptureCoverageSaveAndErrorsInThePage) {
  RIGC_REQUIRE_TOOL(browser_installed(), "chromium-driver and python3-selenium");
  testing::TempDir dir;
  const std::string scene = dir.file("scene.yaml");
  testing::write_text(scene, kStudioTestScene);
  const testing::ProcessResult run =
      testing::run_process({"/usr/bin/python3", testing::source_path("tests/studio_browser.py"),
                            "--rigc", RIGC_BINARY, "--scene", scene});
  EXPECT_EQ(run.exit_code, 0) << run.out << run.err;
  EXPECT_THAT(run.out, Not(HasSubstr("FAIL")));
}

}  // namespace
}  // namespace rigc::studio
