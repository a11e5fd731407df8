// Frame-sized buffers kept between shots. A full-resolution frame is 240 MB of floats; a fresh
// vector of that size is zeroed by one thread (and, unless keep_freed_memory() holds the heap,
// faulted in page by page) on every shot. Buffers handed back here are reused as they are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rigc::dslr {

// A vector of exactly `size` elements. Its contents are UNSPECIFIED (a reused buffer keeps what
// it held): the caller writes every element it reads.
std::vector<float> take_floats(std::size_t size);
std::vector<std::uint8_t> take_bytes(std::size_t size);
std::vector<std::uint16_t> take_words(std::size_t size);

// Hands a buffer back for a later take_*(). Small buffers are simply freed, and the pool keeps
// a bounded number of bytes, so it never holds more than a frame's working set.
void recycle(std::vector<float>&& buffer);
void recycle(std::vector<std::uint8_t>&& buffer);
void recycle(std::vector<std::uint16_t>&& buffer);

// Resizes `buffer` to `size`; new memory is faulted in with every core (by the kernel where it
// can), on 4 KB pages, before the caller's loops touch it. Existing values are kept.
void resize_frame_buffer(std::vector<float>& buffer, std::size_t size);
void resize_frame_buffer(std::vector<std::uint8_t>& buffer, std::size_t size);
void resize_frame_buffer(std::vector<std::int8_t>& buffer, std::size_t size);
void resize_frame_buffer(std::vector<std::uint16_t>& buffer, std::size_t size);

// Bytes the pool holds now (for tests and the memory report).
std::size_t pooled_bytes();
// Frees everything the pool holds.
void release_pooled_buffers();

}  // namespace rigc::dslr
