#include "sweep/local_executor.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <ostream>
#include <thread>

#include "backends/registry.h"
#include "io/child_processes.h"
#include "sweep/task.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Progress shared by the workers: "rigc sweep: 3/12 done (1 failed), about 40 s left".
class Progress {
 public:
  Progress(int total, int jobs, std::ostream& log) : total_(total), jobs_(jobs), log_(log) {}

  void finished(const std::string& name, bool ok, double seconds) {
    std::lock_guard lock(mutex_);
    ++done_;
    failed_ += ok ? 0 : 1;
    busy_s_ += seconds;
    const double left = busy_s_ / done_ * (total_ - done_) / jobs_;
    log_ << fmt::format("rigc sweep: {}/{} done{} ({} {} in {:.1f} s){}\n", done_, total_,
                        failed_ ? fmt::format(", {} failed", failed_) : "", name,
                        ok ? "ok" : "FAILED", seconds,
                        done_ < total_ ? fmt::format(", about {:.0f} s left", left) : "");
    log_.flush();
  }

 private:
  std::mutex mutex_;
  int total_, jobs_, done_ = 0, failed_ = 0;
  double busy_s_ = 0;
  std::ostream& log_;
};

}  // namespace

std::string failure_reason(const fs::path& dir, const std::string& key,
                           const std::string& fallback) {
  const auto result = read_result(dir, key);
  if (result && result->contains("reason")) return result->at("reason").get<std::string>();
  return fallback;
}

std::vector<FailedTask> run_local(const fs::path& sweep_dir, const SweepSpec& spec,
                                  const std::vector<Variant>& variants, const LocalOptions& options,
                                  std::ostream& log) {
  std::vector<int> todo;
  std::size_t left_out = 0;  // variants of backends not chosen
  for (int i = 0; i < static_cast<int>(variants.size()); ++i) {
    if (!options.backends.empty() && std::find(options.backends.begin(), options.backends.end(),
                                               variants[i].backend) == options.backends.end()) {
      ++left_out;
    } else if (variant_needs_run(sweep_dir / variants[i].name, variants[i].key, spec.coverage,
                                 spec.eval)) {
      todo.push_back(i);
    }
  }
  // The in-process renderer's variants (seconds each) before the ray tracers' (minutes a shot),
  // so that a sweep over both backends has the fast half of its table early.
  std::stable_partition(todo.begin(), todo.end(), [&](int i) {
    const backends::BackendEntry* entry = backends::find_backend(variants[i].backend);
    return entry && !entry->make()->emits_scripts();
  });
  log << fmt::format("rigc sweep: {} variants, {} to run ({} done already{}), {} at a time\n",
                     variants.size(), todo.size(), variants.size() - todo.size() - left_out,
                     left_out ? fmt::format(", {} of other backends left out", left_out) : "",
                     options.jobs);
  Progress progress(static_cast<int>(todo.size()), options.jobs, log);
  std::vector<FailedTask> failed;
  std::mutex failed_mutex;
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t t = next++; t < todo.size(); t = next++) {
      const Variant& v = variants[todo[t]];
      const fs::path dir = sweep_dir / v.name;
      std::error_code ec;
      fs::remove(dir / "log.txt", ec);
      const auto start = Clock::now();
      const ChildResult child =
          run_child({{options.rigc.string(), "sweep", "--run-task", sweep_dir.string(),
                      "--task-index", std::to_string(todo[t])},
                     dir / "log.txt",
                     {},
                     {}});
      const bool ok = child.started && child.exit_code == 0;
      progress.finished(v.name, ok, std::chrono::duration<double>(Clock::now() - start).count());
      if (ok) continue;
      const std::string fallback = child.started ? fmt::format("exit {}", child.exit_code)
                                                 : "could not start: " + child.error;
      std::lock_guard lock(failed_mutex);
      failed.push_back(
          {v.name, failure_reason(dir, v.key, fallback), (dir / "log.txt").string(), ""});
    }
  };
  std::vector<std::thread> workers;
  const int threads = std::max(1, std::min<int>(options.jobs, static_cast<int>(todo.size())));
  for (int i = 0; i < threads; ++i) workers.emplace_back(worker);
  for (auto& w : workers) w.join();
  return failed;
}

}  // namespace rigc::sweep
