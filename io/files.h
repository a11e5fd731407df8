// Output files: atomic writes (a reader never sees half a file, a crash leaves the old file) and
// SHA-256 content hashes for the manifest.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "io/atomic_file.h"

struct evp_md_ctx_st;  // OpenSSL's EVP_MD_CTX

namespace rigc {

// Incremental SHA-256 (FIPS 180-4), for hashing large arrays without copying them. OpenSSL's
// implementation: it uses the CPU's SHA instructions where there are any, and the scene hash of
// a textured mesh runs on one core before the first shot can start.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void update(const void* data, std::size_t size);
  void update(std::string_view text) { update(text.data(), text.size()); }
  // The digest as 64 lowercase hex digits. Finishes the hash: call once.
  std::string hex_digest();

 private:
  evp_md_ctx_st* context_;
};

// SHA-256 of `bytes` as 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

}  // namespace rigc
