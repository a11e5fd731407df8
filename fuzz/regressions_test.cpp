// Replays every input the fuzzers found (tests/fuzz_regressions/<harness>/) through the
// harness's entry point: each once crashed, hung or ran out of memory, and must now be read or
// refused cleanly.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "fuzz/entries.h"

namespace rigc::fuzz {
namespace {

namespace fs = std::filesystem;

std::string read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(FuzzRegressions, EveryFoundInputIsReadOrRefusedCleanly) {
  const fs::path root = fs::path(RIGC_SOURCE_DIR) / "tests" / "fuzz_regressions";
  int replayed = 0;
  for (const Harness& harness : harnesses()) {
    const fs::path dir = root / harness.name;
    if (!fs::is_directory(dir)) continue;
    for (const fs::directory_entry& file : fs::directory_iterator(dir)) {
      if (!file.is_regular_file() || file.path().filename().string().starts_with(".")) continue;
      SCOPED_TRACE(file.path().string());
      EXPECT_NO_THROW(harness.entry(read_bytes(file.path())));
      ++replayed;
    }
  }
  EXPECT_GT(replayed, 0) << "no inputs under " << root.string();
}

TEST(FuzzRegressions, EveryHarnessHasAFuzzerSource) {
  for (const Harness& harness : harnesses()) {
    EXPECT_TRUE(fs::exists(fs::path(RIGC_SOURCE_DIR) / "fuzz" /
                           (std::string(harness.name) + "_fuzzer.cpp")))
        << harness.name;
  }
}

TEST(FuzzRegressions, ReadersRefuseGarbageWithoutThrowing) {
  for (const Harness& harness : harnesses()) {
    SCOPED_TRACE(harness.name);
    EXPECT_NO_THROW(harness.entry(""));
    EXPECT_NO_THROW(harness.entry(std::string("\xff\x00{[&*\n", 7)));
  }
}

}  // namespace
}  // namespace rigc::fuzz
