// Frame-sized buffers kept between shots. A full-resolution frame is 240 MB of floats; a fresh
// vector of that size is zeroed by one thread (and, unless keep_freed_memory() holds the heap,
// faulted in page by page) on every shot. Buffers handed back here are reused as they are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rigc::dslr {

// How a buffer's memory is walked, which decides its page size when it is first allocated.
// kTiled: in 2D neighbourhoods (raster tiles, blur and warp gathers), where one 4 KB page holds
// part of one row and the TLB would miss on every row: 2 MB pages. kStreamed: in order, front to
// back (the sensor's codes, the fixed pattern), where a 4 KB page costs the TLB nothing more
// and faults in for much less (see first_touch in buffer_pool.cpp).
enum class Access { kTiled, kStreamed };

// A vector of exactly `size` elements. Its contents are UNSPECIFIED (a reused buffer keeps what
// it held): the caller writes every element it reads.
std::vector<float> take_floats(std::size_t size);
std::vector<std::uint8_t> take_bytes(std::size_t size, Access access = Access::kTiled);
std::vector<std::uint16_t> take_words(std::size_t size, Access access = Access::kTiled);

// Hands a buffer back for a later take_*(). Small buffers are simply freed, and the pool keeps
// a bounded number of bytes, so it never holds more than a frame's working set.
void recycle(std::vector<float>&& buffer);
void recycle(std::vector<std::uint8_t>&& buffer);
void recycle(std::vector<std::uint16_t>&& buffer);

// Resizes `buffer` to `size`; new memory for kTiled access is asked for in transparent huge pages
// (2 MB), so a first frame faults in 120 pages instead of 60 000 per 240 MB. Existing values are
// kept.
void resize_frame_buffer(std::vector<float>& buffer, std::size_t size);
void resize_frame_buffer(std::vector<std::uint8_t>& buffer, std::size_t size,
                         Access access = Access::kTiled);
void resize_frame_buffer(std::vector<std::int8_t>& buffer, std::size_t size,
                         Access access = Access::kTiled);
void resize_frame_buffer(std::vector<std::uint16_t>& buffer, std::size_t size,
                         Access access = Access::kTiled);

// Bytes the pool holds now (for tests and the memory report).
std::size_t pooled_bytes();
// Frees everything the pool holds.
void release_pooled_buffers();

}  // namespace rigc::dslr
