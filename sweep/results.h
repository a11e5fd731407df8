// A sweep's results side by side: results.csv (the numbers, the same whichever executor ran the
// variants), timings.csv, results.md (the table, the best variant, the rank agreement between
// backends) and plots/ (each measure against each varied parameter).
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "sweep/local_executor.h"
#include "sweep/variants.h"

namespace rigc::sweep {

// A measure: its key in result.json, its column title, its format.
struct Measure {
  const char* key;
  const char* title;
  int decimals;
  bool higher_is_better;
};
const std::vector<Measure>& measures();

struct ResultRow {
  const Variant* variant = nullptr;
  bool ran = false;  // it has a result.json for its inputs
  bool ok = false;
  std::string reason, log;
  std::vector<std::optional<double>> numbers;  // per measures()
  double render_s = 0, eval_s = 0, coverage_s = 0;
};

std::vector<ResultRow> collect_results(const std::filesystem::path& sweep_dir,
                                       const std::vector<Variant>& variants);

// Spearman's rank correlation of two equally long series (average ranks for ties); nullopt with
// fewer than two values or a constant series.
std::optional<double> spearman(const std::vector<double>& a, const std::vector<double>& b);

// The variant with the best F-score (with eval) or reconstructable share; -1 if none has one.
int best_variant(const std::vector<ResultRow>& rows);

// Grid lines for a value axis over [lo, hi]: steps of 1, 2 or 5 x 10^k, about `count` of them,
// from a multiple of the step at or below `lo` to one at or above `hi`, and the decimals that
// print them exactly.
struct AxisTicks {
  std::vector<double> values;
  int decimals = 0;
};
AxisTicks nice_ticks(double lo, double hi, int count = 4);

// Writes results.csv, timings.csv, results.md and plots/*.png into `sweep_dir`.
bool write_results(const std::filesystem::path& sweep_dir, const SweepSpec& spec,
                   const std::vector<ResultRow>& rows, std::string* error);

// plots/<measure>_vs_<axis>.png for every measure with numbers and every axis of 2+ values;
// returns the files written (relative to sweep_dir).
std::vector<std::string> write_plots(const std::filesystem::path& sweep_dir, const SweepSpec& spec,
                                     const std::vector<ResultRow>& rows, std::string* error);

}  // namespace rigc::sweep
