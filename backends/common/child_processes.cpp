#include "backends/common/child_processes.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <mutex>

extern char** environ;

namespace rigc::backends {
namespace fs = std::filesystem;
namespace {

// Lock-free slots, read by the signal handler (0: free). A few children run at once at most.
std::array<std::atomic<pid_t>, 16> g_children{};
static_assert(std::atomic<pid_t>::is_always_lock_free, "the signal handler reads the slots");
// Children being started, whose pids are not in the slots yet; and a stop signal that came
// meanwhile, which the last of them to be watched then acts on.
std::atomic<int> g_starting{0};
std::atomic<int> g_deferred_signal{0};

constexpr std::array kStopSignals = {SIGINT, SIGTERM, SIGHUP};

// Async-signal-safe: atomics, kill, signal and raise only.
void stop_children() {
  for (auto& child : g_children) {
    const pid_t pid = child.load();
    if (pid > 0) kill(pid, SIGTERM);
  }
}

void die_of(int signal_number) {
  signal(signal_number, SIG_DFL);
  raise(signal_number);
}

void stop_children_and_die(int signal_number) {
  stop_children();
  if (g_starting.load() > 0) {
    // A child being started would outlive rigc: its starter stops it, then rigc.
    g_deferred_signal.store(signal_number);
    if (g_starting.load() > 0) return;
    // The last starter finished meanwhile and may have looked before the store: unless it took
    // the signal, it is this handler's again.
    if (g_deferred_signal.exchange(0) == 0) return;
    stop_children();
  }
  die_of(signal_number);
}

void install_handlers() {
  for (const int signal_number : kStopSignals) {
    struct sigaction previous {};
    sigaction(signal_number, nullptr, &previous);
    // A signal the caller ignores (nohup's SIGHUP) stays ignored; a handler of its own stays.
    if (previous.sa_handler != SIG_DFL) continue;
    struct sigaction action {};
    action.sa_handler = stop_children_and_die;
    sigemptyset(&action.sa_mask);
    sigaction(signal_number, &action, nullptr);
  }
}

void watch_child(pid_t pid) {
  for (auto& child : g_children) {
    pid_t expected = 0;
    if (child.compare_exchange_strong(expected, pid)) return;
  }
}

void unwatch_child(pid_t pid) {
  for (auto& child : g_children) {
    pid_t expected = pid;
    if (child.compare_exchange_strong(expected, 0)) return;
  }
}

// From the start of a child until its pid is watched: a stop signal meanwhile is carried out
// when the last child being started is watched (or has failed to start).
class Starting {
 public:
  Starting() { g_starting.fetch_add(1); }
  ~Starting() { done(); }
  void done() {
    if (done_) return;
    done_ = true;
    if (g_starting.fetch_sub(1) == 1) {
      if (const int signal_number = g_deferred_signal.exchange(0)) {
        stop_children();
        die_of(signal_number);
      }
    }
  }

 private:
  bool done_ = false;
};

bool is_executable_file(const fs::path& path) {
  struct stat info {};
  return stat(path.c_str(), &info) == 0 && S_ISREG(info.st_mode) && access(path.c_str(), X_OK) == 0;
}

}  // namespace

std::optional<fs::path> find_executable(const std::string& name) {
  if (name.empty()) return std::nullopt;
  if (name.find('/') != std::string::npos) {
    return is_executable_file(name) ? std::optional<fs::path>(name) : std::nullopt;
  }
  const char* path_env = std::getenv("PATH");
  const std::string search = path_env ? path_env : "/usr/local/bin:/usr/bin:/bin";
  size_t start = 0;
  while (start <= search.size()) {
    const size_t end = std::min(search.find(':', start), search.size());
    const std::string dir = search.substr(start, end - start);
    const fs::path candidate = fs::path(dir.empty() ? "." : dir) / name;
    if (is_executable_file(candidate)) return candidate;
    start = end + 1;
  }
  return std::nullopt;
}

ChildResult run_child(const ChildRun& run) {
  ChildResult result;
  if (run.argv.empty()) {
    result.error = "no program to run";
    return result;
  }
  const std::optional<fs::path> program = find_executable(run.argv[0]);
  if (!program) {
    result.error = "'" + run.argv[0] + "' was not found in PATH";
    return result;
  }
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) env_strings.emplace_back(*e);
  for (const std::string& entry : run.default_env) {
    const std::string name = entry.substr(0, entry.find('=') + 1);
    if (name.size() < 2 || std::getenv(name.substr(0, name.size() - 1).c_str()) == nullptr) {
      env_strings.push_back(entry);
    }
  }
  std::vector<char*> envp;
  for (std::string& entry : env_strings) envp.push_back(entry.data());
  envp.push_back(nullptr);
  std::vector<std::string> args = run.argv;
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, run.log.c_str(), O_WRONLY | O_CREAT | O_APPEND,
                                   0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  if (!run.working_dir.empty()) {
    posix_spawn_file_actions_addchdir_np(&actions, run.working_dir.c_str());
  }
  static std::once_flag installed;
  std::call_once(installed, install_handlers);
  Starting starting;
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, program->c_str(), &actions, nullptr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    result.error = "cannot start '" + program->string() + "': " + std::strerror(rc);
    return result;  // a signal deferred meanwhile is carried out by `starting`
  }
  result.started = true;
  watch_child(pid);
  starting.done();
  int status = 0;
  rusage usage{};
  while (wait4(pid, &status, 0, &usage) < 0) {
    if (errno != EINTR) {
      unwatch_child(pid);
      result.error = "waiting for '" + program->string() + "' failed: " + std::strerror(errno);
      return result;
    }
  }
  // Unwatched once reaped, so that a signal cannot reach another process given its pid.
  unwatch_child(pid);
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + t.tv_usec * 1e-6;
  };
  result.cpu_seconds = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

}  // namespace rigc::backends
