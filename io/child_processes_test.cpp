#include "io/child_processes.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>

#include "tests/test_support.h"

namespace rigc {
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

// Whether a process runs whose command line is `words` (NUL-separated in /proc/PID/cmdline).
bool process_runs(const std::vector<std::string>& words) {
  std::string wanted;
  for (const std::string& word : words) wanted += word + '\0';
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    std::ifstream in(entry.path() / "cmdline", std::ios::binary);
    const std::string cmdline((std::istreambuf_iterator<char>(in)), {});
    if (cmdline == wanted) return true;
  }
  return false;
}

// A stop signal that comes while a child is being started (here, raised by the test hook between
// the spawn and the watch) is carried out once the child is watched: the child is stopped, then
// the process dies of the signal. Before, the handler killed the watched children (none yet) and
// died at once, and the child ran on.
TEST(ChildProcessesDeathTest, AStopSignalWhileAChildStartsStopsTheChildThenRigc) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  rigc::testing::TempDir dir;
  // sleep adds its arguments: the odd second one marks this test's child. (A constant: the
  // threadsafe death test runs this body again in a process of its own.)
  const std::vector<std::string> argv = {"sleep", "30", "0.000271828"};
  const std::filesystem::path log = dir.path() / "log.txt";
  EXPECT_EXIT(
      {
        set_spawn_hook_for_tests([] { raise(SIGTERM); });
        run_child({argv, log, {}, {}});
        std::exit(0);
      },
      ::testing::KilledBySignal(SIGTERM), "");
  bool runs = true;
  for (int k = 0; k < 50 && runs; ++k) {
    runs = process_runs(argv);
    if (runs) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_FALSE(runs) << "the child outlived the process that started it";
}

}  // namespace
}  // namespace rigc
