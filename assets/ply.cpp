// PLY, read natively: ASCII and binary (either byte order), any element order, lists anywhere,
// polygons split into fans, triangle strips (`tristrips`, -1 restarting a strip), per-vertex
// colours, and a texture named by a "comment TextureFile" header line.
#include <algorithm>
#include <array>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "assets/model_loading.h"
#include "assets/textures.h"
#include "io/file_status.h"

namespace rigc::loading {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;

enum class PlyType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::optional<PlyType> ply_type(const std::string& name) {
  if (name == "char" || name == "int8") return PlyType::kInt8;
  if (name == "uchar" || name == "uint8") return PlyType::kUint8;
  if (name == "short" || name == "int16") return PlyType::kInt16;
  if (name == "ushort" || name == "uint16") return PlyType::kUint16;
  if (name == "int" || name == "int32") return PlyType::kInt32;
  if (name == "uint" || name == "uint32") return PlyType::kUint32;
  if (name == "float" || name == "float32") return PlyType::kFloat32;
  if (name == "double" || name == "float64") return PlyType::kFloat64;
  return std::nullopt;
}

std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUint8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUint16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUint32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 1;
}

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUint8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { kAscii, kBinaryLittle, kBinaryBig };

// Reads the values of one element instance after another, in ASCII or binary.
class PlyCursor {
 public:
  PlyCursor(const char* begin, const char* end, PlyFormat format)
      : p_(begin), end_(end), format_(format) {}

  double read(PlyType type) {
    if (format_ == PlyFormat::kAscii) return read_ascii();
    const std::size_t size = ply_size(type);
    if (static_cast<std::size_t>(end_ - p_) < size) fail("ends early (truncated data)");
    unsigned char b[8];
    std::memcpy(b, p_, size);
    p_ += size;
    if ((format_ == PlyFormat::kBinaryBig) == (std::endian::native == std::endian::little)) {
      std::reverse(b, b + size);
    }
    switch (type) {
      case PlyType::kInt8:
        return static_cast<std::int8_t>(b[0]);
      case PlyType::kUint8:
        return b[0];
      case PlyType::kInt16:
        return load<std::int16_t>(b);
      case PlyType::kUint16:
        return load<std::uint16_t>(b);
      case PlyType::kInt32:
        return load<std::int32_t>(b);
      case PlyType::kUint32:
        return load<std::uint32_t>(b);
      case PlyType::kFloat32:
        return load<float>(b);
      case PlyType::kFloat64:
        return load<double>(b);
    }
    return 0;
  }

  std::size_t remaining() const { return static_cast<std::size_t>(end_ - p_); }

 private:
  template <typename T>
  static double load(const unsigned char* b) {
    T v;
    std::memcpy(&v, b, sizeof(T));
    return static_cast<double>(v);
  }

  double read_ascii() {
    while (p_ < end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    if (p_ == end_) fail("ends early (truncated data)");
    const char* start = p_;
    while (p_ < end_ && !std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    double v = 0;
    const char* first = start;
    if (*first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, p_, v);
    if (ec != std::errc() || ptr != p_) {
      // from_chars does not take "inf"/"nan" spelled every way; let strtod decide.
      const std::string token(start, p_);
      char* parse_end = nullptr;
      v = std::strtod(token.c_str(), &parse_end);
      if (parse_end != token.c_str() + token.size()) fail("has a bad number '{}'", token);
    }
    return v;
  }

  const char* p_;
  const char* end_;
  PlyFormat format_;
};

// ---------------------------------------------------------------------------------------------
// The header.

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::string texture_file;    // relative to the PLY file; empty if none
  const char* body = nullptr;  // the first byte after end_header
};

// The header's lines, without their line breaks.
class PlyHeaderLines {
 public:
  PlyHeaderLines(const char* begin, const char* end) : p_(begin), end_(end) {}

  std::optional<std::string> next() {
    if (p_ >= end_) return std::nullopt;
    const char* nl = static_cast<const char*>(std::memchr(p_, '\n', end_ - p_));
    const char* line_end = nl ? nl : end_;
    std::string line(p_, line_end);
    p_ = nl ? nl + 1 : end_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
  }

  const char* position() const { return p_; }

 private:
  const char* p_;
  const char* end_;
};

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    std::size_t j = i;
    while (j < line.size() && !std::isspace(static_cast<unsigned char>(line[j]))) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

PlyFormat parse_format(const std::vector<std::string>& w, int line_no) {
  if (w.size() < 2) fail("header line {}: malformed format", line_no);
  if (w[1] == "ascii") return PlyFormat::kAscii;
  if (w[1] == "binary_little_endian") return PlyFormat::kBinaryLittle;
  if (w[1] == "binary_big_endian") return PlyFormat::kBinaryBig;
  fail("header line {}: unknown format '{}'", line_no, w[1]);
}

PlyElement parse_element(const std::vector<std::string>& w, int line_no) {
  if (w.size() != 3) fail("header line {}: malformed element", line_no);
  PlyElement e;
  e.name = w[1];
  const auto [ptr, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
  if (ec != std::errc() || ptr != w[2].data() + w[2].size()) {
    fail("header line {}: bad element count '{}'", line_no, w[2]);
  }
  return e;
}

PlyProperty parse_property(const std::vector<std::string>& w, int line_no) {
  PlyProperty prop;
  if (w.size() == 5 && w[1] == "list") {
    const auto count_type = ply_type(w[2]);
    const auto item_type = ply_type(w[3]);
    if (!count_type || !item_type) fail("header line {}: unknown property type", line_no);
    if (*count_type == PlyType::kFloat32 || *count_type == PlyType::kFloat64) {
      fail("header line {}: list count type must be an integer", line_no);
    }
    prop.is_list = true;
    prop.count_type = *count_type;
    prop.type = *item_type;
    prop.name = w[4];
  } else if (w.size() == 3) {
    const auto type = ply_type(w[1]);
    if (!type) fail("header line {}: unknown property type '{}'", line_no, w[1]);
    prop.type = *type;
    prop.name = w[2];
  } else {
    fail("header line {}: malformed property", line_no);
  }
  return prop;
}

PlyHeader read_header(const char* data, const char* end) {
  PlyHeaderLines lines(data, end);
  if (auto first = lines.next(); !first || words(*first) != std::vector<std::string>{"ply"}) {
    fail("is not a PLY file (no 'ply' magic)");
  }
  PlyHeader header;
  bool has_format = false;
  for (int line_no = 2;; ++line_no) {
    const auto line = lines.next();
    if (!line) fail("has no end_header");
    const std::vector<std::string> w = words(*line);
    if (w.empty()) continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      header.format = parse_format(w, line_no);
      has_format = true;
    } else if (w[0] == "element") {
      header.elements.push_back(parse_element(w, line_no));
    } else if (w[0] == "property") {
      if (header.elements.empty()) fail("header line {}: property before any element", line_no);
      header.elements.back().properties.push_back(parse_property(w, line_no));
    } else if (w[0] == "comment" && w.size() >= 3 && lower(w[1]) == "texturefile") {
      header.texture_file = line->substr(line->find(w[1]) + w[1].size());
      header.texture_file.erase(0, header.texture_file.find_first_not_of(" \t"));
    }
    // Other lines (comment, obj_info, and stray text some exporters write) are ignored.
  }
  if (!has_format) fail("has no format line");
  header.body = lines.position();
  return header;
}

// Guards against absurd counts: every element instance takes at least one byte (binary) or two
// characters (ASCII) per property.
void check_element_counts(const PlyHeader& header, const char* end) {
  for (const PlyElement& e : header.elements) {
    std::size_t per = 0;
    for (const PlyProperty& prop : e.properties) {
      per += header.format == PlyFormat::kAscii
                 ? 2
                 : (prop.is_list ? ply_size(prop.count_type) : ply_size(prop.type));
    }
    if (per > 0 && e.count > (static_cast<std::size_t>(end - header.body) + 1) / per) {
      fail("is truncated: element '{}' claims {} entries, more than the file holds", e.name,
           e.count);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// The body.

// Vertex property slots: x y z nx ny nz u v r g b.
constexpr int kSlots = 11;
struct VertexSlots {
  std::vector<int> slot;  // per property: its slot, or -1 if unused
  bool has_normals = false;
  bool has_uvs = false;
  bool has_colors = false;
  double color_scale = 1;  // to 0..1: 1/255 for uchar colours, 1 for float ones
};

// What a colour of `type` is divided by to reach 0..1.
double color_full_scale(PlyType type) {
  switch (type) {
    case PlyType::kUint8:
    case PlyType::kInt8:
      return 255;
    case PlyType::kUint16:
    case PlyType::kInt16:
      return 65535;
    case PlyType::kUint32:
    case PlyType::kInt32:
      return 4294967295.0;
    case PlyType::kFloat32:
    case PlyType::kFloat64:
      return 1;
  }
  return 1;
}

VertexSlots vertex_slots(const PlyElement& e) {
  static const std::vector<std::vector<std::string>> kNames = {{"x"},
                                                               {"y"},
                                                               {"z"},
                                                               {"nx"},
                                                               {"ny"},
                                                               {"nz"},
                                                               {"s", "u", "texture_u", "texture_s"},
                                                               {"t", "v", "texture_v", "texture_t"},
                                                               {"red", "diffuse_red", "r"},
                                                               {"green", "diffuse_green", "g"},
                                                               {"blue", "diffuse_blue", "b"}};
  VertexSlots slots;
  slots.slot.assign(e.properties.size(), -1);
  std::array<bool, kSlots> found{};
  for (std::size_t k = 0; k < e.properties.size(); ++k) {
    if (e.properties[k].is_list) continue;
    for (int s = 0; s < kSlots; ++s) {
      const auto& names = kNames[s];
      if (!found[s] && std::find(names.begin(), names.end(), e.properties[k].name) != names.end()) {
        slots.slot[k] = s;
        found[s] = true;
        if (s == 8) slots.color_scale = 1 / color_full_scale(e.properties[k].type);
      }
    }
  }
  if (!found[0] || !found[1] || !found[2]) fail("vertex element has no x, y, z properties");
  slots.has_normals = found[3] && found[4] && found[5];
  slots.has_uvs = found[6] && found[7];
  slots.has_colors = found[8] && found[9] && found[10];
  return slots;
}

// The sRGB transfer function undone: an 8-bit scanner colour to linear RGB.
float srgb_to_linear(float v) {
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// Reads the elements into a LoadedModel with one material: vertices, faces, and skips the rest.
class PlyReader {
 public:
  PlyReader(const PlyHeader& header, const char* end, LoadedModel* out)
      : cursor_(header.body, end, header.format), builder_(out) {
    ir::Material material;
    material.name = "default";
    out->materials.push_back(std::move(material));
  }

  void read(const PlyHeader& header) {
    for (const PlyElement& e : header.elements) {
      if (e.name == "vertex") {
        read_vertices(e);
      } else if (e.name == "face") {
        read_faces(e);
      } else if (e.name == "tristrips") {
        read_strips(e);
      } else {
        skip_element(e);
      }
    }
    if (!has_normals_ || !normals_ok_) builder_.set_needs_normal(0, vertex_count_);
    if (has_uvs_) builder_.set_has_uvs();
  }

  MeshBuilder& builder() { return builder_; }

 private:
  void read_vertices(const PlyElement& e) {
    if (seen_vertices_) fail("has two vertex elements");
    seen_vertices_ = true;
    const VertexSlots slots = vertex_slots(e);
    has_normals_ = slots.has_normals;
    has_uvs_ = slots.has_uvs;
    color_scale_ = slots.has_colors ? slots.color_scale : 0;
    vertex_count_ = e.count;
    if (vertex_count_ > kMaxVertices) fail("has too many vertices ({})", vertex_count_);
    builder_.add_vertices(vertex_count_);
    if (color_scale_ > 0) builder_.add_colors();
    double values[kSlots];
    for (std::size_t i = 0; i < e.count; ++i) {
      std::fill(values, values + kSlots, 0.0);
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& prop = e.properties[k];
        if (prop.is_list) {
          skip_list(prop);
          continue;
        }
        const double v = cursor_.read(prop.type);
        if (slots.slot[k] >= 0) values[slots.slot[k]] = v;
      }
      set_vertex(i, values);
    }
  }

  // Sets vertex i from its slot values (x y z nx ny nz u v r g b).
  void set_vertex(std::size_t i, const double* values) {
    const auto index = static_cast<std::uint32_t>(i);
    const Vector3f pos(static_cast<float>(values[0]), static_cast<float>(values[1]),
                       static_cast<float>(values[2]));
    if (!pos.allFinite()) {
      fail("vertex {} has a position that is not finite ({}, {}, {})", i, values[0], values[1],
           values[2]);
    }
    builder_.position(index) = pos;
    if (has_normals_) {
      const Vector3f n(static_cast<float>(values[3]), static_cast<float>(values[4]),
                       static_cast<float>(values[5]));
      const float len = n.norm();
      if (!std::isfinite(len) || len < 1e-6f) {
        normals_ok_ = false;
      } else {
        builder_.normal(index) = n / len;
      }
    }
    if (has_uvs_) {
      // PLY's t = 0 is the image bottom; RigC's v = 0 is the image top.
      const Vector2f uv(static_cast<float>(values[6]), 1.0f - static_cast<float>(values[7]));
      if (uv.allFinite()) builder_.uv(index) = uv;
    }
    if (color_scale_ > 0) {
      // Scanners write sRGB-encoded colours; the IR's are linear.
      Vector3f color;
      for (int c = 0; c < 3; ++c) {
        const double v = values[8 + c] * color_scale_;
        color[c] =
            srgb_to_linear(std::isfinite(v) ? static_cast<float>(std::clamp(v, 0.0, 1.0)) : 0.0f);
      }
      builder_.color(index) = color;
    }
  }

  void read_faces(const PlyElement& e) {
    if (!seen_vertices_) fail("face element comes before the vertex element");
    int list = -1;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const PlyProperty& prop = e.properties[k];
      if (prop.is_list && (prop.name == "vertex_indices" || prop.name == "vertex_index")) {
        list = static_cast<int>(k);
        break;
      }
    }
    if (list < 0) fail("face element has no vertex_indices list");
    builder_.reserve_triangles(e.count);
    for (std::size_t f = 0; f < e.count; ++f) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& prop = e.properties[k];
        if (!prop.is_list) {
          cursor_.read(prop.type);
          continue;
        }
        const double n = cursor_.read(prop.count_type);
        if (n < 0 || n > static_cast<double>(cursor_.remaining())) {
          fail("face {} has a bad vertex count {}", f, n);
        }
        const auto count = static_cast<std::size_t>(n);
        if (static_cast<int>(k) != list) {
          for (std::size_t j = 0; j < count; ++j) cursor_.read(prop.type);
          continue;
        }
        add_polygon(f, prop, count);
      }
    }
  }

  // Reads face f's `count` vertex indices and adds the polygon as a fan of triangles.
  void add_polygon(std::size_t f, const PlyProperty& prop, std::size_t count) {
    polygon_.clear();
    for (std::size_t j = 0; j < count; ++j) {
      const double v = cursor_.read(prop.type);
      if (!(v >= 0 && v < static_cast<double>(vertex_count_))) {
        fail("face {} index {} is out of range ({} vertices)", f, v, vertex_count_);
      }
      polygon_.push_back(static_cast<std::uint32_t>(v));
    }
    for (std::size_t j = 1; j + 1 < polygon_.size(); ++j) {
      builder_.add_triangle(polygon_[0], polygon_[j], polygon_[j + 1], 0, false);
    }
  }

  // Triangle strips: one list of indices per strip, -1 starting a new strip. Every third index
  // after the first two makes a triangle, the winding alternating along the strip; triangles
  // with a repeated corner (used to join strips) are dropped.
  void read_strips(const PlyElement& e) {
    if (!seen_vertices_) fail("tristrips element comes before the vertex element");
    for (std::size_t f = 0; f < e.count; ++f) {
      for (const PlyProperty& prop : e.properties) {
        if (!prop.is_list) {
          cursor_.read(prop.type);
          continue;
        }
        const double n = cursor_.read(prop.count_type);
        if (n < 0 || n > static_cast<double>(cursor_.remaining())) {
          fail("strip {} has a bad index count {}", f, n);
        }
        if (prop.name != "vertex_indices" && prop.name != "vertex_index") {
          for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) cursor_.read(prop.type);
          continue;
        }
        add_strips(f, prop, static_cast<std::size_t>(n));
      }
    }
  }

  void add_strips(std::size_t f, const PlyProperty& prop, std::size_t count) {
    polygon_.clear();  // the current strip
    for (std::size_t j = 0; j < count; ++j) {
      const double v = cursor_.read(prop.type);
      if (v == -1) {
        polygon_.clear();
        continue;
      }
      if (!(v >= 0 && v < static_cast<double>(vertex_count_))) {
        fail("strip {} index {} is out of range ({} vertices)", f, v, vertex_count_);
      }
      polygon_.push_back(static_cast<std::uint32_t>(v));
      const std::size_t k = polygon_.size();
      if (k < 3) continue;
      std::uint32_t a = polygon_[k - 3], b = polygon_[k - 2];
      const std::uint32_t c = polygon_[k - 1];
      if (a == b || b == c || a == c) continue;
      if (k % 2 == 0) std::swap(a, b);  // every other triangle of a strip is wound backwards
      builder_.add_triangle(a, b, c, 0, false);
    }
  }

  void skip_element(const PlyElement& e) {
    for (std::size_t i = 0; i < e.count; ++i) {
      for (const PlyProperty& prop : e.properties) {
        if (prop.is_list) {
          skip_list(prop);
        } else {
          cursor_.read(prop.type);
        }
      }
    }
  }

  void skip_list(const PlyProperty& prop) {
    const double n = cursor_.read(prop.count_type);
    if (n < 0 || n > static_cast<double>(cursor_.remaining())) fail("has a bad list length");
    for (std::size_t j = 0; j < static_cast<std::size_t>(n); ++j) cursor_.read(prop.type);
  }

  PlyCursor cursor_;
  MeshBuilder builder_;
  std::size_t vertex_count_ = 0;
  bool seen_vertices_ = false;
  bool has_normals_ = false, has_uvs_ = false, normals_ok_ = true;
  double color_scale_ = 0;  // 0: the vertices have no colours
  std::vector<std::uint32_t> polygon_;
};

}  // namespace

LoadedModel load_ply(const std::string& path) {
  const std::vector<unsigned char> bytes = read_file_bytes(path);
  const char* data = reinterpret_cast<const char*>(bytes.data());
  const char* end = data + bytes.size();
  const PlyHeader header = read_header(data, end);
  check_element_counts(header, end);

  LoadedModel out;
  PlyReader reader(header, end, &out);
  reader.read(header);
  if (!header.texture_file.empty()) {
    const fs::path file = (fs::path(path).parent_path() / header.texture_file).lexically_normal();
    if (const std::string why = why_not_readable(file); !why.empty()) {
      fail("texture '{}' {}", file.string(), why);
    }
    out.textures.push_back(decode_image(file.string(), read_file_bytes(file),
                                        fmt::format("texture '{}'", file.string())));
    out.materials[0].base_color_texture = 0;
    out.materials[0].base_color = Vector3d(1, 1, 1);
  }
  reader.builder().finish();
  return out;
}

}  // namespace rigc::loading
