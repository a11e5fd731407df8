// STL files checked before Assimp reads them: Assimp loads an ASCII STL cut mid-facet as the
// facets before the cut, and refuses a binary STL whose header's triangle count is wrong with
// "Failed to determine STL storage representation".
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "assets/model_loading.h"

namespace rigc::loading {
namespace {

constexpr std::size_t kBinaryHeaderBytes = 84;  // 80 bytes of text, then the triangle count
constexpr std::size_t kBinaryTriangleBytes = 50;

// The whitespace-separated words of an ASCII STL, each with its line.
class StlWords {
 public:
  explicit StlWords(std::string_view text) : text_(text) {}

  // The next word, or empty at the end.
  std::string_view next() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
      if (text_[pos_++] == '\n') ++line_;
    }
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    return text_.substr(start, pos_ - start);
  }

  // Skips the rest of the line (a solid's name).
  void skip_line() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
  }

  int line() const { return line_; }
  std::size_t position() const { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

bool is_number(std::string_view word) {
  if (!word.empty() && word.front() == '+') word.remove_prefix(1);
  double value = 0;
  const auto [ptr, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc() && ptr == word.data() + word.size();
}

// `facet normal x y z outer loop vertex x y z (x3) endloop endfacet`, the word `facet` read.
void check_ascii_facet(StlWords& words, int facets_before) {
  const int start = words.line();
  auto expect = [&](std::string_view wanted) {
    const std::string_view word = words.next();
    if (word.empty()) {
      fail(
          "is truncated: the ASCII STL ends inside the facet that starts at line {} ({} "
          "whole facets before it)",
          start, facets_before);
    }
    if (lower(std::string(word)) != wanted) {
      fail("line {}: expected '{}' in the facet that starts at line {}, found '{}'", words.line(),
           wanted, start, one_line(std::string(word.substr(0, 40))));
    }
  };
  auto numbers = [&] {
    for (int i = 0; i < 3; ++i) {
      const std::string_view word = words.next();
      if (word.empty()) expect("a number");
      if (!is_number(word)) {
        fail("line {}: '{}' is not a number", words.line(),
             one_line(std::string(word.substr(0, 40))));
      }
    }
  };
  expect("normal");
  numbers();
  expect("outer");
  expect("loop");
  for (int corner = 0; corner < 3; ++corner) {
    expect("vertex");
    numbers();
  }
  expect("endloop");
  expect("endfacet");
}

// A byte range of the file: [begin, end).
using Span = std::pair<std::size_t, std::size_t>;

// One or more `solid name ... endsolid name`; returns the solids without facets, which Assimp
// refuses ("The mesh ... contains no vertices") though they are harmless.
std::vector<Span> check_ascii_stl(std::string_view text) {
  StlWords words(text);
  int facets = 0;
  std::vector<Span> empty_solids;
  for (std::string_view word = words.next(); !word.empty(); word = words.next()) {
    const std::size_t solid_begin = static_cast<std::size_t>(word.data() - text.data());
    const int facets_before = facets;
    if (lower(std::string(word)) != "solid") {
      fail("line {}: expected 'solid', found '{}'", words.line(),
           one_line(std::string(word.substr(0, 40))));
    }
    words.skip_line();
    for (word = words.next(); lower(std::string(word)) == "facet"; word = words.next()) {
      check_ascii_facet(words, facets);
      ++facets;
    }
    if (word.empty()) {
      fail("is truncated: the ASCII STL ends after {} facets without 'endsolid'", facets);
    }
    if (lower(std::string(word)) != "endsolid") {
      fail("line {}: expected 'facet' or 'endsolid', found '{}'", words.line(),
           one_line(std::string(word.substr(0, 40))));
    }
    words.skip_line();
    if (facets == facets_before) empty_solids.emplace_back(solid_begin, words.position());
  }
  if (facets == 0) fail("contains no triangles (an ASCII STL without facets)");
  return empty_solids;
}

std::uint32_t little_endian_u32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
         static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24;
}

// Assimp's test: "solid" after leading whitespace, and no byte above 127 in the first 500.
bool looks_ascii(const std::vector<unsigned char>& bytes) {
  std::size_t i = 0;
  while (i < bytes.size() && std::isspace(bytes[i])) ++i;
  if (bytes.size() - i < 6 || std::memcmp(bytes.data() + i, "solid", 5) != 0) return false;
  for (std::size_t k = 0; k < std::min<std::size_t>(bytes.size(), 500); ++k) {
    if (bytes[k] > 127) return false;
  }
  return true;
}

// A binary STL whose size disagrees with its header's count: the count is mended to what the
// file holds (with a warning) when the body is whole triangles, otherwise it is an error.
void mend_binary_count(StlFile* stl, std::uint32_t claimed) {
  std::vector<unsigned char>& bytes = stl->bytes;
  const std::size_t body = bytes.size() - kBinaryHeaderBytes;
  const std::size_t expected = std::size_t{claimed} * kBinaryTriangleBytes;
  if (body % kBinaryTriangleBytes == 0) {
    const auto held = static_cast<std::uint32_t>(body / kBinaryTriangleBytes);
    for (int k = 0; k < 4; ++k) bytes[80 + k] = static_cast<unsigned char>(held >> (8 * k));
    stl->warnings.push_back(fmt::format(
        "binary STL: the header claims {} triangles but the file holds {}; read {} (the file "
        "may be cut short)",
        claimed, held, held));
  } else if (body > expected) {
    bytes.resize(kBinaryHeaderBytes + expected);
    stl->warnings.push_back(
        fmt::format("binary STL: ignored {} bytes after the {} triangles its header claims",
                    body - expected, claimed));
  } else {
    fail("is truncated: its header claims {} triangles ({} bytes) but the file has {} bytes",
         claimed, kBinaryHeaderBytes + expected, bytes.size());
  }
  if (bytes.size() == kBinaryHeaderBytes) fail("contains no triangles (an empty binary STL)");
}

}  // namespace

StlFile check_stl(const std::string& path) {
  StlFile stl;
  stl.bytes = read_file_bytes(path);
  const std::vector<unsigned char>& bytes = stl.bytes;
  if (bytes.size() >= kBinaryHeaderBytes) {
    const std::uint32_t claimed = little_endian_u32(bytes.data() + 80);
    const std::size_t body = bytes.size() - kBinaryHeaderBytes;
    if (body == std::size_t{claimed} * kBinaryTriangleBytes) {
      if (claimed == 0) fail("contains no triangles (an empty binary STL)");
      return stl;
    }
    if (!looks_ascii(bytes)) {
      mend_binary_count(&stl, claimed);
      return stl;
    }
  }
  if (!looks_ascii(bytes)) {
    fail(
        "is not an STL file: too small for a binary STL ({} bytes) and not ASCII STL (which "
        "starts with 'solid')",
        bytes.size());
  }
  const std::vector<Span> empty_solids =
      check_ascii_stl(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  for (auto it = empty_solids.rbegin(); it != empty_solids.rend(); ++it) {
    stl.bytes.erase(stl.bytes.begin() + static_cast<std::ptrdiff_t>(it->first),
                    stl.bytes.begin() + static_cast<std::ptrdiff_t>(it->second));
  }
  return stl;
}

}  // namespace rigc::loading
