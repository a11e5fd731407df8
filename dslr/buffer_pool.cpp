#include "dslr/buffer_pool.h"

#include <sys/mman.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <type_traits>

namespace rigc::dslr {
namespace {

// Below this a fresh vector is cheap (glibc reuses its heap), so pooling only adds bookkeeping.
constexpr std::size_t kMinPooledBytes = std::size_t{1} << 20;
// About two full-resolution frames of floats plus their masks and depths: what one shot in
// flight and one being written hold between them.
constexpr std::size_t kMaxPooledBytes = std::size_t{800} << 20;

template <typename T>
struct Shelf {
  std::vector<std::vector<T>> buffers;
};

struct Pool {
  std::mutex mutex;
  Shelf<float> floats;
  Shelf<std::uint8_t> bytes;
  Shelf<std::uint16_t> words;
  std::size_t held_bytes = 0;

  template <typename T>
  Shelf<T>& shelf() {
    if constexpr (std::is_same_v<T, float>) return floats;
    if constexpr (std::is_same_v<T, std::uint8_t>) return bytes;
    if constexpr (std::is_same_v<T, std::uint16_t>) return words;
  }
};

Pool& pool() {
  static Pool instance;
  return instance;
}

template <typename T>
std::size_t bytes_of(const std::vector<T>& buffer) {
  return buffer.capacity() * sizeof(T);
}

// Faults fresh memory in with every core. Its first touch is the expensive part of a fresh
// buffer (a full-resolution shot first asks for about 800 MB). The kernel populates the pages
// itself where it can (Linux 5.14 and later): the pages come zeroed, so a memset over them would
// only write them a second time.
//
// The pages are asked to stay 4 KB ones (MADV_NOHUGEPAGE, which also holds where THP is
// "always"): on a virtual machine a fresh 2 MB page can cost several times as much to fault in.
// Later shots reuse the pool's buffers, so small pages cost them nothing.
void first_touch(void* data, std::size_t bytes) {
  constexpr std::uintptr_t kPiece = std::uintptr_t{2} << 20, kPage = 4096;
  const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t end = start + bytes;
  // The advice needs page boundaries: the pages wholly inside the buffer.
  const std::uintptr_t first_whole_page = (start + kPage - 1) & ~(kPage - 1);
  const std::uintptr_t last_whole_page_end = end & ~(kPage - 1);
  if (last_whole_page_end > first_whole_page) {
    madvise(reinterpret_cast<void*>(first_whole_page), last_whole_page_end - first_whole_page,
            MADV_NOHUGEPAGE);
  }
  // Pieces of 2 MB, one per task. madvise needs a page boundary: the first piece starts at the
  // page holding `data` (populating a page changes none of its bytes).
  const std::uintptr_t first = start & ~(kPiece - 1);
  tbb::parallel_for(std::uintptr_t{0}, (end - first + kPiece - 1) / kPiece, [&](std::uintptr_t k) {
    const std::uintptr_t piece = std::max(first + k * kPiece, start & ~(kPage - 1));
    const std::uintptr_t piece_end = std::min(end, first + (k + 1) * kPiece);
#ifdef MADV_POPULATE_WRITE
    if (madvise(reinterpret_cast<void*>(piece), piece_end - piece, MADV_POPULATE_WRITE) == 0) {
      return;
    }
#endif
    const std::uintptr_t from = std::max(start, piece);
    std::memset(reinterpret_cast<void*>(from), 0, piece_end - from);
  });
}

template <typename T>
void resize_populated(std::vector<T>& buffer, std::size_t size) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (size > buffer.capacity() && size * sizeof(T) >= kMinPooledBytes) {
    std::vector<T> bigger;
    bigger.reserve(size);  // allocated, not yet touched
    // Trivial element type: the allocation's bytes may be written before the elements exist
    // (a container-overflow checker would flag it; resize then zeroes them again, warm).
    first_touch(bigger.data(), size * sizeof(T));
    bigger.assign(buffer.begin(), buffer.end());
    buffer.swap(bigger);
  }
  buffer.resize(size);
}

template <typename T>
std::vector<T> take(std::size_t size) {
  std::vector<T> out;
  if (size * sizeof(T) >= kMinPooledBytes) {
    Pool& p = pool();
    std::lock_guard lock(p.mutex);
    auto& buffers = p.shelf<T>().buffers;
    // The smallest buffer that holds `size` without growing.
    auto best = buffers.end();
    for (auto it = buffers.begin(); it != buffers.end(); ++it) {
      if (it->capacity() >= size && (best == buffers.end() || it->capacity() < best->capacity())) {
        best = it;
      }
    }
    if (best != buffers.end()) {
      out = std::move(*best);
      buffers.erase(best);
      p.held_bytes -= bytes_of(out);
    }
  }
  // Only the part past the old size is written (value-initialised) here.
  resize_populated(out, size);
  return out;
}

template <typename T>
void give_back(std::vector<T>&& buffer) {
  std::vector<T> local = std::move(buffer);
  const std::size_t bytes = bytes_of(local);
  if (bytes < kMinPooledBytes) return;
  Pool& p = pool();
  std::vector<std::vector<T>> evicted;  // freed outside the lock
  {
    std::lock_guard lock(p.mutex);
    if (bytes > kMaxPooledBytes) return;
    auto& buffers = p.shelf<T>().buffers;
    // Room is made by dropping this type's smallest buffers first; if that is not enough the
    // newcomer is dropped instead.
    std::sort(buffers.begin(), buffers.end(),
              [](const auto& a, const auto& b) { return a.capacity() > b.capacity(); });
    while (p.held_bytes + bytes > kMaxPooledBytes && !buffers.empty()) {
      p.held_bytes -= bytes_of(buffers.back());
      evicted.push_back(std::move(buffers.back()));
      buffers.pop_back();
    }
    if (p.held_bytes + bytes > kMaxPooledBytes) return;
    p.held_bytes += bytes;
    buffers.push_back(std::move(local));
  }
}

}  // namespace

std::vector<float> take_floats(std::size_t size) {
  return take<float>(size);
}
std::vector<std::uint8_t> take_bytes(std::size_t size) {
  return take<std::uint8_t>(size);
}
std::vector<std::uint16_t> take_words(std::size_t size) {
  return take<std::uint16_t>(size);
}
void recycle(std::vector<float>&& buffer) {
  give_back(std::move(buffer));
}
void recycle(std::vector<std::uint8_t>&& buffer) {
  give_back(std::move(buffer));
}
void recycle(std::vector<std::uint16_t>&& buffer) {
  give_back(std::move(buffer));
}

void resize_frame_buffer(std::vector<float>& buffer, std::size_t size) {
  resize_populated(buffer, size);
}
void resize_frame_buffer(std::vector<std::uint8_t>& buffer, std::size_t size) {
  resize_populated(buffer, size);
}
void resize_frame_buffer(std::vector<std::int8_t>& buffer, std::size_t size) {
  resize_populated(buffer, size);
}
void resize_frame_buffer(std::vector<std::uint16_t>& buffer, std::size_t size) {
  resize_populated(buffer, size);
}

std::size_t pooled_bytes() {
  Pool& p = pool();
  std::lock_guard lock(p.mutex);
  return p.held_bytes;
}

void release_pooled_buffers() {
  Pool& p = pool();
  Shelf<float> floats;
  Shelf<std::uint8_t> bytes;
  Shelf<std::uint16_t> words;
  {
    std::lock_guard lock(p.mutex);
    std::swap(floats, p.floats);
    std::swap(bytes, p.bytes);
    std::swap(words, p.words);
    p.held_bytes = 0;
  }
}

}  // namespace rigc::dslr
