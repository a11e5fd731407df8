#include "io/input_files.h"

#include <sys/stat.h>

#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <utility>

namespace rigc {
namespace {

using FileId = std::pair<dev_t, ino_t>;

struct Registry {
  std::mutex mutex;
  bool enabled = false;
  std::map<FileId, std::string> inputs;
};

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
  if (r.enabled) r.inputs.emplace(*id, what);
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
