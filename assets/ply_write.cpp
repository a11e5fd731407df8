// write_ply: a mesh as binary little-endian PLY.
#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "assets/mesh_io.h"
#include "io/atomic_file.h"

namespace rigc {

namespace fs = std::filesystem;

namespace {

// What makes `mesh` unwritable, or nothing.
std::optional<std::string> unwritable(const ir::Mesh& mesh) {
  const std::size_t n = mesh.positions.size();
  if (!mesh.normals.empty() && mesh.normals.size() != n) {
    return "normals and positions differ in count";
  }
  if (!mesh.uvs.empty() && mesh.uvs.size() != n) return "uvs and positions differ in count";
  if (!mesh.colors.empty() && mesh.colors.size() != n)
    return "colours and positions differ in count";
  if (n > std::numeric_limits<std::uint32_t>::max()) return "too many vertices";
  for (const auto& t : mesh.triangles) {
    if (t[0] >= n || t[1] >= n || t[2] >= n) return "a triangle index is out of range";
  }
  return std::nullopt;
}

std::string ply_header(const ir::Mesh& mesh) {
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by rigc\n";
  header += fmt::format("element vertex {}\n", mesh.positions.size());
  header += "property float x\nproperty float y\nproperty float z\n";
  if (!mesh.normals.empty()) header += "property float nx\nproperty float ny\nproperty float nz\n";
  if (!mesh.uvs.empty()) header += "property float s\nproperty float t\n";
  if (!mesh.colors.empty())
    header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  header += fmt::format("element face {}\n", mesh.triangles.size());
  header += "property list uchar uint vertex_indices\nend_header\n";
  return header;
}

// Little-endian float and uint32 bytes, written to a file in chunks. After a failed write it
// writes nothing more, and ok() is false.
class ChunkedWriter {
 public:
  ChunkedWriter(std::FILE* file, bool ok) : file_(file), ok_(ok) { chunk_.reserve(kChunk + 64); }

  void put8(unsigned char v) { chunk_.push_back(v); }
  void put32(std::uint32_t v) {
    if constexpr (std::endian::native == std::endian::big) {
      v = ((v & 0xffU) << 24) | ((v & 0xff00U) << 8) | ((v >> 8) & 0xff00U) | (v >> 24);
    }
    unsigned char b[4];
    std::memcpy(b, &v, 4);
    chunk_.insert(chunk_.end(), b, b + 4);
  }
  void put_float(float f) { put32(std::bit_cast<std::uint32_t>(f)); }

  // Writes the chunk once it is full, or now when `force`.
  void flush(bool force) {
    if (ok_ && (force || chunk_.size() >= kChunk)) {
      ok_ = std::fwrite(chunk_.data(), 1, chunk_.size(), file_) == chunk_.size();
      chunk_.clear();
    }
  }

  bool ok() const { return ok_; }

 private:
  static constexpr std::size_t kChunk = 1 << 20;
  std::FILE* file_;
  bool ok_;
  std::vector<unsigned char> chunk_;
};

// A linear colour channel as a scanner writes it: 8-bit sRGB.
unsigned char srgb_byte(float linear) {
  const float v = std::isfinite(linear) ? std::clamp(linear, 0.0f, 1.0f) : 0.0f;
  const float encoded = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1 / 2.4f) - 0.055f;
  return static_cast<unsigned char>(std::lround(255 * encoded));
}

// The vertices, then the faces; false if a write failed.
bool write_ply_body(const ir::Mesh& mesh, ChunkedWriter* out) {
  const bool normals = !mesh.normals.empty();
  const bool uvs = !mesh.uvs.empty();
  for (std::size_t i = 0; i < mesh.positions.size() && out->ok(); ++i) {
    for (int k = 0; k < 3; ++k) out->put_float(mesh.positions[i][k]);
    if (normals) {
      for (int k = 0; k < 3; ++k) out->put_float(mesh.normals[i][k]);
    }
    if (uvs) {
      // PLY texture coordinates have t = 0 at the image bottom.
      out->put_float(mesh.uvs[i].x());
      out->put_float(1.0f - mesh.uvs[i].y());
    }
    if (!mesh.colors.empty()) {
      for (int k = 0; k < 3; ++k) out->put8(srgb_byte(mesh.colors[i][k]));
    }
    out->flush(false);
  }
  for (std::size_t i = 0; i < mesh.triangles.size() && out->ok(); ++i) {
    out->put8(3);
    for (int k = 0; k < 3; ++k) out->put32(mesh.triangles[i][k]);
    out->flush(false);
  }
  out->flush(true);
  return out->ok();
}

}  // namespace

// Writes the whole file or nothing (io/atomic_file.h), so a reader never sees half a file.
bool write_ply(const std::string& path, const ir::Mesh& mesh, std::string* error) {
  if (const std::optional<std::string> problem = unwritable(mesh)) {
    if (error) *error = fmt::format("{}: {}", path, *problem);
    return false;
  }
  const std::string header = ply_header(mesh);
  return write_atomically(
      path,
      [&](const fs::path& temporary, std::string* reason) {
        std::FILE* file = std::fopen(temporary.c_str(), "wb");
        if (!file) {
          *reason = std::strerror(errno);
          return false;
        }
        ChunkedWriter out(file,
                          std::fwrite(header.data(), 1, header.size(), file) == header.size());
        bool ok = write_ply_body(mesh, &out);
        ok = (std::fflush(file) == 0) && ok;
        ok = (std::fclose(file) == 0) && ok;
        if (!ok) *reason = "write failed (disk full?)";
        return ok;
      },
      error);
}

}  // namespace rigc
