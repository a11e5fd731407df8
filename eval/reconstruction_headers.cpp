#include "eval/reconstruction_headers.h"

#include <fmt/format.h>

#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

namespace rigc::eval {

namespace fs = std::filesystem;

namespace {

using Bytes = std::uintmax_t;
constexpr Bytes kTooMany = std::numeric_limits<Bytes>::max();

// count * each, saturated.
Bytes times(Bytes count, Bytes each) {
  return each != 0 && count > kTooMany / each ? kTooMany : count * each;
}

// A count as a header writes it; kTooMany for one that is no count or past 2^64.
Bytes count_of(const std::string& word) {
  if (word.empty() || word.find_first_not_of("0123456789") != std::string::npos) return kTooMany;
  if (word.size() > 19) return kTooMany;
  return std::stoull(word);
}

std::string overclaim(Bytes count, const std::string& what, Bytes least, Bytes held) {
  return fmt::format("announces {} {} (at least {} bytes) but holds {} bytes after its header",
                     count == kTooMany ? std::string("more than 2^64") : std::to_string(count),
                     what, least == kTooMany ? std::string("2^64") : std::to_string(least), held);
}

// The header's lines up to and including the one starting with `last`, at most 64 KB; the bytes
// they take in `length`. Empty when there is no such line.
std::vector<std::string> header_lines(std::istream& in, const std::string& last, Bytes* length) {
  std::vector<std::string> lines;
  Bytes taken = 0;
  for (std::string line; taken < (64u << 10) && std::getline(in, line);) {
    taken += line.size() + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
    if (line.rfind(last, 0) == 0) {
      *length = taken;
      return lines;
    }
  }
  return {};
}

// PLY: each element at least its scalar properties' bytes and its lists' counts (binary), or two
// characters a property (ASCII).
std::string ply_overclaims(std::istream& in, Bytes size) {
  Bytes header = 0;
  const auto lines = header_lines(in, "end_header", &header);
  if (lines.empty()) return "";
  const bool ascii = lines.size() > 1 && lines[1].find("ascii") != std::string::npos;
  struct Element {
    std::string name;
    Bytes count = 0, each = 0;
  };
  std::vector<Element> elements;
  for (const auto& line : lines) {
    std::istringstream words(line);
    std::string keyword, type, count_type, count;
    words >> keyword;
    if (keyword == "element") {
      elements.emplace_back();
      words >> elements.back().name >> count;
      elements.back().count = count_of(count);
    } else if (keyword == "property" && !elements.empty()) {
      words >> type;
      if (type == "list") words >> count_type;
      elements.back().each += ascii ? 2 : ply_type_bytes(type == "list" ? count_type : type);
    }
  }
  Bytes least = 0;
  const Element* largest = nullptr;
  for (const auto& e : elements) {
    const Bytes bytes = times(e.count, e.each);
    least = bytes > kTooMany - least ? kTooMany : least + bytes;
    if (!largest || bytes > times(largest->count, largest->each)) largest = &e;
  }
  const Bytes held = size - std::min(size, header);
  if (least <= held || !largest) return "";
  return overclaim(largest->count, largest->name + " elements", least, held);
}

// PCD: POINTS (or WIDTH x HEIGHT) points of the fields' SIZE x COUNT bytes (binary), two
// characters a value (ASCII); compressed data at most 256 times smaller (LZF's best is about 90).
std::string pcd_overclaims(std::istream& in, Bytes size) {
  Bytes header = 0;
  const auto lines = header_lines(in, "DATA", &header);
  if (lines.empty()) return "";
  std::vector<Bytes> sizes, counts;
  Bytes points = 0, width = 0, height = 1;
  std::string data;
  for (const auto& line : lines) {
    std::istringstream words(line);
    std::string keyword, word;
    words >> keyword;
    if (keyword == "SIZE") {
      while (words >> word) sizes.push_back(count_of(word));
    } else if (keyword == "COUNT") {
      while (words >> word) counts.push_back(count_of(word));
    } else if (keyword == "POINTS" && words >> word) {
      points = count_of(word);
    } else if (keyword == "WIDTH" && words >> word) {
      width = count_of(word);
    } else if (keyword == "HEIGHT" && words >> word) {
      height = count_of(word);
    } else if (keyword == "DATA") {
      words >> data;
    }
  }
  if (points == 0) points = times(width, height);
  Bytes point_bytes = 0;
  for (std::size_t f = 0; f < sizes.size(); ++f) {
    const Bytes n = f < counts.size() ? counts[f] : 1;
    point_bytes = std::min(kTooMany - 1, point_bytes) + times(n, data == "ascii" ? 2 : sizes[f]);
  }
  const Bytes held = size - std::min(size, header);
  const Bytes least = times(points, point_bytes);
  const Bytes holdable = data == "binary_compressed" ? times(held, 256) : held;
  return least > holdable ? overclaim(points, "points", least, held) : "";
}

// Binary STL: an 80-byte header, a 32-bit triangle count, 50 bytes a triangle. An ASCII STL
// ("solid" and a size no binary count explains) states no count.
std::string stl_overclaims(std::istream& in, Bytes size) {
  char head[84] = {};
  if (!in.read(head, sizeof head)) return "";
  const auto* b = reinterpret_cast<const unsigned char*>(head + 80);
  const Bytes count = b[0] | b[1] << 8 | b[2] << 16 | static_cast<Bytes>(b[3]) << 24;
  const Bytes least = 84 + 50 * count;
  if (std::string(head, 5) == "solid" && least != size) return "";
  return least > size ? overclaim(count, "triangles", least, size - 84) : "";
}

// PTS: a point count, then a line (at least "0 0 0\n") a point.
std::string pts_overclaims(std::istream& in, Bytes size) {
  std::string first;
  if (!std::getline(in, first)) return "";
  std::istringstream words(first);
  std::string count_text, rest;
  if (!(words >> count_text) || words >> rest) return "";  // not a count line
  const Bytes count = count_of(count_text);
  const Bytes held = size - std::min<Bytes>(size, first.size() + 1);
  const Bytes least = times(count, 6);
  return least > held ? overclaim(count, "points", least, held) : "";
}

}  // namespace

int ply_type_bytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32") {
    return 4;
  }
  if (type == "double" || type == "float64") return 8;
  return 0;
}

std::string header_overclaims(const fs::path& path, const std::string& ext) {
  std::error_code ec;
  const Bytes size = fs::file_size(path, ec);
  if (ec) return "";
  std::ifstream in(path, std::ios::binary);
  if (ext == ".ply") return ply_overclaims(in, size);
  if (ext == ".pcd") return pcd_overclaims(in, size);
  if (ext == ".stl") return stl_overclaims(in, size);
  if (ext == ".pts") return pts_overclaims(in, size);
  return "";
}

}  // namespace rigc::eval
