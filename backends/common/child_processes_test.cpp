#include "backends/common/child_processes.h"

#include <gtest/gtest.h>

#include <cstdlib>

#include "tests/test_support.h"

namespace rigc::backends {
namespace {

TEST(ChildProcesses, DefaultEnvironmentFillsOnlyWhatIsUnset) {
  rigc::testing::TempDir dir;
  const std::filesystem::path log = dir.path() / "log.txt";
  ASSERT_NE(std::getenv("PATH"), nullptr);
  ASSERT_EQ(std::getenv("RIGC_CHILD_TEST_UNSET"), nullptr);
  const ChildResult result =
      run_child({{"sh", "-c", "echo \"$RIGC_CHILD_TEST_UNSET\"; pwd; exit 4"},
                 log,
                 dir.path(),
                 {"RIGC_CHILD_TEST_UNSET=fallback", "PATH=/nowhere"}});
  ASSERT_TRUE(result.started) << result.error;
  EXPECT_EQ(result.exit_code, 4);
  // The fallback is set; rigc's own PATH is kept (with /nowhere, echo and pwd still run as
  // builtins, but the log names the working folder either way).
  const std::string text = rigc::testing::read_text(log.string());
  EXPECT_EQ(text, "fallback\n" + std::filesystem::canonical(dir.path()).string() + "\n");
  const ChildResult path = run_child({{"sh", "-c", "echo \"$PATH\""}, log, {}, {"PATH=/nowhere"}});
  EXPECT_EQ(path.exit_code, 0);
  EXPECT_EQ(rigc::testing::read_text(log.string()), text + std::getenv("PATH") + "\n");
}

TEST(ChildProcesses, ReportsTheChildsCpuTimeAndWhyItDidNotStart) {
  rigc::testing::TempDir dir;
  const std::filesystem::path log = dir.path() / "log.txt";
  const ChildResult busy =
      run_child({{"sh", "-c", "i=0; while [ $i -lt 300000 ]; do i=$((i + 1)); done"}, log, {}, {}});
  ASSERT_TRUE(busy.started) << busy.error;
  EXPECT_EQ(busy.exit_code, 0);
  EXPECT_GT(busy.cpu_seconds, 0.05);
  const ChildResult missing = run_child({{"rigc-no-such-program"}, log, {}, {}});
  EXPECT_FALSE(missing.started);
  EXPECT_EQ(missing.error, "'rigc-no-such-program' was not found in PATH");
}

}  // namespace
}  // namespace rigc::backends
