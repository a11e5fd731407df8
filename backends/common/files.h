// Output files: atomic writes (a reader never sees half a file, a crash leaves the old file) and
// SHA-256 content hashes for the manifest.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

namespace rigc::backends {

// Writes `bytes` to a temporary file beside `path` (unique suffix), then renames it over `path`.
// The folder must exist. On failure removes the temporary file, sets `error` (if not null) to
// one line naming the path and returns false. Never throws.
bool write_file_atomically(const std::filesystem::path& path, std::string_view bytes,
                           std::string* error);

// Incremental SHA-256 (FIPS 180-4), for hashing large arrays without copying them.
class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t size);
  void update(std::string_view text) { update(text.data(), text.size()); }
  // The digest as 64 lowercase hex digits. Finishes the hash: call once.
  std::string hex_digest();

 private:
  void compress(const std::uint8_t* block);

  std::array<std::uint32_t, 8> state_;
  std::array<std::uint8_t, 64> buffer_{};
  std::size_t buffered_ = 0;
  std::uint64_t total_bytes_ = 0;
};

// SHA-256 of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace rigc::backends
