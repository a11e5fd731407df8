#include "eval/reconstruction.h"

#include <fmt/format.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/io/PointCloudIO.h>
#include <open3d/io/TriangleMeshIO.h>
#include <open3d/utility/Logging.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "assets/mesh_io.h"
#include "eval/align.h"
#include "eval/camera_files.h"
#include "eval/colmap.h"
#include "eval/measure.h"
#include "eval/reconstruction_headers.h"

namespace rigc::eval {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// Open3D's vertices (or points) into `g`, leaving out non-finite ones; a mesh keeps its vertex
// indices, so a non-finite vertex there is an error instead.
bool take_points(const std::vector<Eigen::Vector3d>& in, ReconstructionGeometry& g) {
  g.points.reserve(in.size());
  for (const auto& p : in) {
    if (p.allFinite()) {
      g.points.push_back(p);
    } else {
      ++g.dropped;
    }
  }
  return !g.points.empty();
}

bool take_mesh(const open3d::geometry::TriangleMesh& mesh, ReconstructionGeometry& g,
               std::string* error) {
  const int n = static_cast<int>(mesh.vertices_.size());
  for (const auto& v : mesh.vertices_) {
    if (!v.allFinite()) {
      *error = "a vertex has a coordinate that is not a finite number";
      return false;
    }
    g.positions.push_back(v.cast<float>());
  }
  for (const auto& t : mesh.triangles_) {
    if ((t.array() < 0).any() || (t.array() >= n).any()) {
      *error = "a face names a vertex the file does not have";
      return false;
    }
    g.triangles.push_back({std::uint32_t(t(0)), std::uint32_t(t(1)), std::uint32_t(t(2))});
  }
  g.has_colors = mesh.HasVertexColors();
  g.has_normals = mesh.HasVertexNormals();
  return true;
}

// False with `error` when every triangle of a mesh is a line or a point: there is no surface to
// sample, which Open3D reports only as an exception.
bool mesh_has_area(const ReconstructionGeometry& g, std::string* error) {
  double area = 0;
  for (const auto& t : g.triangles) {
    area += (g.positions[t[1]] - g.positions[t[0]])
                .cast<double>()
                .cross((g.positions[t[2]] - g.positions[t[0]]).cast<double>())
                .norm();
  }
  if (area > 0) return true;
  *error = fmt::format("its {} faces have no area (every triangle is a line or a point)",
                       g.triangles.size());
  return false;
}

// glTF / GLB: RigC's loader, in the same axes as a ground truth from a glTF.
bool load_gltf(const fs::path& path, ReconstructionGeometry& g, std::string* error) {
  auto model = load_model(path.string(), error);
  if (!model) return false;
  g.positions = std::move(model->mesh.positions);
  g.triangles = std::move(model->mesh.triangles);
  g.has_normals = !model->mesh.normals.empty();
  return true;
}

// The layout of a binary little-endian PLY cloud: its only non-empty element is `vertex`, of
// scalar properties with float or double x, y, z.
struct PlyCloudLayout {
  std::size_t count = 0, stride = 0;
  std::array<std::size_t, 3> offset{};
  std::array<bool, 3> is_double{};
  bool colors = false, normals = false;
};

std::optional<PlyCloudLayout> ply_cloud_layout(std::istream& in) {
  std::string line, word;
  std::getline(in, line);
  if (line != "ply") return std::nullopt;
  PlyCloudLayout layout;
  std::string element;
  std::array<bool, 3> found{};
  bool binary_le = false;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    words >> word;
    if (word == "format") {
      words >> word;
      binary_le = word == "binary_little_endian";
    } else if (word == "element") {
      long count = -1;
      words >> element >> count;
      if (count < 0) return std::nullopt;
      if (element == "vertex") {
        layout.count = static_cast<std::size_t>(count);
      } else if (count > 0) {
        return std::nullopt;  // faces, or data before or after the vertices
      }
    } else if (word == "property" && element == "vertex") {
      std::string type, name;
      words >> type >> name;
      const int size = ply_type_bytes(type);
      if (size == 0) return std::nullopt;  // a list
      const int axis = name == "x" ? 0 : name == "y" ? 1 : name == "z" ? 2 : -1;
      if (axis >= 0) {
        if (size != 4 && size != 8) return std::nullopt;
        if (size == 4 && type != "float" && type != "float32") return std::nullopt;
        found[axis] = true;
        layout.offset[axis] = layout.stride;
        layout.is_double[axis] = size == 8;
      }
      layout.colors = layout.colors || name == "red" || name == "r";
      layout.normals = layout.normals || name == "nx";
      layout.stride += size;
    }
  }
  if (!binary_le || line != "end_header" || !found[0] || !found[1] || !found[2]) {
    return std::nullopt;
  }
  return layout;
}

// The point of one binary PLY vertex record.
Vec3 ply_record_point(const char* record, const PlyCloudLayout& layout) {
  Vec3 p;
  for (int axis = 0; axis < 3; ++axis) {
    if (layout.is_double[axis]) {
      std::memcpy(&p[axis], record + layout.offset[axis], sizeof(double));
    } else {
      float f;
      std::memcpy(&f, record + layout.offset[axis], sizeof(float));
      p[axis] = f;
    }
  }
  return p;
}

// Binary little-endian PLY clouds read straight from the file, in chunks converted in parallel
// (Open3D's reader calls back once per value, several times slower). nullopt for any other PLY
// (then Open3D reads it); false with `error` for a file cut short.
std::optional<bool> read_binary_ply_cloud(const fs::path& path, ReconstructionGeometry& g,
                                          std::string* error) {
  if constexpr (std::endian::native != std::endian::little) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  const auto layout = ply_cloud_layout(in);
  if (!layout || layout->count == 0) return std::nullopt;
  // load_reconstruction has held the header's count to the file's size (header_overclaims); a
  // file cut short since is found by the reads.
  const std::size_t chunk = std::max<std::size_t>(1, (8 << 20) / layout->stride);
  std::vector<char> data(std::min(layout->count, chunk) * layout->stride);
  g.points.resize(layout->count);
  for (std::size_t first = 0; first < layout->count; first += chunk) {
    const std::size_t n = std::min(chunk, layout->count - first);
    if (!in.read(data.data(), static_cast<std::streamsize>(n * layout->stride))) {
      *error = fmt::format("holds fewer than the {} points its header announces", layout->count);
      g.points.clear();
      return false;
    }
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1 << 14),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        for (std::size_t i = range.begin(); i < range.end(); ++i) {
                          g.points[first + i] =
                              ply_record_point(data.data() + i * layout->stride, *layout);
                        }
                      });
  }
  const auto finite_end = std::remove_if(g.points.begin(), g.points.end(),
                                         [](const Vec3& p) { return !p.allFinite(); });
  g.dropped = static_cast<std::size_t>(g.points.end() - finite_end);
  g.points.erase(finite_end, g.points.end());
  g.has_colors = layout->colors;
  g.has_normals = layout->normals;
  if (g.points.empty()) *error = "holds no finite point";
  return !g.points.empty();
}

bool load_with_open3d(const fs::path& path, const std::string& ext, ReconstructionGeometry& g,
                      std::string* error) {
  if (ext == ".ply") {
    if (const auto read = read_binary_ply_cloud(path, g, error)) return *read;
  }
  open3d::geometry::TriangleMesh mesh;
  open3d::io::ReadTriangleMeshOptions options;
  options.enable_post_processing = false;
  options.print_progress = false;
  const bool cloud_only_format = ext == ".pcd" || ext == ".xyz" || ext == ".pts";
  if (!cloud_only_format && open3d::io::ReadTriangleMesh(path.string(), mesh, options) &&
      !mesh.triangles_.empty()) {
    return take_mesh(mesh, g, error);
  }
  if (!cloud_only_format && ext != ".ply") {
    // OBJ or STL without faces: its vertices are the cloud.
    g.has_colors = mesh.HasVertexColors();
    g.has_normals = mesh.HasVertexNormals();
    if (take_points(mesh.vertices_, g)) return true;
    *error = "holds no faces and no finite vertex";
    return false;
  }
  open3d::geometry::PointCloud cloud;
  open3d::io::ReadPointCloudOption cloud_options;
  cloud_options.remove_nan_points = false;
  cloud_options.remove_infinite_points = false;
  if (!open3d::io::ReadPointCloud(path.string(), cloud, cloud_options)) {
    *error = "cannot be read as a mesh or a point cloud";
    return false;
  }
  g.has_colors = cloud.HasColors();
  g.has_normals = cloud.HasNormals();
  if (take_points(cloud.points_, g)) return true;
  *error = "holds no finite point";
  return false;
}

}  // namespace

std::optional<ReconstructionGeometry> load_reconstruction(const fs::path& path,
                                                          std::string* error) {
  open3d::utility::SetVerbosityLevel(open3d::utility::VerbosityLevel::Error);
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    *error = fmt::format("{} is not a file", path.string());
    return std::nullopt;
  }
  const std::string ext = lower_extension(path);
  static const std::set<std::string> known = {".ply", ".obj", ".stl", ".gltf",
                                              ".glb", ".pcd", ".xyz", ".pts"};
  if (!known.count(ext)) {
    *error = fmt::format(
        "{}: unknown reconstruction format '{}' (PLY, OBJ, STL, glTF/GLB; clouds also PCD, XYZ, "
        "PTS)",
        path.string(), ext);
    return std::nullopt;
  }
  if (const std::string why = header_overclaims(path, ext); !why.empty()) {
    *error = fmt::format("{}: {}", path.string(), why);
    return std::nullopt;
  }
  ReconstructionGeometry g;
  std::string why;
  bool ok = false;
  try {
    ok = ((ext == ".gltf" || ext == ".glb") ? load_gltf(path, g, &why)
                                            : load_with_open3d(path, ext, g, &why)) &&
         (!g.is_mesh() || mesh_has_area(g, &why));
  } catch (const std::bad_alloc&) {
    // What the header checks cannot see: counts inside the data (a face list's length).
    why = "claims more data than memory can hold (a count in it past what it holds)";
  }
  if (!ok) {
    *error = why.starts_with(path.string()) ? why : fmt::format("{}: {}", path.string(), why);
    return std::nullopt;
  }
  return g;
}

namespace {

// One evaluation of a reconstruction file; run() takes its steps.
class ReconstructionEval {
 public:
  ReconstructionEval(const EvalOptions& o, const EvalInputs& in, EvalReport& report,
                     std::ostream& log, EvalSummary& sum)
      : o_(o), in_(in), report_(report), log_(log), sum_(sum) {}

  int run(Clock::time_point start) {
    const double setup_s = seconds_since(start);
    const auto t_load = Clock::now();
    if (int code = load()) return code;
    if (int code = load_cameras()) return code;
    const double load_s = seconds_since(t_load);
    const auto t_metrics = Clock::now();
    const Surface surface(in_.truth.positions, in_.truth.triangles);
    const Alignment alignment =
        align_to_ground_truth(o_, model_, in_.truth, surface, method(), &points_);
    if (!alignment.ok) return report_.fail("alignment", alignment.failure, 2);
    report_.sections()["alignment"] = alignment.report;
    if (int code = check_fitness(alignment)) return code;
    const Measurements m = measure(o_, model_, in_.truth, surface, alignment, in_.out,
                                   report_.sections(), mesh_.get());
    sum_.mean_mm = m.stats.mean;
    sum_.std_mm = m.stats.stddev;
    sum_.fscore = m.f.fscore;
    const double metrics_s = seconds_since(t_metrics);
    const auto t_files = Clock::now();
    report_.write_pictures(o_, surface, alignment, m);
    const double files_s = seconds_since(t_files);
    sum_.rigc_s = seconds_since(start);
    report_.sections()["timing_s"] = {{"rigc_ground_truth", setup_s},
                                      {"load_reconstruction", load_s},
                                      {"rigc_alignment_and_metrics", metrics_s},
                                      {"files", files_s},
                                      {"total", sum_.rigc_s}};
    if (!report_.write()) return 2;
    if (o_.quiet) return 0;
    report_.print_measurements(o_, m);
    log_ << fmt::format(
        "rigc eval: {:.1f} s in all (ground truth {:.1f}, reading {:.1f}, alignment and metrics "
        "{:.1f}, files {:.1f})\n",
        sum_.rigc_s, setup_s, load_s, metrics_s, files_s);
    report_.print_written();
    return 0;
  }

 private:
  AlignMethod method() const {
    if (!o_.imported.align) return AlignMethod::kNone;
    return o_.imported.cameras.empty() ? AlignMethod::kRegistration : AlignMethod::kCameras;
  }

  // The file, as points: a cloud's own, or a mesh's dense samples.
  int load() {
    std::string error;
    auto g = load_reconstruction(o_.imported.reconstruction, &error);
    if (!g) return report_.fail("reconstruction", error, 1);
    json section = {{"status", "ok"},
                    {"file", o_.imported.reconstruction},
                    {"kind", g->is_mesh() ? "mesh" : "point cloud"},
                    {"colors", g->has_colors},
                    {"normals", g->has_normals}};
    std::vector<Vec3> points;
    if (g->is_mesh()) {
      mesh_ = std::make_unique<Surface>(g->positions, g->triangles);
      std::vector<Vec3> normals;
      mesh_->sample(o_.imported.mesh_samples, 13, &points, &normals);
      section["vertices"] = g->positions.size();
      section["triangles"] = g->triangles.size();
      section["samples"] = points.size();
      section["sampling"] = "area-uniform samples of the mesh (cloud-to-mesh on sampled points)";
    } else {
      points = std::move(g->points);
      section["points"] = points.size();
      section["non_finite_points_left_out"] = g->dropped;
    }
    if (o_.metrics.poisson) {
      section["poisson"] =
          g->is_mesh() ? "not applied: the file is a mesh already"
                       : "not applied: a file's points have no cameras to orient the normals by";
    }
    if (points.size() < 3) {
      return report_.fail("reconstruction",
                          fmt::format("{} has fewer than 3 points", o_.imported.reconstruction), 1);
    }
    points_ = std::move(points);
    sum_.reconstructed = true;
    sum_.points = static_cast<long>(points_.size());
    report_.sections()["reconstruction"] = section;
    if (!o_.quiet) {
      log_ << fmt::format("rigc eval: {}: {}\n", o_.imported.reconstruction,
                          g->is_mesh() ? fmt::format("mesh of {} triangles, {} samples",
                                                     g->triangles.size(), points_.size())
                                       : fmt::format("{} points", points_.size()));
    }
    return 0;
  }

  // --cameras: the tool's poses, whose centres are fitted to the ground-truth ones.
  int load_cameras() {
    if (o_.imported.cameras.empty()) return 0;
    if (in_.truth.poses.empty()) {
      return report_.fail(
          "reconstruction",
          fmt::format("--cameras aligns the tool's cameras to the ground-truth poses, and {} has "
                      "none (sparse/images.txt); give a run folder or leave --cameras out",
                      in_.run_dir.string()),
          1);
    }
    std::string error;
    auto cameras = read_camera_file(o_.imported.cameras, &error);
    if (!cameras) return report_.fail("reconstruction", error, 1);
    int matched = 0;
    for (const auto& im : cameras->images) matched += in_.truth.poses.count(im.name) > 0;
    model_.images = std::move(cameras->images);
    model_.cameras = std::move(cameras->cameras);
    sum_.registered = matched;
    report_.sections()["reconstruction"]["cameras"] = {{"file", o_.imported.cameras},
                                                       {"format", cameras->format},
                                                       {"images", model_.images.size()},
                                                       {"with_ground_truth_pose", matched}};
    if (!cameras->list.empty()) {
      report_.sections()["reconstruction"]["cameras"]["list"] = cameras->list.string();
    }
    if (!o_.quiet) {
      log_ << fmt::format("rigc eval: {} ({}): {} cameras, {} with a ground-truth pose\n",
                          o_.imported.cameras, cameras->format, model_.images.size(), matched);
    }
    return 0;
  }

  // A registration that fits poorly aligned the cloud wrongly, or the cloud is of another object:
  // its numbers would mean nothing.
  int check_fitness(const Alignment& a) {
    const std::string figures = fmt::format(
        "fitness {:.3f}: {:.1f} % of the points near the object lie within {:.2f} mm of the "
        "ground truth",
        a.fitness, 100 * a.fitness, 1000 * a.fitness_distance);
    if (a.fitness >= o_.imported.min_fitness) return 0;
    if (method() == AlignMethod::kRegistration) {
      return report_.fail(
          "alignment",
          fmt::format("the registration fits poorly ({}; at least {} is needed): is the "
                      "reconstruction of this object? Give its cameras with --cameras",
                      figures, o_.imported.min_fitness),
          2);
    }
    log_ << fmt::format("rigc eval: warning: the aligned reconstruction fits poorly ({})\n",
                        figures);
    return 0;
  }

  const EvalOptions& o_;
  const EvalInputs& in_;
  EvalReport& report_;
  std::ostream& log_;
  EvalSummary& sum_;
  SparseModel model_;              // the cameras (--cameras); no COLMAP points
  std::vector<Vec3> points_;       // the file's points, or its mesh's samples
  std::unique_ptr<Surface> mesh_;  // the reconstructed mesh, when the file is one
};

}  // namespace

int evaluate_reconstruction(const EvalOptions& options, const EvalInputs& inputs,
                            EvalReport& report, std::ostream& log, EvalSummary& summary,
                            Clock::time_point start) {
  return ReconstructionEval(options, inputs, report, log, summary).run(start);
}

}  // namespace rigc::eval
