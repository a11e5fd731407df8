// Heap policy for a process that renders frame after frame.
#pragma once

namespace rigc {

// Keeps freed memory in the process for the next frame instead of handing it back to the kernel.
// glibc serves blocks above 32 MB with fresh mmaps and returns them on free, so every frame paid
// for zeroing its buffers page by page again (a third to a half of a coverage run went there).
// Peak memory is unchanged: the same buffers are reused. Call once, first thing in main.
void keep_freed_memory();

// For a long-lived server: one heap arena per core instead of glibc's eight. Each of the studio's
// worker threads otherwise took an arena of its own, whose freed (and kept) memory no other
// thread reuses: an hour of edits grew without bound.
void share_heap_arenas();

}  // namespace rigc
