#include "assets/gltf_schema.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <system_error>

#include "assets/model_loading.h"
#include "io/file_status.h"

namespace rigc::loading {
namespace {

using json = nlohmann::json;

// The checks, one glTF section at a time; the first wrong member found is reported.
class GltfSchemaCheck {
 public:
  void run(const json& root) {
    check_asset(root);
    check_required_extensions(root);
    index(root, "scene", "");
    check_scenes_and_nodes(root);
    check_meshes(root);
    check_buffers(root);
    check_materials(root);
    check_textures(root);
  }

 private:
  void check_asset(const json& root) {
    object(root, "the top level");
    if (!root.contains("asset")) fail("has no 'asset' (not a glTF 2.0 file)");
    const json& asset = object(root["asset"], "asset");
    const json* version = member(asset, "version");
    if (!version || !version->is_string()) {
      fail("is not a glTF 2.0 file (asset.version is {})", version ? version->dump() : "missing");
    }
    if (version->get<std::string>().rfind("2.", 0) != 0) {
      fail("is glTF version {}; only glTF 2.x is supported", version->get<std::string>());
    }
  }

  void check_required_extensions(const json& root) {
    const json* required = member(root, "extensionsRequired");
    if (!required) return;
    for (const json& ext : array(*required, "extensionsRequired")) {
      if (!ext.is_string()) fail("extensionsRequired must hold strings");
      const std::string name = ext.get<std::string>();
      if (name != "KHR_materials_pbrSpecularGlossiness" && name != "KHR_mesh_quantization" &&
          name != "KHR_materials_unlit") {
        fail("requires the glTF extension {}, which is not supported", name);
      }
    }
  }

  void check_scenes_and_nodes(const json& root) {
    each(root, "scenes", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      indices(o, "nodes", at);
    });
    each(root, "nodes", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      index(o, "mesh", at);
      indices(o, "children", at);
      numbers(o, "matrix", 16, at);
      numbers(o, "translation", 3, at);
      numbers(o, "rotation", 4, at);
      numbers(o, "scale", 3, at);
    });
  }

  void check_meshes(const json& root) {
    each(root, "meshes", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      const json* prims = member(o, "primitives");
      if (!prims) fail("{}.primitives is missing", at);
      const json& list = array(*prims, at + ".primitives");
      for (std::size_t i = 0; i < list.size(); ++i) {
        check_primitive(list[i], fmt::format("{}.primitives[{}]", at, i));
      }
    });
  }

  static void check_primitive(const json& j, const std::string& at) {
    const json& prim = object(j, at);
    const json* attrs = member(prim, "attributes");
    if (!attrs) fail("{}.attributes is missing", at);
    for (const auto& [key, value] : object(*attrs, at + ".attributes").items()) {
      if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
        fail("{}.attributes.{} must be an index (it is {})", at, key, value.type_name());
      }
    }
    index(prim, "indices", at);
    index(prim, "material", at);
    index(prim, "mode", at);
  }

  // Accessors, buffer views and buffers.
  void check_buffers(const json& root) {
    each(root, "accessors", [&](const json& o, const std::string& at) {
      index(o, "bufferView", at);
      index(o, "byteOffset", at);
      index(o, "componentType", at);
      index(o, "count", at);
      string(o, "type", at);
    });
    each(root, "bufferViews", [&](const json& o, const std::string& at) {
      index(o, "buffer", at);
      index(o, "byteOffset", at);
      index(o, "byteLength", at);
      index(o, "byteStride", at);
    });
    each(root, "buffers", [&](const json& o, const std::string& at) {
      index(o, "byteLength", at);
      string(o, "uri", at);
    });
  }

  void check_materials(const json& root) {
    each(root, "materials", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      if (const json* pbr = member(o, "pbrMetallicRoughness")) {
        const std::string pat = at + ".pbrMetallicRoughness";
        object(*pbr, pat);
        numbers(*pbr, "baseColorFactor", 4, pat);
        number(*pbr, "metallicFactor", pat);
        number(*pbr, "roughnessFactor", pat);
        texture_info(*pbr, "baseColorTexture", pat);
        texture_info(*pbr, "metallicRoughnessTexture", pat);
      }
      texture_info(o, "normalTexture", at);
      texture_info(o, "occlusionTexture", at);
      texture_info(o, "emissiveTexture", at);
      if (const json* t = member(o, "normalTexture")) number(*t, "scale", at + ".normalTexture");
      if (const json* t = member(o, "occlusionTexture")) {
        number(*t, "strength", at + ".occlusionTexture");
      }
    });
  }

  // Textures and the images they use.
  void check_textures(const json& root) {
    each(root, "textures", [&](const json& o, const std::string& at) {
      index(o, "source", at);
      index(o, "sampler", at);
    });
    each(root, "images", [&](const json& o, const std::string& at) {
      string(o, "name", at);
      string(o, "uri", at);
      string(o, "mimeType", at);
      index(o, "bufferView", at);
    });
  }

  static std::string join(const std::string& at, const char* key) {
    return at.empty() ? std::string(key) : at + "." + key;
  }
  static const json& object(const json& j, const std::string& at) {
    if (!j.is_object()) fail("{} must be an object (it is {})", at, j.type_name());
    check_extensions(j, at);
    return j;
  }
  static const json& array(const json& j, const std::string& at) {
    if (!j.is_array()) fail("{} must be an array (it is {})", at, j.type_name());
    return j;
  }
  // Every "extensions" member is an object of objects.
  static void check_extensions(const json& o, const std::string& at) {
    const auto it = o.find("extensions");
    if (it == o.end()) return;
    if (!it->is_object()) fail("{}.extensions must be an object", at);
    for (const auto& [key, value] : it->items()) {
      if (!value.is_object()) fail("{}.extensions.{} must be an object", at, key);
    }
  }
  static const json* member(const json& o, const char* key) {
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }
  static void index(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key)) {
      if (!v->is_number_integer() || v->get<std::int64_t>() < 0) {
        fail("{} must be a non-negative integer (it is {} {})", join(at, key), v->type_name(),
             v->dump());
      }
    }
  }
  static void indices(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key)) {
      for (const json& e : array(*v, join(at, key))) {
        if (!e.is_number_integer() || e.get<std::int64_t>() < 0) {
          fail("{} must hold non-negative integers", join(at, key));
        }
      }
    }
  }
  static void number(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key); v && !v->is_number()) {
      fail("{} must be a number (it is {})", join(at, key), v->type_name());
    }
  }
  static void numbers(const json& o, const char* key, std::size_t n, const std::string& at) {
    if (const json* v = member(o, key)) {
      const json& a = array(*v, join(at, key));
      if (a.size() != n) fail("{} must have {} numbers (it has {})", join(at, key), n, a.size());
      for (const json& e : a) {
        if (!e.is_number()) fail("{} must hold numbers", join(at, key));
      }
    }
  }
  static void string(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key); v && !v->is_string()) {
      fail("{} must be a string (it is {})", join(at, key), v->type_name());
    }
  }
  static void texture_info(const json& o, const char* key, const std::string& at) {
    if (const json* v = member(o, key)) {
      const std::string pat = join(at, key);
      object(*v, pat);
      if (!v->contains("index")) fail("{}.index is missing", pat);
      index(*v, "index", pat);
      index(*v, "texCoord", pat);
    }
  }
  template <typename F>
  void each(const json& root, const char* key, F&& f) {
    if (const json* v = member(root, key)) {
      const json& a = array(*v, key);
      for (std::size_t i = 0; i < a.size(); ++i) {
        const std::string at = fmt::format("{}[{}]", key, i);
        f(object(a[i], at), at);
      }
    }
  }
};

// The JSON text of a .gltf file, or of a .glb's JSON chunk; empty if it cannot be found (tinygltf
// then reports the problem).
std::string gltf_json_text(const std::string& path, bool binary) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  if (!binary) return std::string(std::istreambuf_iterator<char>(in), {});
  unsigned char header[20];
  if (!in.read(reinterpret_cast<char*>(header), 20)) return {};
  auto u32 = [&](int at) {
    return static_cast<std::uint32_t>(header[at]) |
           static_cast<std::uint32_t>(header[at + 1]) << 8 |
           static_cast<std::uint32_t>(header[at + 2]) << 16 |
           static_cast<std::uint32_t>(header[at + 3]) << 24;
  };
  if (std::memcmp(header, "glTF", 4) != 0 || u32(16) != 0x4E4F534AU) return {};
  const std::uint32_t length = u32(12);
  std::error_code ec;
  const auto file_size = std::filesystem::file_size(path, ec);
  if (ec || length > file_size) return {};
  std::string text(length, '\0');
  if (!in.read(text.data(), length)) return {};
  return text;
}

// The files the buffers and images name beside the model must be regular files: tinygltf reads a
// folder as a file of absurd size (out of memory) and calls a device "missing". A file that does
// not exist is left to tinygltf's message; percent-encoded names too (tinygltf decodes them).
void check_external_files(const json& root, const std::filesystem::path& folder) {
  for (const char* key : {"buffers", "images"}) {
    const auto found = root.find(key);
    if (found == root.end()) continue;
    const json& list = *found;  // an array of objects (checked above)
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto uri = list[i].find("uri");
      if (uri == list[i].end() || !uri->is_string()) continue;
      const std::string name = uri->get<std::string>();
      if (name.starts_with("data:") || name.find('%') != std::string::npos) continue;
      const std::filesystem::path file = folder / name;
      if (names_nothing(file)) continue;
      if (const std::string why = why_not_readable(file); !why.empty()) {
        fail("{} {} '{}' {}", key == std::string("images") ? "image" : "buffer", i, name, why);
      }
    }
  }
}

}  // namespace

void check_gltf_schema(const std::string& path, bool binary) {
  const json root = json::parse(gltf_json_text(path, binary), nullptr, /*allow_exceptions=*/false);
  if (root.is_discarded()) return;
  GltfSchemaCheck().run(root);
  check_external_files(root, std::filesystem::path(path).parent_path());
}

}  // namespace rigc::loading
