// The process's standard streams: what `rigc` makes sure of before a verb runs and after it ends.
#pragma once

namespace rigc::cli {

// Before anything opens a file: a closed descriptor 0, 1 or 2 gets /dev/null (descriptor 1
// read-only, so that output to a closed standard output fails instead of vanishing, and the next
// file opened is never taken for standard output). SIGXFSZ is ignored, so a write past a
// file-size limit fails with EFBIG and is reported like a full disk instead of killing rigc.
void guard_standard_streams();

// After a verb: flushes standard output. When anything written to it was lost (`> /dev/full`, a
// closed descriptor), prints `rigc: error: cannot write to standard output: WHY` and returns 2
// (or the verb's own non-zero code); otherwise returns `code`.
int finish_standard_output(int code);

}  // namespace rigc::cli
