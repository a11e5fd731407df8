#include "io/input_files.h"

#include <sys/stat.h>

#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <utility>
#include <vector>

namespace rigc {
namespace {

using FileId = std::pair<dev_t, ino_t>;

struct Registry {
  std::mutex mutex;
  bool enabled = false;
  std::map<FileId, std::string> inputs;
  // Where each input and input folder is (symbolic links resolved), for the folders a command
  // clears.
  std::vector<std::pair<std::filesystem::path, std::string>> places;
};

std::filesystem::path resolved(const std::filesystem::path& path) {
  std::error_code ec;
  std::filesystem::path p = std::filesystem::weakly_canonical(path, ec);
  return ec ? std::filesystem::absolute(path, ec).lexically_normal() : p;
}

// Whether `path` is `dir` or lies under it (both resolved).
bool is_at_or_under(const std::filesystem::path& path, const std::filesystem::path& dir) {
  auto p = path.begin();
  for (auto d = dir.begin(); d != dir.end(); ++d, ++p) {
    if (d->empty()) continue;  // a trailing separator
    if (p == path.end() || *p != *d) return false;
  }
  return true;
}

Registry& registry() {
  static Registry instance;
  return instance;
}

std::optional<FileId> file_id(const std::filesystem::path& path) {
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) return std::nullopt;
  return FileId{info.st_dev, info.st_ino};
}

}  // namespace

void enable_input_protection() {
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  r.enabled = true;
}

void protect_input_file(const std::filesystem::path& path, const std::string& what) {
  const auto id = file_id(path);
  if (!id) return;
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  if (!r.enabled) return;
  r.inputs.emplace(*id, what);
  r.places.emplace_back(resolved(path), what);
}

void protect_input_folder(const std::filesystem::path& dir, const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec)) return;
  Registry& r = registry();
  std::lock_guard lock(r.mutex);
  if (r.enabled) r.places.emplace_back(resolved(dir), what);
}

std::optional<std::string> protected_input_within(const std::filesystem::path& dir) {
  Registry& r = registry();
  const std::filesystem::path folder = resolved(dir);
  std::lock_guard lock(r.mutex);
  for (const auto& [place, what] : r.places) {
    if (is_at_or_under(place, folder)) return what + " (" + place.string() + ")";
  }
  return std::nullopt;
}

std::optional<std::string> protected_input_at(const std::filesystem::path& path) {
  Registry& r = registry();
  {
    std::lock_guard lock(r.mutex);
    if (r.inputs.empty()) return std::nullopt;
  }
  const auto id = file_id(path);
  if (!id) return std::nullopt;
  std::lock_guard lock(r.mutex);
  const auto it = r.inputs.find(*id);
  if (it == r.inputs.end()) return std::nullopt;
  return it->second;
}

std::vector<std::filesystem::path> obj_material_libraries(const std::filesystem::path& obj) {
  std::vector<std::filesystem::path> libraries;
  std::string extension = obj.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (extension != ".obj") return libraries;
  std::ifstream in(obj, std::ios::binary);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.starts_with("mtllib")) continue;
    std::istringstream names(line.substr(6));
    std::string name;
    while (names >> name) libraries.push_back(obj.parent_path() / name);
  }
  return libraries;
}

}  // namespace rigc
