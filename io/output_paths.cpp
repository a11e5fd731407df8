#include "io/output_paths.h"

#include <fmt/format.h>
#include <signal.h>

#include <cerrno>
#include <cstdlib>
#include <regex>
#include <system_error>

#include "io/input_files.h"

namespace rigc {
namespace {

void set_error(std::string* error, std::string text) {
  if (error != nullptr) *error = std::move(text);
}

// A temporary's name, its writer's PID the first group. The suffix is atomic_file.cpp's
// unique_suffix: ".tmp.PID.COUNTER.HEX".
const std::regex& temporary_name_pattern() {
  static const std::regex pattern(R"(\..+\.tmp\.([0-9]+)\.[0-9]+\.[0-9a-f]+)");
  return pattern;
}

}  // namespace

bool is_temporary_name(const std::string& filename) {
  return std::regex_match(filename, temporary_name_pattern());
}

int remove_abandoned_temporaries(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  int removed = 0;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    std::smatch match;
    std::error_code file_ec;
    if (!std::regex_match(name, match, temporary_name_pattern()) || !it->is_regular_file(file_ec)) {
      continue;
    }
    const long pid = std::strtol(match[1].str().c_str(), nullptr, 10);
    const bool writer_alive =
        pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM);
    if (!writer_alive && fs::remove(it->path(), file_ec)) ++removed;
  }
  return removed;
}

bool make_output_folder(const std::filesystem::path& dir, std::string* error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(dir, ec);
  if (fs::is_symlink(link)) {
    const fs::file_status target = fs::status(dir, ec);
    if (ec.value() == ELOOP) {
      set_error(error,
                fmt::format("the output folder '{}' is a symbolic link that loops", dir.string()));
      return false;
    }
    if (!fs::exists(target)) {
      const fs::path to = fs::read_symlink(dir, ec);
      set_error(error,
                fmt::format("the output folder '{}' is a symbolic link to '{}', which does not "
                            "exist; create it or name another folder",
                            dir.string(), to.string()));
      return false;
    }
  }
  fs::create_directories(dir, ec);
  std::error_code is_dir_ec;
  if (!ec && fs::is_directory(dir, is_dir_ec)) return true;
  if (!ec && !is_dir_ec) {
    set_error(error,
              fmt::format("cannot create the output folder '{}': a file of that name is in the way",
                          dir.string()));
    return false;
  }
  set_error(error, fmt::format("cannot create the output folder '{}': {}", dir.string(),
                               (ec ? ec : is_dir_ec).message()));
  return false;
}

bool clear_output_folder(const std::filesystem::path& dir, std::string* error) {
  if (const auto input = protected_input_within(dir)) {
    set_error(error, fmt::format("will not clear '{}': it holds {}, an input of this command; "
                                 "choose another output folder",
                                 dir.string(), *input));
    return false;
  }
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  return make_output_folder(dir, error);
}

}  // namespace rigc
