#include "io/allocator.h"

#include <malloc.h>

#include <climits>

namespace rigc {

void keep_freed_memory() {
  // No mmap'd chunks (all blocks come from the heap and return to it), and no trimming of the
  // heap's top after a free.
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, INT_MAX);
}

}  // namespace rigc
