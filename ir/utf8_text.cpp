#include "ir/utf8_text.h"

namespace rigc {
namespace {

// The length of the well-formed UTF-8 sequence at `p`, or 0 if none starts there.
std::size_t sequence_length(const unsigned char* p, const unsigned char* end) {
  const unsigned char c = *p;
  if (c < 0x80) return 1;
  int extra = 0;
  unsigned char low = 0x80, high = 0xBF;  // the first continuation byte's range
  if (c >= 0xC2 && c <= 0xDF) {
    extra = 1;
  } else if (c >= 0xE0 && c <= 0xEF) {
    extra = 2;
    if (c == 0xE0) low = 0xA0;
    if (c == 0xED) high = 0x9F;
  } else if (c >= 0xF0 && c <= 0xF4) {
    extra = 3;
    if (c == 0xF0) low = 0x90;
    if (c == 0xF4) high = 0x8F;
  } else {
    return 0;
  }
  if (end - p <= extra || p[1] < low || p[1] > high) return 0;
  for (int k = 2; k <= extra; ++k) {
    if (p[k] < 0x80 || p[k] > 0xBF) return 0;
  }
  return static_cast<std::size_t>(extra) + 1;
}

}  // namespace

bool valid_utf8(std::string_view text) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const auto* end = p + text.size();
  while (p < end) {
    const std::size_t length = sequence_length(p, end);
    if (length == 0) return false;
    p += length;
  }
  return true;
}

std::string valid_utf8_text(std::string_view text) {
  if (valid_utf8(text)) return std::string(text);
  std::string out;
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const auto* end = p + text.size();
  while (p < end) {
    const std::size_t length = sequence_length(p, end);
    if (length == 0) {
      out += "\xEF\xBF\xBD";  // U+FFFD
      ++p;
    } else {
      out.append(reinterpret_cast<const char*>(p), length);
      p += length;
    }
  }
  return out;
}

}  // namespace rigc
