// The Slurm executor: one job array, a task per variant, each running `rigc sweep --run-task` on
// the shared sweep folder; sbatch, squeue and scontrol run as argument vectors
// (io/child_processes), so no value reaches a shell. slurm.json in the sweep folder records each
// variant's task.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "sweep/local_executor.h"
#include "sweep/variants.h"

namespace rigc::sweep {

struct SlurmOptions {
  std::filesystem::path rigc;            // the rigc the tasks run (on the shared file system)
  std::vector<std::string> sbatch_args;  // passed to sbatch as they are, one argument each
  bool wait = true;                      // wait for the tasks, with progress
  bool retry_failed = false;             // submit only the variants whose task failed
  double poll_seconds = 0.5;
};

struct SlurmOutcome {
  int exit_code = 0;  // 1: sbatch refused the job (its message printed), 2: no Slurm client
  std::vector<FailedTask> failed;
};

// Submits the variants that need to run (and are not queued already), waits for every task of the
// sweep still queued, and lists the failed ones with their job id and log.
SlurmOutcome run_slurm(const std::filesystem::path& sweep_dir, const SweepSpec& spec,
                       const std::vector<Variant>& variants, const SlurmOptions& options,
                       std::ostream& log);

// One line per variant: done, failed (why, log), queued or running in Slurm, or not run.
std::string status_text(const std::filesystem::path& sweep_dir, const SweepSpec& spec,
                        const std::vector<Variant>& variants);

// Runs a Slurm client (argv[0]: sbatch, squeue, scontrol, ...) with its output captured through a
// file in DIR/slurm/ into `output`. Its exit code, or -1 when it cannot start (`output` says why).
int run_slurm_tool(const std::filesystem::path& dir, const std::vector<std::string>& argv,
                   std::string* output);

// The tasks Slurm holds, pending or running ("123_4" -> "RUNNING").
std::map<std::string, std::string> queued_tasks(const std::filesystem::path& dir);

// A finished task's JobState ("CANCELLED", "FAILED", ...) while slurmctld remembers it, or "".
std::string finished_state(const std::filesystem::path& dir, const std::string& job);

// "0-3,7,9-10": sorted indices as an sbatch --array list.
std::string array_list(std::vector<int> indices);

}  // namespace rigc::sweep
