#include "sweep/results.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>

#include "io/atomic_file.h"
#include "run/backend.h"
#include "sweep/task.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

std::string number_text(const std::optional<double>& value, int decimals) {
  return value ? fmt::format("{:.{}f}", *value, decimals) : "";
}

// The log a variant's task wrote: log.txt locally, the Slurm task's log otherwise.
std::string task_log(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir / "log.txt", ec)) return (dir / "log.txt").string();
  std::ifstream in(dir / "slurm-task.json");
  try {
    if (in) return nlohmann::json::parse(in).value("log", "");
  } catch (const nlohmann::json::exception&) {
  }
  return "";
}

std::vector<double> average_ranks(const std::vector<double>& values) {
  std::vector<std::size_t> order(values.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return values[a] < values[b]; });
  std::vector<double> ranks(values.size());
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i;
    while (j + 1 < order.size() && values[order[j + 1]] == values[order[i]]) ++j;
    for (std::size_t k = i; k <= j; ++k) ranks[order[k]] = (i + j) / 2.0 + 1;
    i = j + 1;
  }
  return ranks;
}

std::string csv_text(const SweepSpec& spec, const std::vector<ResultRow>& rows) {
  std::string csv = "variant";
  for (const Axis& axis : spec.axes) csv += "," + csv_field(axis.path);
  csv += ",status";
  for (const Measure& m : measures()) csv += std::string(",") + m.key;
  csv += ",reason\n";
  for (const ResultRow& r : rows) {
    csv += csv_field(r.variant->name);
    for (const std::string& v : r.variant->values) csv += "," + csv_field(v);
    csv += r.ok ? ",ok" : r.ran ? ",failed" : ",not run";
    for (std::size_t m = 0; m < measures().size(); ++m) {
      csv += "," + number_text(r.numbers[m], measures()[m].decimals);
    }
    csv += "," + csv_field(r.reason) + "\n";
  }
  return csv;
}

std::string timings_csv(const std::vector<ResultRow>& rows) {
  std::string csv = "variant,render_s,coverage_s,eval_s\n";
  for (const ResultRow& r : rows) {
    csv += fmt::format("{},{:.3f},{:.3f},{:.3f}\n", csv_field(r.variant->name), r.render_s,
                       r.coverage_s, r.eval_s);
  }
  return csv;
}

std::string markdown_table(const SweepSpec& spec, const std::vector<ResultRow>& rows) {
  std::string md = "| variant |";
  for (const Axis& axis : spec.axes) md += " " + axis.path + " |";
  md +=
      " coverage ≥2 views (%) | reconstructable (%) | registered | points | signed distance "
      "mean ± std (mm) | F-score | render (s) | eval (s) |\n|---|";
  for (std::size_t i = 0; i < spec.axes.size() + 8; ++i) md += "---|";
  md += "\n";
  for (const ResultRow& r : rows) {
    md += "| " + r.variant->name + " |";
    for (const std::string& v : r.variant->values) md += " " + v + " |";
    const auto& n = r.numbers;
    const std::string distance =
        n[4] && n[5] ? fmt::format("{:+.3f} ± {:.3f}", *n[4], *n[5]) : std::string();
    md += fmt::format(" {} | {} | {} | {} | {} | {} | {:.1f} | {} |\n", number_text(n[0], 1),
                      number_text(n[1], 1), number_text(n[2], 0), number_text(n[3], 0), distance,
                      number_text(n[6], 3), r.render_s,
                      r.eval_s > 0 ? fmt::format("{:.1f}", r.eval_s) : "");
  }
  return md;
}

// Rank agreement of every other backend with the first, over the configurations both ran.
std::string rank_agreement(const SweepSpec& spec, const std::vector<ResultRow>& rows) {
  const auto backend_axis = std::find_if(spec.axes.begin(), spec.axes.end(),
                                         [](const Axis& a) { return a.is_backend(); });
  if (backend_axis == spec.axes.end() || backend_axis->values.size() < 2) return "";
  const std::size_t b = backend_axis - spec.axes.begin();
  std::string md =
      "\n## Rank agreement between backends\n\nSpearman's ρ between the ranks "
      "each backend gives the configurations (1: the same order).\n\n"
      "| backends | measure | configurations | ρ |\n|---|---|---|---|\n";
  // Configuration (the other axes' values) -> backend -> row.
  std::map<std::vector<std::string>, std::map<std::string, const ResultRow*>> configs;
  for (const ResultRow& r : rows) {
    std::vector<std::string> config = r.variant->values;
    config.erase(config.begin() + b);
    configs[config][r.variant->values[b]] = &r;
  }
  const std::string first = backend_axis->values[0].text;
  for (std::size_t k = 1; k < backend_axis->values.size(); ++k) {
    const std::string other = backend_axis->values[k].text;
    for (std::size_t m = 0; m < measures().size(); ++m) {
      std::vector<double> a, c;
      for (const auto& [config, by_backend] : configs) {
        const auto x = by_backend.find(first), y = by_backend.find(other);
        if (x == by_backend.end() || y == by_backend.end()) continue;
        if (!x->second->numbers[m] || !y->second->numbers[m]) continue;
        a.push_back(*x->second->numbers[m]);
        c.push_back(*y->second->numbers[m]);
      }
      if (a.empty()) continue;
      const auto rho = spearman(a, c);
      md += fmt::format("| {} vs {} | {} | {} | {} |\n", first, other, measures()[m].title,
                        a.size(), rho ? fmt::format("{:+.3f}", *rho) : "n/a (constant or < 2)");
    }
  }
  return md;
}

std::string markdown_text(const SweepSpec& spec, const std::vector<ResultRow>& rows,
                          const std::vector<std::string>& plots) {
  std::string md = fmt::format(
      "# Sweep {}\n\nScene `{}`, render scale {}{}, measured: {}{}.\n\n", spec.name,
      spec.scene_path, spec.scale,
      spec.samples == run::kConvergedSamples ? ", converged sampling"
      : spec.samples > 0                     ? fmt::format(", {} samples a pixel", spec.samples)
                                             : "",
      spec.coverage ? "coverage" : "", spec.eval ? (spec.coverage ? ", eval" : "eval") : "");
  md += markdown_table(spec, rows);
  const int best = best_variant(rows);
  if (best >= 0) {
    const ResultRow& r = rows[best];
    md +=
        fmt::format("\nBest variant: **{}** ({} {}).\n", r.variant->name,
                    spec.eval ? "F-score" : "reconstructable",
                    spec.eval ? number_text(r.numbers[6], 3) : number_text(r.numbers[1], 1) + " %");
  }
  std::string failures;
  for (const ResultRow& r : rows) {
    if (r.ran && !r.ok)
      failures += fmt::format("- {}: {} (log: {})\n", r.variant->name, r.reason, r.log);
  }
  if (!failures.empty()) md += "\n## Failed variants\n\n" + failures;
  md += rank_agreement(spec, rows);
  if (!plots.empty()) md += "\n## Plots\n\n";
  for (const std::string& p : plots) md += fmt::format("![{}]({})\n", p, p);
  return md;
}

}  // namespace

const std::vector<Measure>& measures() {
  static const std::vector<Measure> list = {
      {"coverage_2_views_pct", "coverage ≥2 views (%)", 2, true},
      {"reconstructable_pct", "reconstructable (%)", 2, true},
      {"registered", "registered images", 0, true},
      {"points", "points", 0, true},
      {"mean_mm", "signed distance mean (mm)", 4, false},
      {"std_mm", "signed distance std (mm)", 4, false},
      {"fscore", "F-score", 4, true},
  };
  return list;
}

std::vector<ResultRow> collect_results(const fs::path& sweep_dir,
                                       const std::vector<Variant>& variants) {
  std::vector<ResultRow> rows;
  for (const Variant& v : variants) {
    ResultRow row;
    row.variant = &v;
    row.numbers.assign(measures().size(), std::nullopt);
    const fs::path dir = sweep_dir / v.name;
    row.log = task_log(dir);
    const auto result = read_result(dir, v.key);
    if (!result) {
      row.reason = "not run";
    } else {
      row.ran = true;
      row.ok = result->value("status", "") == "ok";
      row.reason = row.ok ? "" : result->value("reason", std::string("failed"));
      for (std::size_t m = 0; m < measures().size(); ++m) {
        const auto it = result->find(measures()[m].key);
        if (it != result->end() && it->is_number()) row.numbers[m] = it->get<double>();
      }
      row.render_s = result->value("render_s", 0.0);
      row.eval_s = result->value("eval_s", 0.0);
      row.coverage_s = result->value("coverage_s", 0.0);
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

std::optional<double> spearman(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size() || a.size() < 2) return std::nullopt;
  const auto ra = average_ranks(a), rb = average_ranks(b);
  const double n = static_cast<double>(a.size());
  const double mean = (n + 1) / 2;
  double cov = 0, va = 0, vb = 0;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    cov += (ra[i] - mean) * (rb[i] - mean);
    va += (ra[i] - mean) * (ra[i] - mean);
    vb += (rb[i] - mean) * (rb[i] - mean);
  }
  if (va == 0 || vb == 0) return std::nullopt;
  return cov / std::sqrt(va * vb);
}

int best_variant(const std::vector<ResultRow>& rows) {
  int best = -1;
  for (const std::size_t m : {std::size_t{6}, std::size_t{1}}) {
    for (int i = 0; i < static_cast<int>(rows.size()); ++i) {
      if (!rows[i].ok || !rows[i].numbers[m]) continue;
      if (best < 0 || *rows[i].numbers[m] > *rows[best].numbers[m]) best = i;
    }
    if (best >= 0) return best;
  }
  return best;
}

bool write_results(const fs::path& sweep_dir, const SweepSpec& spec,
                   const std::vector<ResultRow>& rows, std::string* error) {
  const auto plots = write_plots(sweep_dir, spec, rows, error);
  if (!error->empty()) return false;
  return write_file_atomically(sweep_dir / "results.csv", csv_text(spec, rows), error) &&
         write_file_atomically(sweep_dir / "timings.csv", timings_csv(rows), error) &&
         write_file_atomically(sweep_dir / "results.md", markdown_text(spec, rows, plots), error);
}

}  // namespace rigc::sweep
