// load_model: picks the reader by the file's extension (gltf.cpp, ply.cpp, assimp.cpp) and turns
// what goes wrong into one line naming the file.
#include "assets/mesh_io.h"

#include <exception>
#include <filesystem>
#include <new>
#include <system_error>

#include "assets/model_loading.h"
#include "io/file_status.h"

namespace rigc {

namespace fs = std::filesystem;
using loading::one_line;

std::optional<LoadedModel> load_model(const std::string& path, std::string* error) {
  auto set_error = [&](const std::string& message) {
    if (error)
      *error = fmt::format("{}: {}", one_line(path), loading::cut_long_words(one_line(message)));
  };
  try {
    if (const std::string why = why_not_readable(path); !why.empty()) {
      set_error(why);
      return std::nullopt;
    }
    const std::string ext = loading::lower(fs::path(path).extension().string());
    if (ext == ".gltf" || ext == ".glb") return loading::load_gltf(path, ext == ".glb");
    if (ext == ".ply") return loading::load_ply(path);
    if (ext == ".obj" || ext == ".stl") return loading::load_with_assimp(path, ext);
    set_error(
        fmt::format("unsupported model format '{}' (use .gltf, .glb, .obj, .ply or .stl)", ext));
  } catch (const loading::LoadError& e) {
    set_error(e.what());
  } catch (const std::bad_alloc&) {
    set_error("out of memory while loading (malformed or too large)");
  } catch (const std::exception& e) {
    set_error(fmt::format("could not be read: {}", e.what()));
  } catch (...) {
    set_error("could not be read: unknown error");
  }
  return std::nullopt;
}

}  // namespace rigc
