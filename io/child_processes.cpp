#include "io/child_processes.h"

#include <fcntl.h>
#include <fmt/format.h>
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
#include <system_error>

extern char** environ;

namespace rigc {
namespace fs = std::filesystem;
namespace {

// Lock-free slots, read by the signal handler (0: free). A few children run at once at most.
std::array<std::atomic<pid_t>, 16> g_children{};
static_assert(std::atomic<pid_t>::is_always_lock_free, "the signal handler reads the slots");
// Children being started, whose pids are not in the slots yet; and a stop signal that came
// meanwhile, which the last of them to be watched then acts on.
std::atomic<int> g_starting{0};
std::atomic<int> g_deferred_signal{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler uses them");
// Called between a child's spawn and its watch (tests only; see the header).
void (*g_spawn_hook)() = nullptr;

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
  if (g_starting.load() > 0) {
    // A child being started would outlive rigc: its starter stops every child, then rigc. The
    // others are left running until then, so that no caller meanwhile takes their SIGTERM for
    // a failure of its own. The handler returns: the interrupted thread keeps its errno.
    const int saved_errno = errno;
    g_deferred_signal.store(signal_number);
    if (g_starting.load() > 0) {
      errno = saved_errno;
      return;
    }
    // The last starter finished meanwhile and may have looked before the store: unless it took
    // the signal, it is this handler's again.
    if (g_deferred_signal.exchange(0) == 0) {
      errno = saved_errno;
      return;
    }
  }
  stop_children();
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
    // While a signal is deferred the handler returns: other threads' calls carry on.
    action.sa_flags = SA_RESTART;
    sigemptyset(&action.sa_mask);
    sigaction(signal_number, &action, nullptr);
  }
}

// False when every slot is taken (rigc runs a few children at once at most).
bool watch_child(pid_t pid) {
  for (auto& child : g_children) {
    pid_t expected = 0;
    if (child.compare_exchange_strong(expected, pid)) return true;
  }
  return false;
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

void stop_child_processes() {
  stop_children();
}

void set_spawn_hook_for_tests(void (*hook)()) {
  g_spawn_hook = hook;
}

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
  std::optional<fs::path> program = find_executable(run.argv[0]);
  if (!program) {
    result.error = run.argv[0].find('/') != std::string::npos
                       ? "'" + run.argv[0] + "' is not an executable file"
                       : "'" + run.argv[0] + "' was not found in PATH";
    return result;
  }
  // The child changes to working_dir before it runs the program: a path relative to rigc's
  // folder would be looked up there.
  std::error_code absolute_error;
  program = fs::absolute(*program, absolute_error);
  if (absolute_error) {
    result.error = "cannot locate '" + run.argv[0] + "': " + absolute_error.message();
    return result;
  }
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) env_strings.emplace_back(*e);
  for (const std::string& entry : run.default_env) {
    const std::size_t equals = entry.find('=');
    if (equals == 0 || equals == std::string::npos) continue;  // no NAME=value
    if (std::getenv(entry.substr(0, equals).c_str()) == nullptr) env_strings.push_back(entry);
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
  // Nothing else of rigc's: a descriptor without O_CLOEXEC (a stream's, a library's) would stay
  // open in the child for as long as it runs, as would a pipe's write end that someone reads to
  // its end.
  posix_spawn_file_actions_addclosefrom_np(&actions, 3);
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
    // The program was found: the log or the working folder may be what failed.
    result.error = fmt::format(
        "cannot start '{}' (log {}{}): {}", program->string(), run.log.string(),
        run.working_dir.empty() ? "" : ", in " + run.working_dir.string(), std::strerror(rc));
    return result;  // a signal deferred meanwhile is carried out by `starting`
  }
  result.started = true;
  if (g_spawn_hook != nullptr) g_spawn_hook();
  const bool watched = watch_child(pid);
  starting.done();
  if (!watched) {
    kill(pid, SIGTERM);
    result.error = "too many programs running at once";
  }
  // Waited for without reaping first: the pid stays this child's until it is unwatched, so that
  // a signal cannot reach another process that is given the pid.
  siginfo_t info{};
  while (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
  }
  unwatch_child(pid);
  int status = 0;
  rusage usage{};
  while (wait4(pid, &status, 0, &usage) < 0) {
    if (errno != EINTR) {
      result.error = "waiting for '" + program->string() + "' failed: " + std::strerror(errno);
      return result;
    }
  }
  if (!watched) return result;
  const auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + t.tv_usec * 1e-6;
  };
  result.cpu_seconds = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

}  // namespace rigc
