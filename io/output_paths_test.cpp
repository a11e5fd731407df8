#include "io/output_paths.h"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include "tests/test_support.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

// A process id that was a process and is no longer one.
long finished_pid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

TEST(OutputPaths, AbandonedTemporariesGoAndALiveWritersStay) {
  TempDir dir;
  const std::string abandoned = fmt::format(".views.glb.tmp.{}.3.a1b2c3", finished_pid());
  const std::string live = fmt::format(".views.glb.tmp.{}.4.a1b2c4", static_cast<long>(::getpid()));
  for (const std::string& name : {abandoned, live, std::string("views.glb")}) {
    testing::write_text(dir.file(name), "x");
  }
  EXPECT_TRUE(is_temporary_name(abandoned));
  EXPECT_EQ(remove_abandoned_temporaries(dir.path()), 1);
  EXPECT_FALSE(fs::exists(dir.file(abandoned)));
  EXPECT_TRUE(fs::exists(dir.file(live)));
  EXPECT_TRUE(fs::exists(dir.file("views.glb")));
}

}  // namespace
}  // namespace rigc
