#include "dslr/buffer_pool.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

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

// The smaps fields of the mapping holding `address`: "VmFlags" ("hg": advised huge pages) and
// "Rss" (kB), each line as it stands.
struct MappingFields {
  std::string vm_flags;
  long rss_kb = -1;
};
MappingFields mapping_at(const void* address) {
  const auto wanted = reinterpret_cast<std::uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  MappingFields fields;
  while (std::getline(smaps, line)) {
    std::uintptr_t begin = 0, end = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> begin >> dash >> end && dash == '-') {
      if (inside) break;
      inside = begin <= wanted && wanted < end;
    } else if (inside && line.rfind("VmFlags:", 0) == 0) {
      fields.vm_flags = line;
    } else if (inside && line.rfind("Rss:", 0) == 0) {
      fields.rss_kb = std::stol(line.substr(4));
    }
  }
  return fields;
}

// Fresh frame buffers stay on 4 KB pages: on the VM this is measured on, a cold 2 MB page costs
// six times as much to fault in (see first_touch). They are populated before they are handed
// out, so the caller's loops take no faults.
TEST(BufferPool, FreshBuffersArePopulatedOnSmallPages) {
  release_pooled_buffers();
  constexpr std::size_t kValues = std::size_t{16} << 20;  // 64 MB of floats
  std::vector<float> frame = take_floats(kValues);
  const MappingFields fields = mapping_at(frame.data());
  ASSERT_FALSE(fields.vm_flags.empty()) << "no mapping found in /proc/self/smaps";
  EXPECT_EQ(fields.vm_flags.find(" hg"), std::string::npos) << fields.vm_flags;
  EXPECT_GE(fields.rss_kb, static_cast<long>(kValues * sizeof(float) / 1024));
  recycle(std::move(frame));
  release_pooled_buffers();
}

}  // namespace
}  // namespace rigc::dslr
