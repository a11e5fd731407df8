// The local executor: each variant that needs it runs as a `rigc sweep --run-task` child process
// (its output in the variant's log.txt), a few at a time.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "sweep/variants.h"

namespace rigc::sweep {

struct LocalOptions {
  std::filesystem::path rigc;  // the rigc program the tasks run
  // Variants at once. 1 by default: a variant's renderer, coverage and COLMAP each use every core
  // already, so two at once only share the cores and double the memory.
  int jobs = 1;
  // The backends whose variants run (`rigc sweep FILE --backend preview`); empty: every one.
  std::vector<std::string> backends;
};

// A task that did not finish with its numbers.
struct FailedTask {
  std::string variant, reason, log, job;  // job: Slurm's job id, empty locally
};

// Runs the variants whose outputs are missing or stale; progress (done / total, time left) to
// `log`. Returns the failed ones. A Ctrl-C stops the running tasks and rigc (io/child_processes).
std::vector<FailedTask> run_local(const std::filesystem::path& sweep_dir, const SweepSpec& spec,
                                  const std::vector<Variant>& variants, const LocalOptions& options,
                                  std::ostream& log);

// Why variant `dir` has no numbers: its result.json's reason, or `fallback`.
std::string failure_reason(const std::filesystem::path& dir, const std::string& key,
                           const std::string& fallback);

}  // namespace rigc::sweep
