#include "io/files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <stdexcept>
#include <string>

#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc {
namespace {

namespace fs = std::filesystem;

TEST(BackendFiles, Sha256KnownVectors) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(
      sha256_hex("abcdefghbcdefghicdefghijdefghijkefghijklfghijklmghijklmnhijklmnoijklmnopjklm"
                 "nopqklmnopqrlmnopqrsmnopqrstnopqrstu"),
      "cf5b16a778af8380036ce59e7b0492370b249b11e8f07a51afac45037afee9d1");
}

TEST(BackendFiles, Sha256PaddingBoundaries) {
  // Lengths around the 55/56/64-byte padding boundaries (values from Python's hashlib).
  const std::pair<int, const char*> cases[] = {
      {55, "d5e285683cd4efc02d021a5c62014694958901005d6f71e89e0989fac77e4072"},
      {56, "04c26261370ee7541549d16dee320c723e3fd14671e66a099afe0a377c16888e"},
      {63, "75220b47218278e656f2013bb8f0c455a25eaf01e86c64924e9d48d89776d6f2"},
      {64, "7ce100971f64e7001e8fe5a51973ecdfe1ced42befe7ee8d5fd6219506b5393c"},
      {65, "9537c5fdf120482f7d58d25e9ed583f52c02b4e304ea814db1633ad565aed7e9"},
      {119, "000b48d4edf0fa7bee3c6236ecd2785baa5db4eeb8bb54341b029e0d9fa5fb0c"},
      {120, "13f05a0b594787f5ecd315edc96141bd3243203d1b7d4f0836f37308b276ba98"}};
  for (const auto& [length, digest] : cases) {
    EXPECT_EQ(sha256_hex(std::string(length, 'x')), digest) << length;
  }
}

TEST(BackendFiles, Sha256IncrementalMillionA) {
  // A million 'a' fed in uneven pieces gives the same digest as one call.
  const std::string a(1000000, 'a');
  Sha256 hash;
  std::size_t offset = 0;
  for (std::size_t piece = 1; offset < a.size(); piece = piece * 7 % 131 + 1) {
    const std::size_t n = std::min(piece, a.size() - offset);
    hash.update(a.data() + offset, n);
    offset += n;
  }
  const std::string expected = "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0";
  EXPECT_EQ(hash.hex_digest(), expected);
  EXPECT_EQ(sha256_hex(a), expected);
}

TEST(BackendFiles, WriteAtomicallyWritesAndReplaces) {
  rigc::testing::TempDir dir;
  const fs::path path = dir.path() / "out.txt";
  std::string error;
  ASSERT_TRUE(write_file_atomically(path, "first", &error)) << error;
  EXPECT_EQ(rigc::testing::read_text(path.string()), "first");
  ASSERT_TRUE(write_file_atomically(path, std::string("second\0bytes", 12), &error)) << error;
  EXPECT_EQ(rigc::testing::read_text(path.string()), std::string("second\0bytes", 12));
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1) << "a temporary file was left behind";
}

// A rename over the path replaced what was there: a symbolic link became a file of its own, and
// as root /dev/stdout became a regular file.
TEST(BackendFiles, WriteAtomicallyWritesThroughALinkAndRefusesAPipe) {
  rigc::testing::TempDir dir;
  const fs::path target = dir.path() / "target.json", link = dir.path() / "link.json";
  rigc::testing::write_text(target.string(), "old");
  fs::create_symlink("target.json", link);
  std::string error;
  ASSERT_TRUE(write_file_atomically(link, "new", &error)) << error;
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(rigc::testing::read_text(target.string()), "new");

  const fs::path pipe = dir.path() / "pipe.json";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  EXPECT_FALSE(write_file_atomically(pipe, "bytes", &error));
  EXPECT_THAT(error, HasSubstr("not a regular file"));
  EXPECT_TRUE(fs::is_fifo(pipe));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 3)
      << "a temporary file was left behind";
}

TEST(BackendFiles, WriteAtomicallyIntoMissingFolderFails) {
  rigc::testing::TempDir dir;
  const fs::path path = dir.path() / "missing" / "out.txt";
  std::string error;
  EXPECT_FALSE(write_file_atomically(path, "bytes", &error));
  EXPECT_THAT(error, HasSubstr(path.string()));
  EXPECT_THAT(error, Not(HasSubstr("\n")));
  EXPECT_TRUE(fs::is_empty(dir.path()));
  EXPECT_FALSE(write_file_atomically(path, "bytes", nullptr));  // a null error is allowed
}

TEST(BackendFiles, WriteAtomicallyOverAFolderFailsAndCleansUp) {
  rigc::testing::TempDir dir;
  const fs::path path = dir.path() / "taken";
  fs::create_directories(path / "child");
  std::string error;
  EXPECT_FALSE(write_file_atomically(path, "bytes", &error));
  EXPECT_THAT(error, HasSubstr(path.string()));
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 1) << "the temporary file was not removed";
}

TEST(BackendFiles, AFailingWriterLeavesTheOldFileAndNoTemporary) {
  rigc::testing::TempDir dir;
  const fs::path path = dir.path() / "out.txt";
  ASSERT_TRUE(write_file_atomically(path, "old", nullptr));
  std::string error;
  const bool written = write_atomically(
      path,
      [](const fs::path& temporary, std::string* reason) {
        rigc::testing::write_text(temporary, "half");
        *reason = "the encoder failed";
        return false;
      },
      &error);
  EXPECT_FALSE(written);
  EXPECT_EQ(error, "cannot write " + path.string() + ": the encoder failed");
  EXPECT_EQ(rigc::testing::read_text(path), "old");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 1)
      << "a temporary file was left behind";
}

TEST(BackendFiles, AWriterThatThrowsIsAnErrorAndCleansUp) {
  rigc::testing::TempDir dir;
  const fs::path path = dir.path() / "out.txt";
  std::string error;
  const bool written = write_atomically(
      path,
      [](const fs::path& temporary, std::string*) -> bool {
        rigc::testing::write_text(temporary, "half");
        throw std::runtime_error("out of memory");
      },
      &error);
  EXPECT_FALSE(written);
  EXPECT_THAT(error, HasSubstr("out of memory"));
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

}  // namespace
}  // namespace rigc
