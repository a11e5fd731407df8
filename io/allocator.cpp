#include "io/allocator.h"

#include <malloc.h>

#include <algorithm>
#include <climits>
#include <thread>

namespace rigc {

void keep_freed_memory() {
  // No mmap'd chunks (all blocks come from the heap and return to it), and no trimming of the
  // heap's top after a free.
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

void share_heap_arenas() {
  mallopt(M_ARENA_MAX, static_cast<int>(std::max(2u, std::thread::hardware_concurrency())));
}

}  // namespace rigc
