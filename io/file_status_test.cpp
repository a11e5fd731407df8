#include "io/file_status.h"

#include <gtest/gtest.h>

#include "tests/test_support.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using testing::TempDir;

TEST(FileStatus, SaysWhyAFileCannotBeRead) {
  TempDir dir;
  testing::write_text(dir.file("ok.txt"), "x");
  fs::create_directory(dir.file("folder"));
  fs::create_symlink("b", dir.file("a"));
  fs::create_symlink("a", dir.file("b"));
  fs::create_symlink("gone", dir.file("dangling"));
  EXPECT_EQ(why_not_readable(dir.file("ok.txt")), "");
  EXPECT_EQ(why_not_readable(dir.file("missing")), "does not exist");
  EXPECT_EQ(why_not_readable(dir.file("folder")), "is a folder");
  EXPECT_EQ(why_not_readable(dir.file("a")), "is a loop of symbolic links");
  EXPECT_EQ(why_not_readable(dir.file("dangling")), "is a symbolic link to nothing");
  EXPECT_EQ(why_not_readable("/dev/zero"), "is not a regular file (a device, a pipe or a socket)");
  EXPECT_TRUE(names_nothing(dir.file("missing")));
  EXPECT_FALSE(names_nothing(dir.file("a")));
  EXPECT_FALSE(names_nothing(dir.file("dangling")));
}

}  // namespace
}  // namespace rigc
