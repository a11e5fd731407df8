#include "assets/model_cache.h"

#include <algorithm>
#include <deque>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <tuple>
#include <utility>
#include <vector>

namespace rigc {
namespace {

namespace fs = std::filesystem;

// The last few entries, newest first: a studio alternates between one or two scenes.
constexpr size_t kKept = 2;

// A file as a loaded model depends on it: its size and modification time (-1 when missing).
struct FileStamp {
  std::string path;
  std::uintmax_t size = 0;
  fs::file_time_type modified{};
  bool operator==(const FileStamp&) const = default;
};

FileStamp stamp_of(const fs::path& path) {
  std::error_code ec;
  FileStamp stamp{path.string()};
  stamp.size = fs::file_size(path, ec);
  if (ec) stamp.size = static_cast<std::uintmax_t>(-1);
  stamp.modified = fs::last_write_time(path, ec);
  return stamp;
}

// What `model` (loaded from `path`) was made from: the file, its image files, and for OBJ the
// material libraries in its folder (whichever the file names).
std::vector<FileStamp> stamps_of(const std::string& path, const LoadedModel& model) {
  std::vector<FileStamp> stamps = {stamp_of(path)};
  for (const ir::Texture& texture : model.textures) {
    if (texture.source.find('#') == std::string::npos) stamps.push_back(stamp_of(texture.source));
  }
  const auto lower_extension = [](const fs::path& file) {
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
    return ext;
  };
  const fs::path file(path);
  if (lower_extension(file) != ".obj") return stamps;
  std::vector<FileStamp> libraries;
  std::error_code ec;
  const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    if (lower_extension(entry.path()) == ".mtl") libraries.push_back(stamp_of(entry.path()));
  }
  std::sort(libraries.begin(), libraries.end(),
            [](const FileStamp& a, const FileStamp& b) { return a.path < b.path; });
  stamps.insert(stamps.end(), libraries.begin(), libraries.end());
  return stamps;
}

struct KeptModel {
  std::string path;
  std::vector<FileStamp> stamps;
  LoadedModel model;
};

struct KeptPrimitive {
  std::tuple<PrimitiveKind, int, std::uint32_t> key;
  ir::Mesh mesh;
};

std::mutex cache_mutex;
bool keeping = false;                       // under cache_mutex
std::deque<KeptModel> kept_models;          // under cache_mutex
std::deque<KeptPrimitive> kept_primitives;  // under cache_mutex

}  // namespace

void keep_loaded_models(bool keep) {
  std::lock_guard lock(cache_mutex);
  keeping = keep;
  if (!keep) {
    kept_models.clear();
    kept_primitives.clear();
  }
}

std::optional<LoadedModel> load_model_cached(const std::string& path, std::string* error) {
  {
    std::lock_guard lock(cache_mutex);
    if (!keeping) return load_model(path, error);
    for (const KeptModel& kept : kept_models) {
      if (kept.path == path && stamps_of(path, kept.model) == kept.stamps) return kept.model;
    }
  }
  std::optional<LoadedModel> model = load_model(path, error);
  if (!model) return model;
  std::vector<FileStamp> stamps = stamps_of(path, *model);
  std::lock_guard lock(cache_mutex);
  std::erase_if(kept_models, [&](const KeptModel& kept) { return kept.path == path; });
  kept_models.push_front({path, std::move(stamps), *model});
  if (kept_models.size() > kKept) kept_models.pop_back();
  return model;
}

ir::Mesh make_primitive_cached(PrimitiveKind kind, int detail, std::uint32_t seed) {
  const auto key = std::make_tuple(kind, detail, seed);
  {
    std::lock_guard lock(cache_mutex);
    if (!keeping) return make_primitive(kind, detail, seed);
    for (const KeptPrimitive& kept : kept_primitives) {
      if (kept.key == key) return kept.mesh;
    }
  }
  ir::Mesh mesh = make_primitive(kind, detail, seed);
  std::lock_guard lock(cache_mutex);
  kept_primitives.push_front({key, mesh});
  if (kept_primitives.size() > kKept) kept_primitives.pop_back();
  return mesh;
}

}  // namespace rigc
