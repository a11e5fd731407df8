#include "compiler/diagnostics.h"

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace rigc {
namespace {

TEST(Diagnostics, RendersLocationSourceLineAndCaret) {
  DiagnosticEngine diag;
  std::string captured;
  rigc::testing::capture_diagnostics(diag, captured);
  diag.add_source("rig.yaml", "camera:\n  exposure: {aperture: f/0.8}\n");
  diag.error({"rig.yaml", 2, 24}, "aperture f/0.8 is outside f/1.2..f/64");
  EXPECT_EQ(captured,
            "rig.yaml:2:24: error: aperture f/0.8 is outside f/1.2..f/64\n"
            "    exposure: {aperture: f/0.8}\n"
            "                         ^\n");
  EXPECT_EQ(diag.error_count(), 1);
  diag.warning({"rig.yaml", 1, 1}, "something");
  EXPECT_EQ(diag.warning_count(), 1);
  EXPECT_EQ(diag.diagnostics().size(), 2u);
}

TEST(Diagnostics, ClosestMatchSuggestsNearNamesOnly) {
  EXPECT_EQ(closest_match("aperure", {"aperture", "shutter", "iso"}), "aperture");
  EXPECT_EQ(closest_match("hieght", {"distance", "height", "aim"}), "height");
  EXPECT_EQ(closest_match("zzzzzz", {"distance", "height", "aim"}), "");
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3);
}

}  // namespace
}  // namespace rigc
