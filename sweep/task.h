// One variant of a sweep, run in this process: render, coverage and eval as `rigc render`,
// `rigc coverage` and `rigc eval` would, into the variant's folder, then its result.json. The
// local executor and every Slurm array task run this (`rigc sweep --run-task DIR --task-index I`).
#pragma once

#include <filesystem>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <optional>

namespace rigc::sweep {

// Runs variant `index` of the sweep in `sweep_dir` (sweep.json). Returns the exit code (0, 1 for
// a bad folder or index, 2 when a stage failed); result.json records the numbers or the failure.
int run_variant_task(const std::filesystem::path& sweep_dir, int index, std::ostream& log);

// A variant's result.json if it is there and was made from the inputs `key` names.
std::optional<nlohmann::json> read_result(const std::filesystem::path& variant_dir,
                                          const std::string& key);

// Whether the variant must run: no result for its key, a failed one, or outputs missing.
bool variant_needs_run(const std::filesystem::path& variant_dir, const std::string& key,
                       bool coverage, bool eval);

}  // namespace rigc::sweep
