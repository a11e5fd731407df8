#include "sweep/slurm_executor.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <map>
#include <ostream>
#include <set>
#include <sstream>
#include <thread>

#include "io/atomic_file.h"
#include "io/child_processes.h"
#include "sweep/task.h"

namespace rigc::sweep {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

nlohmann::json read_slurm_json(const fs::path& sweep_dir) {
  std::ifstream in(sweep_dir / "slurm.json");
  try {
    if (in) return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception&) {
  }
  return {{"tasks", nlohmann::json::object()}};
}

// The sbatch options RigC sets itself; a user's would break the array or its logs.
std::string forbidden_option(const std::vector<std::string>& args) {
  for (const std::string& arg : args) {
    for (const char* own :
         {"--array", "--output", "--error", "--wrap", "--parsable", "-a", "-o", "-e"}) {
      const std::string o = own;
      if (arg == o || arg.starts_with(o + "=") || (o.size() == 2 && arg.starts_with(o))) {
        return arg;
      }
    }
  }
  return "";
}

constexpr const char* kTaskScript =
    "#!/bin/sh\n"
    "# A rigc sweep task: runs variant $SLURM_ARRAY_TASK_ID of a sweep folder. Its arguments\n"
    "# (given to sbatch after this script): the rigc program, the sweep folder.\n"
    "exec \"$1\" sweep --run-task \"$2\" --task-index \"$SLURM_ARRAY_TASK_ID\"\n";

// sbatch for `indices`; records each task in slurm.json. Exit code 0, 1 (refused) or 2.
int submit(const fs::path& sweep_dir, const std::vector<Variant>& variants,
           const std::vector<int>& indices, const SlurmOptions& options, nlohmann::json& record,
           std::ostream& log) {
  const fs::path slurm_dir = fs::absolute(sweep_dir / "slurm");
  std::string error;
  if (!write_file_atomically(slurm_dir / "task.sh", kTaskScript, &error)) {
    log << "rigc: error: " << error << '\n';
    return 1;
  }
  std::vector<std::string> argv = {"sbatch", "--parsable", "--job-name=rigc-sweep",
                                   "--array=" + array_list(indices),
                                   "--output=" + (slurm_dir / "%A_%a.log").string()};
  argv.insert(argv.end(), options.sbatch_args.begin(), options.sbatch_args.end());
  argv.insert(argv.end(), {(slurm_dir / "task.sh").string(), fs::absolute(options.rigc).string(),
                           fs::absolute(sweep_dir).string()});
  std::string output;
  const int status = run_slurm_tool(sweep_dir, argv, &output);
  if (status == -1) {
    log << "rigc: error: cannot run sbatch (--executor slurm needs Slurm's client tools): "
        << output << '\n';
    return 2;
  }
  const std::string job = output.substr(0, output.find_first_not_of("0123456789"));
  if (status != 0 || job.empty()) {
    log << fmt::format("rigc: error: sbatch refused the job array (exit {}):\n{}", status, output);
    return 1;
  }
  for (const int i : indices) {
    const fs::path dir = sweep_dir / variants[i].name;
    std::error_code ec;
    fs::remove(dir / "result.json", ec);
    fs::remove(dir / "log.txt", ec);
    const nlohmann::json task = {{"job", fmt::format("{}_{}", job, i)},
                                 {"log", (slurm_dir / fmt::format("{}_{}.log", job, i)).string()},
                                 {"key", variants[i].key}};
    record["tasks"][variants[i].name] = task;
    write_file_atomically(dir / "slurm-task.json", task.dump(2) + "\n", &error);
  }
  log << fmt::format("rigc sweep: submitted job array {} ({} tasks)\n", job, indices.size());
  return write_file_atomically(sweep_dir / "slurm.json", record.dump(2) + "\n", &error) ? 0 : 2;
}

// The variants whose task Slurm still holds.
std::set<std::string> active_variants(const nlohmann::json& record,
                                      const std::map<std::string, std::string>& queue) {
  std::set<std::string> active;
  for (const auto& [name, task] : record["tasks"].items()) {
    if (queue.count(task.value("job", ""))) active.insert(name);
  }
  return active;
}

void wait_for(const fs::path& sweep_dir, const nlohmann::json& record,
              const std::set<std::string>& tracked, const SlurmOptions& options,
              std::ostream& log) {
  const auto start = Clock::now();
  std::size_t last_active = tracked.size() + 1;
  while (true) {
    const auto queue = queued_tasks(sweep_dir);
    const auto active = active_variants(record, queue);
    int running = 0;
    for (const auto& name : active) {
      running += queue.at(record["tasks"][name]["job"].get<std::string>()) == "RUNNING" ? 1 : 0;
    }
    const std::size_t done = tracked.size() - std::min(active.size(), tracked.size());
    if (active.size() != last_active) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      log << fmt::format("rigc sweep: {}/{} tasks done, {} running, {} pending{}\n", done,
                         tracked.size(), running, active.size() - running,
                         done > 0 && !active.empty()
                             ? fmt::format(", about {:.0f} s left", elapsed / done * active.size())
                             : "");
      last_active = active.size();
    }
    if (active.empty()) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(options.poll_seconds));
  }
}

}  // namespace

// Runs a Slurm client; its output (stdout and stderr) in `output`. -1 when it cannot start.
int run_slurm_tool(const fs::path& sweep_dir, const std::vector<std::string>& argv,
                   std::string* output) {
  static std::atomic<int> counter{0};
  const fs::path capture =
      sweep_dir / "slurm" / fmt::format(".{}-{}-{}.out", argv[0], getpid(), counter++);
  const ChildResult result = run_child({argv, capture, {}, {}});
  std::ifstream in(capture);
  std::ostringstream text;
  text << in.rdbuf();
  *output = text.str();
  std::error_code ec;
  fs::remove(capture, ec);
  if (!result.started) *output = result.error;
  return result.started ? result.exit_code : -1;
}

// The states of the tasks Slurm still holds ("123_4" -> "RUNNING"); every job of the queue.
std::map<std::string, std::string> queued_tasks(const fs::path& sweep_dir) {
  std::string output;
  std::map<std::string, std::string> states;
  if (run_slurm_tool(sweep_dir, {"squeue", "-h", "-r", "-o", "%i %T"}, &output) != 0) return states;
  std::istringstream lines(output);
  for (std::string id, state; lines >> id >> state;) states[id] = state;
  return states;
}

// JobState (and Reason) of a finished task, while slurmctld still remembers it.
std::string finished_state(const fs::path& sweep_dir, const std::string& job) {
  std::string output;
  if (run_slurm_tool(sweep_dir, {"scontrol", "-o", "show", "job", job}, &output) != 0) return "";
  const std::size_t at = output.find("JobState=");
  if (at == std::string::npos) return "";
  const std::size_t end = output.find(' ', at);
  return output.substr(at + 9, end == std::string::npos ? end : end - at - 9);
}

std::string array_list(std::vector<int> indices) {
  std::sort(indices.begin(), indices.end());
  std::string list;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    list += (list.empty() ? "" : ",") +
            (i == j ? std::to_string(indices[i]) : fmt::format("{}-{}", indices[i], indices[j]));
    i = j + 1;
  }
  return list;
}

SlurmOutcome run_slurm(const fs::path& sweep_dir, const SweepSpec& spec,
                       const std::vector<Variant>& variants, const SlurmOptions& options,
                       std::ostream& log) {
  if (const std::string bad = forbidden_option(options.sbatch_args); !bad.empty()) {
    log << fmt::format(
        "rigc: error: sbatch option '{}' is rigc's own (it sets the array and the "
        "logs)\n",
        bad);
    return {1, {}};
  }
  std::error_code ec;
  fs::create_directories(sweep_dir / "slurm", ec);
  nlohmann::json record = read_slurm_json(sweep_dir);
  const auto active = active_variants(record, queued_tasks(sweep_dir));
  std::vector<int> indices;
  for (int i = 0; i < static_cast<int>(variants.size()); ++i) {
    const Variant& v = variants[i];
    if (active.count(v.name)) continue;
    if (options.retry_failed && !record["tasks"].contains(v.name)) continue;
    if (variant_needs_run(sweep_dir / v.name, v.key, spec.coverage, spec.eval))
      indices.push_back(i);
  }
  log << fmt::format("rigc sweep: {} variants, {} to submit, {} queued already\n", variants.size(),
                     indices.size(), active.size());
  if (!indices.empty()) {
    if (const int status = submit(sweep_dir, variants, indices, options, record, log)) {
      return {status, {}};
    }
  }
  if (!options.wait) return {};
  std::set<std::string> tracked = active;
  for (const int i : indices) tracked.insert(variants[i].name);
  wait_for(sweep_dir, record, tracked, options, log);
  SlurmOutcome outcome;
  for (const Variant& v : variants) {
    if (!tracked.count(v.name) ||
        !variant_needs_run(sweep_dir / v.name, v.key, spec.coverage, spec.eval)) {
      continue;
    }
    const auto& task = record["tasks"][v.name];
    const std::string job = task.value("job", "");
    const std::string state = finished_state(sweep_dir, job);
    outcome.failed.push_back(
        {v.name,
         failure_reason(sweep_dir / v.name, v.key, state.empty() ? "no result" : "Slurm: " + state),
         task.value("log", ""), job});
  }
  return outcome;
}

std::string status_text(const fs::path& sweep_dir, const SweepSpec& spec,
                        const std::vector<Variant>& variants) {
  const nlohmann::json record = read_slurm_json(sweep_dir);
  const auto queue =
      record["tasks"].empty() ? std::map<std::string, std::string>{} : queued_tasks(sweep_dir);
  std::string text;
  int done = 0;
  for (const Variant& v : variants) {
    const fs::path dir = sweep_dir / v.name;
    const auto task = record["tasks"].contains(v.name) ? record["tasks"][v.name] : nlohmann::json{};
    const std::string job = task.is_object() ? task.value("job", "") : "";
    std::string state;
    if (queue.count(job)) {
      state = fmt::format("{} (job {})", queue.at(job), job);
    } else if (!variant_needs_run(dir, v.key, spec.coverage, spec.eval)) {
      state = "done";
      ++done;
    } else if (const auto result = read_result(dir, v.key)) {
      state = fmt::format("failed: {}{} (log: {})", result->value("reason", std::string("?")),
                          job.empty() ? "" : ", job " + job,
                          job.empty() ? (dir / "log.txt").string() : task.value("log", ""));
    } else {
      state = job.empty()
                  ? "not run"
                  : fmt::format("failed: no result, job {} (log: {})", job, task.value("log", ""));
    }
    text += fmt::format("{:<40} {}\n", v.name, state);
  }
  return text + fmt::format("{}/{} variants done\n", done, variants.size());
}

}  // namespace rigc::sweep
