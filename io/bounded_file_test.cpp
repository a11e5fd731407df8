#include "io/bounded_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include "tests/test_support.h"

namespace rigc {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using testing::TempDir;

TEST(BoundedFile, ReadsARegularFileWithinItsBoundAndNamesItsIdentity) {
  TempDir dir;
  testing::write_text(dir.file("scene.yaml"), "rigc: 1\n");
  std::string why;
  const auto file = read_bounded_file(dir.file("scene.yaml"), 8, &why);
  ASSERT_TRUE(file) << why;
  EXPECT_EQ(file->bytes, "rigc: 1\n");
  EXPECT_EQ(identity_of(dir.file("scene.yaml")), file->identity);
  fs::create_symlink("scene.yaml", dir.file("link.yaml"));
  EXPECT_EQ(identity_of(dir.file("link.yaml")), file->identity);
  testing::write_text(dir.file("other.yaml"), "rigc: 1\n");
  EXPECT_NE(identity_of(dir.file("other.yaml")), file->identity);
}

TEST(BoundedFile, RefusesALargerFileADeviceAPipeAndAFolder) {
  TempDir dir;
  testing::write_text(dir.file("big.yaml"), std::string(2048, 'x'));
  std::string why;
  EXPECT_FALSE(read_bounded_file(dir.file("big.yaml"), 1024, &why));
  EXPECT_EQ(why, "is larger than 1 KB");
  // Neither read forever nor waited on: a pipe with no writer would block a plain open.
  ASSERT_EQ(::mkfifo(dir.file("pipe.yaml").c_str(), 0600), 0);
  EXPECT_FALSE(read_bounded_file(dir.file("pipe.yaml"), 1024, &why));
  EXPECT_THAT(why, HasSubstr("not a regular file"));
  EXPECT_FALSE(read_bounded_file("/dev/zero", 1024, &why));
  EXPECT_THAT(why, HasSubstr("not a regular file"));
  EXPECT_FALSE(read_bounded_file(dir.path(), 1024, &why));
  EXPECT_EQ(why, "is a folder");
  EXPECT_FALSE(read_bounded_file(dir.file("missing"), 1024, &why));
  EXPECT_EQ(why, "does not exist");
  EXPECT_EQ(size_in_words(16 << 20), "16 MB");
  EXPECT_EQ(size_in_words(200), "200 bytes");
}

}  // namespace
}  // namespace rigc
