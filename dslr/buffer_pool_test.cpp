#include "dslr/buffer_pool.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::dslr {
namespace {

TEST(BufferPool, ReusesAFrameSizedBufferWithoutReallocating) {
  release_pooled_buffers();
  std::vector<float> first = take_floats(1 << 20);
  ASSERT_EQ(first.size(), 1u << 20);
  const float* memory = first.data();
  recycle(std::move(first));
  EXPECT_EQ(pooled_bytes(), (1u << 20) * sizeof(float));
  // A smaller request is served from the same memory, at the size asked for.
  const std::vector<float> second = take_floats(1000 * 1000);
  EXPECT_EQ(second.size(), 1000u * 1000);
  EXPECT_EQ(second.data(), memory);
  EXPECT_EQ(pooled_bytes(), 0u);
}

TEST(BufferPool, PicksTheSmallestBufferThatFits) {
  release_pooled_buffers();
  std::vector<std::uint8_t> big = take_bytes(8 << 20), small = take_bytes(2 << 20);
  const std::uint8_t* small_memory = small.data();
  recycle(std::move(big));
  recycle(std::move(small));
  EXPECT_EQ(take_bytes(2 << 20).data(), small_memory);
  EXPECT_EQ(pooled_bytes(), std::size_t{8} << 20);
  release_pooled_buffers();
  EXPECT_EQ(pooled_bytes(), 0u);
}

TEST(BufferPool, SmallBuffersAreNotKeptAndTheTotalIsBounded) {
  release_pooled_buffers();
  recycle(std::vector<std::uint16_t>(1000));
  EXPECT_EQ(pooled_bytes(), 0u);
  // Far more than the pool keeps: it stays under its bound (800 MB) however much comes back.
  for (int k = 0; k < 6; ++k) {
    std::vector<std::uint8_t> reserved;
    reserved.reserve(std::size_t{200} << 20);  // capacity counts; untouched pages cost nothing
    recycle(std::move(reserved));
  }
  EXPECT_LE(pooled_bytes(), std::size_t{800} << 20);
  EXPECT_GE(pooled_bytes(), std::size_t{600} << 20);
  release_pooled_buffers();
}

TEST(BufferPool, GrowsABufferThatIsTooSmall) {
  release_pooled_buffers();
  recycle(std::vector<float>(1 << 20, 5.0f));
  const std::vector<float> bigger = take_floats(3 << 20);
  EXPECT_EQ(bigger.size(), std::size_t{3} << 20);
  EXPECT_EQ(bigger.back(), 0.0f);  // the part past a reused buffer's old size is zeroed
  release_pooled_buffers();
}

// Over the mappings that overlap [begin, begin + bytes) in /proc/self/smaps: their VmFlags lines
// ("hg": advised huge pages, "nh": advised against them) and the sum of their AnonHugePages (kB).
struct MappingFields {
  std::vector<std::string> vm_flags;
  long anon_huge_kb = 0;
};
MappingFields mappings_over(const void* begin, std::size_t bytes) {
  const auto from = reinterpret_cast<std::uintptr_t>(begin), to = from + bytes;
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  MappingFields fields;
  while (std::getline(smaps, line)) {
    std::uintptr_t start = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> start >> dash >> end && dash == '-') {
      inside = start < to && from < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      fields.vm_flags.push_back(line);
    } else if (inside && line.rfind("AnonHugePages:", 0) == 0) {
      fields.anon_huge_kb += std::stol(line.substr(14));
    }
  }
  return fields;
}

// Fresh frame buffers stay on 4 KB pages: on the VM this is measured on, a cold 2 MB page costs
// six times as much to fault in (see first_touch). No part of the buffer is advised to take huge
// pages, none has them, and its inner pages are advised against them.
TEST(BufferPool, FreshBuffersStayOnSmallPages) {
  release_pooled_buffers();
  constexpr std::size_t kValues = std::size_t{16} << 20;  // 64 MB of floats
  std::vector<float> frame = take_floats(kValues);
  const MappingFields fields = mappings_over(frame.data(), kValues * sizeof(float));
  ASSERT_FALSE(fields.vm_flags.empty()) << "no mapping found in /proc/self/smaps";
  bool advised_against = false;
  for (const std::string& flags : fields.vm_flags) {
    EXPECT_THAT(flags, Not(HasSubstr(" hg")));
    advised_against = advised_against || flags.find(" nh") != std::string::npos;
  }
  EXPECT_TRUE(advised_against);
  EXPECT_EQ(fields.anon_huge_kb, 0);
  recycle(std::move(frame));
  release_pooled_buffers();
}

}  // namespace
}  // namespace rigc::dslr
