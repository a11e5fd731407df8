#include "dslr/mask_png.h"

#include <zlib.h>

#include <array>
#include <bit>
#include <cstring>

namespace rigc::dslr {
namespace {

// Deflate's bit stream: fields are packed from the least significant bit of each byte on.
class BitWriter {
 public:
  explicit BitWriter(std::string& out) : out_(out) {}
  void put(std::uint32_t bits, int count) {  // count <= 32
    buffer_ |= static_cast<std::uint64_t>(bits) << filled_;
    filled_ += count;
    while (filled_ >= 8) {
      out_.push_back(static_cast<char>(buffer_ & 0xFF));
      buffer_ >>= 8;
      filled_ -= 8;
    }
  }
  void flush() {
    if (filled_ > 0) out_.push_back(static_cast<char>(buffer_ & 0xFF));
    buffer_ = 0;
    filled_ = 0;
  }

 private:
  std::string& out_;
  std::uint64_t buffer_ = 0;
  int filled_ = 0;
};

// A Huffman code is sent from its most significant bit on: reversed for BitWriter.
constexpr std::uint32_t reversed(std::uint32_t code, int length) {
  std::uint32_t out = 0;
  for (int i = 0; i < length; ++i) out |= ((code >> i) & 1u) << (length - 1 - i);
  return out;
}

struct Code {
  std::uint32_t bits;
  int length;
};

// The fixed literal/length code (RFC 1951, 3.2.6).
constexpr Code fixed_code(int symbol) {
  if (symbol < 144) return {reversed(0x30 + symbol, 8), 8};
  if (symbol < 256) return {reversed(0x190 + symbol - 144, 9), 9};
  if (symbol < 280) return {reversed(symbol - 256, 7), 7};
  return {reversed(0xC0 + symbol - 280, 8), 8};
}

constexpr std::array<Code, 288> kFixedCodes = [] {
  std::array<Code, 288> codes{};
  for (int s = 0; s < 288; ++s) codes[s] = fixed_code(s);
  return codes;
}();

// Lengths 3..258: symbols 257..285, their base lengths and extra bits.
constexpr std::array<int, 29> kLengthBase = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                             15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                             67, 83, 99, 115, 131, 163, 195, 227, 258};
constexpr std::array<int, 29> kLengthExtra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                              2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
constexpr int kMaxMatch = 258;
constexpr std::uint32_t kAdlerModulus = 65521;

class RunEncoder {
 public:
  explicit RunEncoder(std::string& out) : bits_(out) {
    bits_.put(1, 1);  // BFINAL: this is the only block
    bits_.put(1, 2);  // BTYPE 01: fixed Huffman codes
  }

  // `length` (>= 1) more bytes of `value` in the stream.
  void add_run(std::uint8_t value, std::uint64_t length) {
    update_adler(value, length);
    if (has_previous_ && previous_ == value) {
      match(length);  // the run goes on from the last byte sent
      return;
    }
    literal(value);
    previous_ = value;
    has_previous_ = true;
    if (length > 1) match(length - 1);
  }

  // Ends the block; the stream's Adler-32.
  std::uint32_t finish() {
    put_symbol(256);
    bits_.flush();
    return (adler_b_ << 16) | adler_a_;
  }

 private:
  void put_symbol(int symbol) { bits_.put(kFixedCodes[symbol].bits, kFixedCodes[symbol].length); }

  void literal(std::uint8_t value) { put_symbol(value); }

  // `count` copies of the previous byte: matches at distance 1, and literals for a tail below
  // deflate's shortest match.
  void match(std::uint64_t count) {
    while (count >= 3) {
      const int length = static_cast<int>(count > kMaxMatch ? kMaxMatch : count);
      // A 258 that would leave one or two bytes behind leaves three instead (two matches).
      const int take = (count > kMaxMatch && count - kMaxMatch < 3) ? kMaxMatch - 3 : length;
      put_length(take);
      bits_.put(0, 5);  // distance code 0: distance 1, no extra bits
      count -= take;
    }
    for (; count > 0; --count) literal(previous_);
  }

  void put_length(int length) {
    int index = 28;
    while (kLengthBase[index] > length) --index;
    put_symbol(257 + index);
    if (kLengthExtra[index] > 0) {
      bits_.put(static_cast<std::uint32_t>(length - kLengthBase[index]), kLengthExtra[index]);
    }
  }

  // Adler-32 over `length` bytes of `value` at once: a grows by length·value, and b by the
  // sum of a after each byte, length·a + value·length(length+1)/2.
  void update_adler(std::uint8_t value, std::uint64_t length) {
    const std::uint64_t n = length % kAdlerModulus;
    // length(length+1)/2 mod M, from whichever factor is even.
    const std::uint64_t triangle =
        length % 2 == 0 ? ((length / 2) % kAdlerModulus) * ((length + 1) % kAdlerModulus)
                        : (length % kAdlerModulus) * (((length + 1) / 2) % kAdlerModulus);
    adler_b_ = static_cast<std::uint32_t>(
        (adler_b_ + n * adler_a_ + value * (triangle % kAdlerModulus)) % kAdlerModulus);
    adler_a_ = static_cast<std::uint32_t>((adler_a_ + n * value) % kAdlerModulus);
  }

  BitWriter bits_;
  std::uint8_t previous_ = 0;
  bool has_previous_ = false;
  std::uint32_t adler_a_ = 1, adler_b_ = 0;
};

// The index of the first byte in [begin, end) that is not `value` (end if none): eight bytes
// at a time.
std::size_t run_end(const std::uint8_t* row, std::size_t begin, std::size_t end,
                    std::uint8_t value) {
  const std::uint64_t pattern = 0x0101010101010101ull * value;
  std::size_t i = begin;
  for (; i + 8 <= end; i += 8) {
    std::uint64_t word;
    std::memcpy(&word, row + i, sizeof word);
    const std::uint64_t differ = word ^ pattern;
    // Little-endian: the lowest set bit is in the first differing byte.
    if (differ != 0) return i + static_cast<std::size_t>(std::countr_zero(differ)) / 8;
  }
  while (i < end && row[i] == value) ++i;
  return i;
}

void put_u32_big_endian(std::string& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<char>(value >> shift));
}

// Appends a chunk: length, type, data, CRC-32 of type and data.
void put_chunk(std::string& out, const char type[4], const std::string& data) {
  put_u32_big_endian(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t type_at = out.size();
  out.append(type, 4);
  out += data;
  const auto* crc_from = reinterpret_cast<const Bytef*>(out.data() + type_at);
  put_u32_big_endian(out, static_cast<std::uint32_t>(crc32(crc32(0L, Z_NULL, 0), crc_from,
                                                           static_cast<uInt>(4 + data.size()))));
}

}  // namespace

std::string encode_mask_png(ImageView<const std::uint8_t> mask) {
  const std::uint8_t* pixels = mask.values;
  const int width = mask.width, height = mask.height;
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string header;
  put_u32_big_endian(header, static_cast<std::uint32_t>(width));
  put_u32_big_endian(header, static_cast<std::uint32_t>(height));
  header += std::string("\x08\x00\x00\x00\x00", 5);  // 8 bits, greyscale, deflate, no interlace
  put_chunk(png, "IHDR", header);

  // zlib header: deflate with a 32 KB window, fastest-level flag, (0x78 << 8 | 0x01) % 31 == 0.
  std::string stream("\x78\x01", 2);
  std::uint32_t adler = 0;
  {
    RunEncoder encoder(stream);
    const std::size_t row_bytes = static_cast<std::size_t>(width);
    for (int y = 0; y < height; ++y) {
      encoder.add_run(0, 1);  // filter type 0 (none) before each row
      const std::uint8_t* row = pixels + static_cast<std::size_t>(y) * row_bytes;
      for (std::size_t x = 0; x < row_bytes;) {
        const std::size_t end = run_end(row, x, row_bytes, row[x]);
        encoder.add_run(row[x], end - x);
        x = end;
      }
    }
    adler = encoder.finish();
  }
  put_u32_big_endian(stream, adler);
  put_chunk(png, "IDAT", stream);
  put_chunk(png, "IEND", std::string());
  return png;
}

}  // namespace rigc::dslr
