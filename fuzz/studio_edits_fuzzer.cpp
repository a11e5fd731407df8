// libFuzzer harness: fuzz::studio_edits (fuzz/entries.h) on each input.
#include <cstddef>
#include <cstdint>

#include "fuzz/entries.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rigc::fuzz::studio_edits({reinterpret_cast<const char*>(data), size});
  return 0;
}
