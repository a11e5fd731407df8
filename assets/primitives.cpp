#include "assets/primitives.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <thread>
#include <vector>

#include "ir/hash.h"

namespace rigc {
namespace {

using Eigen::Vector2f;
using Eigen::Vector3d;
using Eigen::Vector3f;
using Tri = std::array<std::uint32_t, 3>;

constexpr double kPi = std::numbers::pi;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

// Icosphere edge frequency per detail level: each of the 20 icosahedron faces is cut into
// N x N triangles, so a sphere or statue has 20 N^2 triangles and 10 N^2 + 2 welded vertices:
//   detail:     1    2     3     4      5       6        7          8          9          10
//   N:          4    7    12    22     40      71      126        225        400         712
//   triangles: 320  980  2880  9680  32000  100820  317520  1012500  3200000  10138880
constexpr std::array<int, 10> kFrequency = {4, 7, 12, 22, 40, 71, 126, 225, 400, 712};

int clamp_detail(int detail) {
  return std::clamp(detail, 1, 10);
}

// ---------------------------------------------------------------------------------------------
// Deterministic noise: integer hashing only, so the same seed gives the same shape everywhere.

std::uint32_t hash_u32(std::uint32_t x) {
  return lowbias32(x);
}

std::uint32_t hash_lattice(std::int32_t x, std::int32_t y, std::int32_t z, std::uint32_t seed) {
  return hash_u32(static_cast<std::uint32_t>(x) * 0x8da6b343U ^
                  static_cast<std::uint32_t>(y) * 0xd8163841U ^
                  static_cast<std::uint32_t>(z) * 0xcb1ab31fU ^ seed * 0x9e3779b9U);
}

// Dot product of the lattice point's pseudo-random gradient with the offset (x, y, z). The
// gradients are Perlin's 12 cube-edge directions, four of them twice to make 16 (a table lookup
// rather than a branch: the branch mispredicts on every call).
double grad_dot(std::uint32_t h, double x, double y, double z) {
  static constexpr double kGrad[16][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0},
                                          {1, 0, 1}, {-1, 0, 1}, {1, 0, -1}, {-1, 0, -1},
                                          {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1},
                                          {1, 1, 0}, {-1, 1, 0}, {0, -1, 1}, {0, -1, -1}};
  const double* g = kGrad[h >> 28];
  return g[0] * x + g[1] * y + g[2] * z;
}

double fade(double t) {
  return t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
}
double lerp(double a, double b, double t) {
  return a + t * (b - a);
}

// 3D gradient noise, roughly in [-1, 1], zero at lattice points.
double gradient_noise(double x, double y, double z, std::uint32_t seed) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const auto ix = static_cast<std::int32_t>(fx);
  const auto iy = static_cast<std::int32_t>(fy);
  const auto iz = static_cast<std::int32_t>(fz);
  const double dx = x - fx, dy = y - fy, dz = z - fz;
  const double u = fade(dx), v = fade(dy), w = fade(dz);
  auto g = [&](int ox, int oy, int oz) {
    return grad_dot(hash_lattice(ix + ox, iy + oy, iz + oz, seed), dx - ox, dy - oy, dz - oz);
  };
  const double x00 = lerp(g(0, 0, 0), g(1, 0, 0), u);
  const double x10 = lerp(g(0, 1, 0), g(1, 1, 0), u);
  const double x01 = lerp(g(0, 0, 1), g(1, 0, 1), u);
  const double x11 = lerp(g(0, 1, 1), g(1, 1, 1), u);
  return lerp(lerp(x00, x10, v), lerp(x01, x11, v), w);
}

// One octave of displacement: amplitude * noise(frequency * p), with its own seed and a lattice
// offset so that octaves do not share zero crossings at the lattice points.
struct Octave {
  double frequency;
  double amplitude;
  std::uint32_t seed;
  Vector3d offset;

  Octave(double f, double a, std::uint32_t s) : frequency(f), amplitude(a), seed(hash_u32(s)) {
    offset = Vector3d(hash_u32(seed ^ 1U) % 1024U, hash_u32(seed ^ 2U) % 1024U,
                      hash_u32(seed ^ 3U) % 1024U) /
             7.0;
  }
  double operator()(const Vector3d& p) const {
    const Vector3d q = p * frequency + offset;
    return gradient_noise(q.x(), q.y(), q.z(), seed);
  }
};

// ---------------------------------------------------------------------------------------------
// Geodesic icosphere with a shared (welded) vertex for every point, so it is a closed mesh.

struct Icosphere {
  std::vector<Vector3d> directions;  // unit
  std::vector<Tri> triangles;        // counter-clockwise seen from outside
};

// The icosahedron the sphere is cut from, with vertices at the poles: 0 = north, 1..5 upper ring,
// 6..10 lower ring, 11 = south.
struct Icosahedron {
  std::array<Vector3d, 12> corners;  // unit
  std::vector<Tri> faces;            // 20, counter-clockwise seen from outside
};

Icosahedron make_icosahedron() {
  // cos and sin of multiples of 36 degrees from square roots only (no libm trigonometry, so the
  // corners are bit-identical on every platform).
  const double s5 = std::sqrt(5.0);
  const std::array<double, 3> cos36 = {1.0, (1.0 + s5) / 4.0, (s5 - 1.0) / 4.0};  // 0, 36, 72
  const std::array<double, 3> sin36 = {0.0, std::sqrt(10.0 - 2.0 * s5) / 4.0,
                                       std::sqrt(10.0 + 2.0 * s5) / 4.0};
  auto cos_sin = [&](int step) -> std::pair<double, double> {  // angle = 36 degrees * step
    step %= 10;
    const int q = step <= 5 ? step : 10 - step;  // fold to 0..180
    const double c = q <= 2 ? cos36[q] : -cos36[5 - q];
    const double s = q <= 2 ? sin36[q] : sin36[5 - q];
    return {c, step <= 5 ? s : -s};
  };
  Icosahedron ico;
  const double ring_z = 1.0 / s5;
  const double ring_r = 2.0 / s5;
  ico.corners[0] = {0, 0, 1};
  ico.corners[11] = {0, 0, -1};
  for (int k = 0; k < 5; ++k) {
    const auto [cu, su] = cos_sin(2 * k);
    const auto [cl, sl] = cos_sin(2 * k + 1);
    ico.corners[1 + k] = {ring_r * cu, ring_r * su, ring_z};
    ico.corners[6 + k] = {ring_r * cl, ring_r * sl, -ring_z};
  }
  for (std::uint32_t k = 0; k < 5; ++k) {
    const std::uint32_t u0 = 1 + k, u1 = 1 + (k + 1) % 5;
    const std::uint32_t l0 = 6 + k, l1 = 6 + (k + 1) % 5;
    ico.faces.push_back({0, u0, u1});
    ico.faces.push_back({u0, l0, u1});
    ico.faces.push_back({u1, l0, l1});
    ico.faces.push_back({11, l1, l0});
  }
  return ico;
}

// Cuts each icosahedron face into n x n triangles. The vertices are numbered corners first (12),
// then each of the 30 edges' n - 1 inner points, then each face's interior points, so that a
// point on an edge is one vertex shared by the edge's two faces.
class IcosphereSubdivision {
 public:
  IcosphereSubdivision(const Icosahedron& ico, int n)
      : ico_(ico),
        n_(n),
        un_(static_cast<std::uint32_t>(n)),
        edge_verts_(static_cast<std::size_t>(n - 1)),
        face_verts_(static_cast<std::size_t>(n - 1) * (n - 2) / 2) {
    number_edges();
  }

  Icosphere build() {
    Icosphere out;
    out.directions.resize(12 + 30 * edge_verts_ + 20 * face_verts_);
    out.triangles.reserve(static_cast<std::size_t>(20) * n_ * n_);
    for (int c = 0; c < 12; ++c) out.directions[c] = ico_.corners[c];
    for (std::size_t fi = 0; fi < ico_.faces.size(); ++fi) subdivide_face(fi, &out);
    return out;
  }

 private:
  void number_edges() {
    for (auto& row : edge_id_) row.fill(-1);
    int edge_count = 0;
    for (const Tri& f : ico_.faces) {
      for (int e = 0; e < 3; ++e) {
        const std::uint32_t a = f[e], b = f[(e + 1) % 3];
        if (edge_id_[a][b] < 0) edge_id_[a][b] = edge_id_[b][a] = edge_count++;
      }
    }
  }

  // Vertex on edge a->b, t steps (1..n-1) from a.
  std::uint32_t edge_vertex(std::uint32_t a, std::uint32_t b, std::uint32_t t) const {
    const std::uint32_t k = a < b ? t : un_ - t;
    return static_cast<std::uint32_t>(12 + edge_id_[a][b] * edge_verts_ + (k - 1));
  }

  // Numbers and places the points of face fi's triangular grid (point (i, j) is i steps from its
  // corner a towards b and j towards c), and adds the face's n x n triangles.
  void subdivide_face(std::size_t fi, Icosphere* out) {
    const auto [a, b, c] = ico_.faces[fi];
    const std::size_t face_base = 12 + 30 * edge_verts_ + fi * face_verts_;
    const int n = n_;
    const std::uint32_t un = un_;
    grid_.assign(static_cast<std::size_t>(n + 1) * (n + 1), kNone);
    std::size_t interior = 0;
    for (std::uint32_t j = 0; j <= un; ++j) {
      for (std::uint32_t i = 0; i + j <= un; ++i) {
        std::uint32_t id;
        if (i == 0 && j == 0) {
          id = a;
        } else if (i == un) {
          id = b;
        } else if (j == un) {
          id = c;
        } else if (j == 0) {
          id = edge_vertex(a, b, i);
        } else if (i == 0) {
          id = edge_vertex(a, c, j);
        } else if (i + j == un) {
          id = edge_vertex(b, c, j);
        } else {
          id = static_cast<std::uint32_t>(face_base + interior++);
        }
        grid_[i + j * (n + 1)] = id;
        if (id >= 12) {
          // Edge vertices are written by both faces; both compute the same normalised point
          // up to rounding, and the order of faces is fixed, so the result is deterministic.
          const double wb = static_cast<double>(i) / n, wc = static_cast<double>(j) / n;
          const Vector3d p =
              ico_.corners[a] * (1.0 - wb - wc) + ico_.corners[b] * wb + ico_.corners[c] * wc;
          out->directions[id] = p.normalized();
        }
      }
    }
    auto at = [&](std::uint32_t i, std::uint32_t j) { return grid_[i + j * (n + 1)]; };
    for (std::uint32_t j = 0; j < un; ++j) {
      for (std::uint32_t i = 0; i + j < un; ++i) {
        out->triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 1 < un) {
          out->triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
        }
      }
    }
  }

  const Icosahedron& ico_;
  const int n_;
  const std::uint32_t un_;
  const std::size_t edge_verts_;                 // inner points per edge
  const std::size_t face_verts_;                 // interior points per face
  std::array<std::array<int, 12>, 12> edge_id_;  // the 30 edges' numbers, -1 for no edge
  std::vector<std::uint32_t> grid_;  // (n+1) x (n+1), index i + j * (n+1), for i + j <= n
};

Icosphere make_icosphere(int n) {
  const Icosahedron ico = make_icosahedron();
  return IcosphereSubdivision(ico, n).build();
}

// Area-weighted vertex normals.
std::vector<Vector3f> vertex_normals(const std::vector<Vector3f>& positions,
                                     const std::vector<Tri>& triangles) {
  std::vector<Vector3f> normals(positions.size(), Vector3f::Zero());
  for (const Tri& t : triangles) {
    const Vector3f& p0 = positions[t[0]];
    const Vector3f n = (positions[t[1]] - p0).cross(positions[t[2]] - p0);
    normals[t[0]] += n;
    normals[t[1]] += n;
    normals[t[2]] += n;
  }
  for (std::size_t i = 0; i < normals.size(); ++i) {
    const float len = normals[i].norm();
    normals[i] = len > 0 ? Vector3f(normals[i] / len) : Vector3f(0, 0, 1);
  }
  return normals;
}

// Gives a welded sphere-like mesh spherical uvs from the unit directions: u = longitude / 2 pi,
// v = colatitude / pi (v = 0 at the north pole, the image top). Vertices on the seam and at the
// poles are duplicated so that no triangle interpolates across the seam; u then runs to a little
// past 1 on the seam's triangles (textures repeat).
void add_spherical_uvs(const std::vector<Vector3d>& directions, ir::Mesh* mesh) {
  const std::size_t n = directions.size();
  mesh->uvs.resize(n);
  std::vector<bool> pole(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    const Vector3d& d = directions[i];
    const double r_xy = std::hypot(d.x(), d.y());
    pole[i] = r_xy < 1e-12;
    const double u = pole[i] ? 0.0 : std::atan2(d.y(), d.x()) / (2.0 * kPi) + 0.5;
    const double v = std::acos(std::clamp(d.z(), -1.0, 1.0)) / kPi;
    mesh->uvs[i] = Vector2f(static_cast<float>(u), static_cast<float>(v));
  }
  std::vector<std::uint32_t> wrapped(n, kNone);
  std::vector<bool> pole_used(n, false);
  auto duplicate = [&](std::uint32_t i, const Vector2f& uv) {
    const Vector3f p = mesh->positions[i], normal = mesh->normals[i];
    mesh->positions.push_back(p);
    mesh->normals.push_back(normal);
    mesh->uvs.push_back(uv);
    return static_cast<std::uint32_t>(mesh->positions.size() - 1);
  };
  for (Tri& t : mesh->triangles) {
    float u_min = 2, u_max = -1;
    for (std::uint32_t i : t) {
      if (pole[i]) continue;
      u_min = std::min(u_min, mesh->uvs[i].x());
      u_max = std::max(u_max, mesh->uvs[i].x());
    }
    if (u_max - u_min > 0.5f) {
      for (std::uint32_t& i : t) {
        if (pole[i] || mesh->uvs[i].x() >= 0.5f) continue;
        if (wrapped[i] == kNone) {
          wrapped[i] = duplicate(i, Vector2f(mesh->uvs[i].x() + 1.0f, mesh->uvs[i].y()));
        }
        i = wrapped[i];
      }
    }
    for (std::uint32_t& i : t) {
      if (i >= n || !pole[i]) continue;
      // A pole vertex gets its own copy per triangle, with u between its neighbours.
      float u_sum = 0;
      int count = 0;
      for (std::uint32_t k : t) {
        if (k != i && (k >= n || !pole[k])) {
          u_sum += mesh->uvs[k].x();
          ++count;
        }
      }
      const Vector2f uv(count ? u_sum / count : 0.5f, mesh->uvs[i].y());
      if (!pole_used[i]) {
        pole_used[i] = true;  // the first triangle keeps the original vertex
        mesh->uvs[i] = uv;
      } else {
        i = duplicate(i, uv);
      }
    }
  }
}

ir::Mesh make_sphere(int detail) {
  const Icosphere ico = make_icosphere(kFrequency[detail - 1]);
  ir::Mesh mesh;
  mesh.positions.reserve(ico.directions.size() * 11 / 10);
  mesh.normals.reserve(ico.directions.size() * 11 / 10);
  for (const Vector3d& d : ico.directions) {
    mesh.positions.push_back((0.5 * d).cast<float>());
    mesh.normals.push_back(d.cast<float>());
  }
  mesh.triangles = ico.triangles;
  add_spherical_uvs(ico.directions, &mesh);
  return mesh;
}

// The statue: a unit-sphere direction d is pushed out to radius R(d) (so the surface is
// star-shaped about the origin and cannot intersect itself), then the figure is stretched to
// twice its width in z and scaled to 1 m tall.
struct StatueShape {
  explicit StatueShape(std::uint32_t seed)
      : figure(1.2, 0.24, seed * 8 + 1),
        lumps(2.4, 0.10, seed * 8 + 2),
        ridges(4.3, 0.07, seed * 8 + 3),
        details{Octave(9.1, 0.030, seed * 8 + 4), Octave(19.3, 0.015, seed * 8 + 5),
                Octave(41.0, 0.008, seed * 8 + 6), Octave(87.0, 0.004, seed * 8 + 7)} {}

  double radius(const Vector3d& d) const {
    // Noise is sampled where the point will be after the vertical stretch, so bumps stay round.
    const Vector3d q(d.x(), d.y(), 2.0 * d.z());
    double r = 1.0 + figure.amplitude * figure(q) + lumps.amplitude * lumps(q);
    r += ridges.amplitude * (0.5 - std::abs(ridges(q)));      // sharp creases, rock-like
    for (const Octave& o : details) r += o.amplitude * o(q);  // bumps at several scales
    // A narrower "neck" below a head-like top (a polynomial bump: no libm, same everywhere).
    const double neck = (d.z() - 0.6) / 0.35;
    if (std::abs(neck) < 1.0) {
      const double b = 1.0 - neck * neck;
      r *= 1.0 - 0.2 * b * b * b;
    }
    r = std::max(r, 0.3);
    // A flat base to stand on.
    constexpr double kBase = 0.9;
    if (d.z() < 0 && r * -d.z() > kBase) r = kBase / -d.z();
    return r;
  }

  Octave figure, lumps, ridges;
  std::array<Octave, 4> details;
};

ir::Mesh make_statue(int detail, std::uint32_t seed) {
  const Icosphere ico = make_icosphere(kFrequency[detail - 1]);
  const std::size_t n = ico.directions.size();
  const StatueShape shape(seed);
  ir::Mesh mesh;
  mesh.positions.reserve(n * 11 / 10);
  mesh.positions.resize(n);
  auto displace = [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vector3d& d = ico.directions[i];
      const double r = shape.radius(d);
      mesh.positions[i] =
          Vector3f(static_cast<float>(0.5 * r * d.x()), static_cast<float>(0.5 * r * d.y()),
                   static_cast<float>(r * d.z()));
    }
  };
  // The noise is most of the time; big meshes use a second thread (each vertex is independent,
  // so the result does not depend on the split).
  if (n > 200000 && std::thread::hardware_concurrency() > 1) {
    std::thread helper(displace, n / 2, n);
    displace(0, n / 2);
    helper.join();
  } else {
    displace(0, n);
  }
  // Centre the bounds on the origin and scale to exactly 1 m tall.
  Vector3f lo = mesh.positions[0], hi = mesh.positions[0];
  for (const Vector3f& p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Vector3f centre = 0.5f * (lo + hi);
  const float scale = 1.0f / (hi.z() - lo.z());
  for (Vector3f& p : mesh.positions) p = (p - centre) * scale;
  mesh.triangles = ico.triangles;
  mesh.normals = vertex_normals(mesh.positions, mesh.triangles);
  mesh.normals.reserve(n * 11 / 10);
  add_spherical_uvs(ico.directions, &mesh);
  return mesh;
}

ir::Mesh make_box() {
  ir::Mesh mesh;
  // Each face: outward normal, and the directions of +u and +v on it (v runs down the image).
  struct Face {
    Vector3f n, u, v;
  };
  const std::array<Face, 6> faces = {{
      {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}},
      {{-1, 0, 0}, {0, -1, 0}, {0, 0, -1}},
      {{0, 1, 0}, {-1, 0, 0}, {0, 0, -1}},
      {{0, -1, 0}, {1, 0, 0}, {0, 0, -1}},
      {{0, 0, 1}, {1, 0, 0}, {0, -1, 0}},
      {{0, 0, -1}, {1, 0, 0}, {0, 1, 0}},
  }};
  for (const Face& f : faces) {
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int k = 0; k < 4; ++k) {
      const float su = (k == 1 || k == 2) ? 1.0f : 0.0f;
      const float sv = (k >= 2) ? 1.0f : 0.0f;
      mesh.positions.push_back(0.5f * f.n + (su - 0.5f) * f.u + (sv - 0.5f) * f.v);
      mesh.normals.push_back(f.n);
      mesh.uvs.emplace_back(su, sv);
    }
    // The normal of triangle (0, 1, 2) is u x v: keep it when that points outward.
    if (f.u.cross(f.v).dot(f.n) > 0) {
      mesh.triangles.push_back({base, base + 1, base + 2});
      mesh.triangles.push_back({base, base + 2, base + 3});
    } else {
      mesh.triangles.push_back({base, base + 2, base + 1});
      mesh.triangles.push_back({base, base + 3, base + 2});
    }
  }
  return mesh;
}

ir::Mesh make_cylinder(int detail) {
  const int n = kFrequency[detail - 1];
  const int segments = std::max(12, 4 * n);
  const int rows = std::max(1, n);
  ir::Mesh mesh;
  const float radius = 0.5f;
  // Side: (segments + 1) columns (the seam column is duplicated for u = 1) by (rows + 1) rings.
  for (int r = 0; r <= rows; ++r) {
    const float v = static_cast<float>(r) / rows;
    const float z = 0.5f - v;
    for (int s = 0; s <= segments; ++s) {
      const double a = 2.0 * kPi * (s % segments) / segments;
      const Vector3f dir(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a)), 0);
      mesh.positions.push_back(radius * dir + Vector3f(0, 0, z));
      mesh.normals.push_back(dir);
      mesh.uvs.emplace_back(static_cast<float>(s) / segments, v);
    }
  }
  const auto cols = static_cast<std::uint32_t>(segments + 1);
  for (int r = 0; r < rows; ++r) {
    for (int s = 0; s < segments; ++s) {
      const auto a = static_cast<std::uint32_t>(r * cols + s);
      const std::uint32_t b = a + 1, c = a + cols, d = a + cols + 1;
      // Ring r is above ring r + 1; counter-clockwise seen from outside.
      mesh.triangles.push_back({a, c, d});
      mesh.triangles.push_back({a, d, b});
    }
  }
  // Caps: a centre vertex and a ring with the cap's normal; planar uvs.
  for (int cap = 0; cap < 2; ++cap) {
    const float z = cap == 0 ? 0.5f : -0.5f;
    const Vector3f normal(0, 0, cap == 0 ? 1.0f : -1.0f);
    const auto centre = static_cast<std::uint32_t>(mesh.positions.size());
    mesh.positions.emplace_back(0, 0, z);
    mesh.normals.push_back(normal);
    mesh.uvs.emplace_back(0.5f, 0.5f);
    for (int s = 0; s < segments; ++s) {
      const double a = 2.0 * kPi * s / segments;
      const float x = radius * static_cast<float>(std::cos(a));
      const float y = radius * static_cast<float>(std::sin(a));
      mesh.positions.emplace_back(x, y, z);
      mesh.normals.push_back(normal);
      mesh.uvs.emplace_back(0.5f + x, cap == 0 ? 0.5f - y : 0.5f + y);
    }
    for (int s = 0; s < segments; ++s) {
      const std::uint32_t p = centre + 1 + s;
      const std::uint32_t q = centre + 1 + (s + 1) % segments;
      if (cap == 0) {
        mesh.triangles.push_back({centre, p, q});
      } else {
        mesh.triangles.push_back({centre, q, p});
      }
    }
  }
  return mesh;
}

}  // namespace

std::optional<PrimitiveKind> primitive_from_name(const std::string& name) {
  if (name == "sphere") return PrimitiveKind::kSphere;
  if (name == "box") return PrimitiveKind::kBox;
  if (name == "cylinder") return PrimitiveKind::kCylinder;
  if (name == "statue") return PrimitiveKind::kStatue;
  return std::nullopt;
}

std::vector<std::string> primitive_names() {
  return {"sphere", "box", "cylinder", "statue"};
}

ir::Mesh make_primitive(PrimitiveKind kind, int detail, std::uint32_t seed) {
  detail = clamp_detail(detail);
  ir::Mesh mesh;
  switch (kind) {
    case PrimitiveKind::kSphere:
      mesh = make_sphere(detail);
      break;
    case PrimitiveKind::kBox:
      mesh = make_box();
      break;
    case PrimitiveKind::kCylinder:
      mesh = make_cylinder(detail);
      break;
    case PrimitiveKind::kStatue:
      mesh = make_statue(detail, seed);
      break;
  }
  mesh.triangle_material.assign(mesh.triangles.size(), 0);
  return mesh;
}

}  // namespace rigc
