#include "analysis/coverage_output.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "dslr/image_io.h"
#include "dslr/lens.h"
#include "io/atomic_file.h"
#include "io/files.h"
#include "io/output_paths.h"
#include "raster/rasterizer.h"

namespace rigc::analysis {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3f;

std::uint8_t to_srgb8(float linear) {
  linear = std::clamp(linear, 0.0f, 1.0f);
  const float encoded =
      linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1 / 2.4f) - 0.055f;
  return static_cast<std::uint8_t>(std::lround(encoded * 255));
}

// Binary PLY with one colour per face (CloudCompare and MeshLab read face colours). With
// `coverage`, each face also carries its prediction as scalar fields: the shots that see it, of
// those the ones SfM can use, and whether it is reconstructable (for a user's viewer; the
// calibration bench computes them from the scene itself).
bool write_face_color_ply(const fs::path& path, const scene::Geometry& mesh,
                          const std::vector<Vector3f>& colors, const CoverageResult* coverage,
                          std::string* error) {
  std::string data = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment RigC coverage\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\nelement face {}\n"
      "property list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\n{}end_header\n",
      mesh.positions.size(), mesh.triangles.size(),
      coverage ? "property ushort views\nproperty ushort usable_views\n"
                 "property uchar reconstructable\n"
               : "");
  auto append = [&](const void* bytes, size_t size) {
    data.append(static_cast<const char*>(bytes), size);
  };
  for (const auto& p : mesh.positions) append(p.data(), 3 * sizeof(float));
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const std::uint8_t count = 3;
    append(&count, 1);
    for (const std::uint32_t index : mesh.triangles[f]) {
      const std::int32_t i = static_cast<std::int32_t>(index);
      append(&i, 4);
    }
    const std::uint8_t rgb[3] = {to_srgb8(colors[f].x()), to_srgb8(colors[f].y()),
                                 to_srgb8(colors[f].z())};
    append(rgb, 3);
    if (coverage) {
      append(&coverage->views[f], sizeof(std::uint16_t));
      append(&coverage->usable_views[f], sizeof(std::uint16_t));
      append(&coverage->reconstructable[f], 1);
    }
  }
  return rigc::write_file_atomically(path, data, error);
}

// The faces unwelded so that each carries its own colour: three vertices per face, glTF axes.
struct UnweldedFaces {
  size_t vertex_count = 0;
  std::vector<float> positions, normals, colors;                             // 3 floats per vertex
  Vector3f lo = Vector3f::Constant(1e30f), hi = Vector3f::Constant(-1e30f);  // of the positions
};

UnweldedFaces unweld_faces(const scene::Geometry& mesh, const std::vector<Vector3f>& colors) {
  const size_t vertex_count = mesh.triangles.size() * 3;
  std::vector<float> positions, normals, vertex_colors;
  positions.reserve(vertex_count * 3);
  normals.reserve(vertex_count * 3);
  vertex_colors.reserve(vertex_count * 3);
  Vector3f lo = Vector3f::Constant(1e30f), hi = Vector3f::Constant(-1e30f);
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Vector3f n = (mesh.positions[t[1]] - mesh.positions[t[0]])
                           .cross(mesh.positions[t[2]] - mesh.positions[t[0]])
                           .normalized();
    for (int k = 0; k < 3; ++k) {
      // RigC is +Z up; glTF is +Y up: (x, y, z) -> (x, z, -y).
      const Vector3f& p = mesh.positions[t[k]];
      const Vector3f gp(p.x(), p.z(), -p.y());
      lo = lo.cwiseMin(gp);
      hi = hi.cwiseMax(gp);
      positions.insert(positions.end(), {gp.x(), gp.y(), gp.z()});
      const Vector3f gn = std::isfinite(n.x()) ? Vector3f(n.x(), n.z(), -n.y()) : Vector3f(0, 1, 0);
      normals.insert(normals.end(), {gn.x(), gn.y(), gn.z()});
      vertex_colors.insert(vertex_colors.end(), {colors[f].x(), colors[f].y(), colors[f].z()});
    }
  }
  return {vertex_count, std::move(positions), std::move(normals), std::move(vertex_colors), lo, hi};
}

// Appends `values` (3 floats per vertex) to the model's one buffer as a view and an accessor;
// returns the accessor's index.
int add_vec3_accessor(tinygltf::Model& model, tinygltf::Buffer& buffer,
                      const std::vector<float>& values, size_t vertex_count) {
  const size_t offset = buffer.data.size();
  const auto* bytes = reinterpret_cast<const unsigned char*>(values.data());
  buffer.data.insert(buffer.data.end(), bytes, bytes + values.size() * sizeof(float));
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = values.size() * sizeof(float);
  view.target = TINYGLTF_TARGET_ARRAY_BUFFER;
  model.bufferViews.push_back(view);
  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.count = vertex_count;
  accessor.type = TINYGLTF_TYPE_VEC3;
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size()) - 1;
}

// A glTF model of one mesh with per-vertex colours (COLOR_0, linear) and a matte material.
tinygltf::Model face_color_model(const UnweldedFaces& faces) {
  tinygltf::Model model;
  tinygltf::Buffer buffer;
  const int position_accessor =
      add_vec3_accessor(model, buffer, faces.positions, faces.vertex_count);
  model.accessors[position_accessor].minValues = {faces.lo.x(), faces.lo.y(), faces.lo.z()};
  model.accessors[position_accessor].maxValues = {faces.hi.x(), faces.hi.y(), faces.hi.z()};
  const int normal_accessor = add_vec3_accessor(model, buffer, faces.normals, faces.vertex_count);
  const int color_accessor = add_vec3_accessor(model, buffer, faces.colors, faces.vertex_count);
  model.buffers.push_back(buffer);
  tinygltf::Material material;
  material.name = "coverage";
  material.pbrMetallicRoughness.metallicFactor = 0;
  material.pbrMetallicRoughness.roughnessFactor = 1;
  material.doubleSided = true;
  model.materials.push_back(material);
  tinygltf::Primitive primitive;
  primitive.attributes["POSITION"] = position_accessor;
  primitive.attributes["NORMAL"] = normal_accessor;
  primitive.attributes["COLOR_0"] = color_accessor;
  primitive.material = 0;
  primitive.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = "coverage";
  gltf_mesh.primitives.push_back(primitive);
  model.meshes.push_back(gltf_mesh);
  tinygltf::Node node;
  node.mesh = 0;
  model.nodes.push_back(node);
  tinygltf::Scene scene;
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
  model.asset.version = "2.0";
  model.asset.generator = "RigC coverage";
  return model;
}

// GLB with the faces unwelded so each carries its own vertex colour. Atomic.
bool write_face_color_glb(const fs::path& path, const scene::Geometry& mesh,
                          const std::vector<Vector3f>& colors, std::string* error) {
  tinygltf::Model model = face_color_model(unweld_faces(mesh, colors));
  // Encoded in memory, then written atomically: a write error is reported, never a short file.
  std::ostringstream bytes;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&model, bytes, false, true)) {
    *error = fmt::format("{}: cannot write the GLB", path.string());
    return false;
  }
  return rigc::write_file_atomically(path, bytes.str(), error);
}

bool write_png(const fs::path& path, const std::vector<float>& rgb, int width, int height,
               std::string* error) {
  std::vector<std::uint8_t> pixels(rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) pixels[i] = to_srgb8(rgb[i]);
  return dslr::write_pixels(path, OIIO::ImageSpec(width, height, 3, OIIO::TypeDesc::UINT8),
                            pixels.data(), error);
}

// A camera orbiting the object at `azimuth`/`elevation` (radians), framing it whole.
ir::Mat4 picture_camera(const ir::Scene& scene, const scene::StudioScene& studio, double azimuth,
                        double elevation, double horizontal_fov) {
  const ir::Vec3 center =
      (ir::world_from_object(scene, 0) * studio.object_center.homogeneous()).head<3>();
  const double distance = studio.object_radius / std::sin(horizontal_fov / 2 * 0.6);
  const ir::Vec3 eye =
      center + distance * ir::Vec3(std::cos(elevation) * std::cos(azimuth),
                                   std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  const ir::Vec3 forward = (center - eye).normalized();
  const ir::Vec3 right = forward.cross(ir::Vec3::UnitZ()).normalized();
  ir::Mat4 m = ir::Mat4::Identity();
  m.block<3, 1>(0, 0) = right;
  m.block<3, 1>(0, 1) = forward.cross(right);
  m.block<3, 1>(0, 2) = forward;
  m.block<3, 1>(0, 3) = eye;
  return m;
}

// Each face's colour in the two colourings: paper colours and the heat map by view count.
struct FaceColors {
  std::vector<Vector3f> paper, heat;
};

FaceColors face_colors(const CoverageResult& coverage) {
  const size_t faces = coverage.views.size();
  int max_views = 1;
  for (auto v : coverage.views) max_views = std::max<int>(max_views, v);
  FaceColors colors{std::vector<Vector3f>(faces), std::vector<Vector3f>(faces)};
  for (size_t f = 0; f < faces; ++f) {
    colors.paper[f] = paper_color(coverage.views[f]);
    colors.heat[f] = heat_color(coverage.views[f], max_views);
  }
  return colors;
}

// coverage.ply/.glb in paper colours (the PLY with each face's prediction), views.ply/.glb as the
// heat map.
bool write_coverage_meshes(const fs::path& dir, const scene::Geometry& mesh,
                           const CoverageResult& coverage, const FaceColors& colors,
                           std::string* error) {
  return write_face_color_ply(dir / "coverage.ply", mesh, colors.paper, &coverage, error) &&
         write_face_color_glb(dir / "coverage.glb", mesh, colors.paper, error) &&
         write_face_color_ply(dir / "views.ply", mesh, colors.heat, nullptr, error) &&
         write_face_color_glb(dir / "views.glb", mesh, colors.heat, error);
}

// The pictures' canvas: 3:2, the camera's horizontal field of view.
struct PictureFrame {
  PictureFrame(const ir::Scene& scene, int picture_width)
      : fov(2 * std::atan(0.5 * scene.camera.sensor_width_m / scene.camera.focal_length_m)),
        width(picture_width),
        height(picture_width * 2 / 3) {
    request.canvas = {
        width,       height,      width / (2 * std::tan(fov / 2)), width / (2 * std::tan(fov / 2)),
        width / 2.0, height / 2.0};
  }
  double fov;
  int width, height;
  raster::FrameRequest request;  // turntable angle 0: the object on its own
};

// The object in paper colours from four sides, from above and from below.
bool write_view_pictures(const fs::path& dir, const ir::Scene& scene,
                         const scene::StudioScene& studio, const PictureFrame& frame,
                         const std::vector<Vector3f>& paper, std::string* error) {
  struct View {
    const char* name;
    double azimuth_deg, elevation_deg;
  };
  const View views[] = {{"front", -90, 20}, {"right", 0, 20}, {"back", 90, 20},
                        {"left", 180, 20},  {"top", -90, 75}, {"below", -90, -30}};
  raster::FrameRequest request = frame.request;
  for (const auto& view : views) {
    request.world_from_camera = picture_camera(scene, studio, view.azimuth_deg * M_PI / 180,
                                               view.elevation_deg * M_PI / 180, frame.fov);
    const auto rgb = raster::render_face_colors(scene, studio, request, paper);
    if (!write_png(dir / fmt::format("view_{}.png", view.name), rgb, frame.width, frame.height,
                   error)) {
      return false;
    }
  }
  return true;
}

// Coverage growing shot by shot (paper colours of the views so far), from a fixed
// three-quarter view.
bool write_progress_pictures(const fs::path& dir, const ir::Scene& scene,
                             const scene::StudioScene& studio, const CoverageResult& coverage,
                             const PictureFrame& frame, std::string* error) {
  raster::FrameRequest request = frame.request;
  request.world_from_camera =
      picture_camera(scene, studio, -60 * M_PI / 180, 25 * M_PI / 180, frame.fov);
  const size_t faces = coverage.views.size();
  for (size_t s = 0; s < coverage.shots.size(); ++s) {
    std::vector<Vector3f> colors(faces);
    for (size_t f = 0; f < faces; ++f) {
      const int views_so_far = (coverage.first_seen[f] <= s) + (coverage.second_seen[f] <= s);
      colors[f] = paper_color(views_so_far);
    }
    const auto rgb = raster::render_face_colors(scene, studio, request, colors);
    if (!write_png(dir / fmt::format("after_{}.png", scene.shots[s].name), rgb, frame.width,
                   frame.height, error)) {
      return false;
    }
  }
  return true;
}

nlohmann::json summary_json(const CoverageResult& coverage) {
  const auto& last = coverage.shots.empty() ? ShotCoverage{} : coverage.shots.back();
  double reconstructable_area = 0, resting_area = 0;
  for (size_t f = 0; f < coverage.views.size(); ++f) {
    if (coverage.reconstructable[f]) reconstructable_area += coverage.face_area_m2[f];
    if (coverage.resting[f]) resting_area += coverage.face_area_m2[f];
  }
  return {{"seen_by_1_or_more", last.seen_1},
          {"seen_by_2_or_more", last.seen_2},
          {"seen_by_3_or_more", last.seen_3},
          {"reconstructable", reconstructable_area / coverage.total_area_m2},
          {"resting_on_turntable", resting_area / coverage.total_area_m2},
          {"blur_ratio_95", coverage.blur_ratio_95}};
}

nlohmann::json thresholds_json(const ir::CoverageSettings& settings) {
  return {{"min_pixels_per_mm2", settings.min_pixels_per_mm2},
          {"max_view_angle_deg", settings.max_view_angle_rad * 180 / M_PI},
          {"max_blur_px", settings.max_blur_px},
          {"min_triangulation_angle_deg", settings.min_triangulation_angle_rad * 180 / M_PI},
          {"min_signal", settings.min_signal},
          {"max_signal", settings.max_signal}};
}

nlohmann::json shot_json(const ir::Scene& scene, const CoverageResult& coverage,
                         const ShotCoverage& shot) {
  return {{"shot", scene.shots[shot.shot].name},
          {"visible_area_share", shot.visible_area_m2 / coverage.total_area_m2},
          {"new_area_share", shot.new_area_m2 / coverage.total_area_m2},
          {"overlap_with_previous", shot.overlap_with_previous},
          {"cumulative",
           {{"seen_1", shot.seen_1},
            {"seen_2", shot.seen_2},
            {"seen_3", shot.seen_3},
            {"reconstructable", shot.reconstructable}}},
          {"unusable_shares",
           {{"out_of_focus", shot.out_of_focus},
            {"clipped", shot.clipped},
            {"too_dark", shot.too_dark},
            {"too_oblique", shot.too_oblique},
            {"too_coarse", shot.too_coarse}}},
          {"frame_fill", shot.frame_fill}};
}

// coverage.json: the summary, the thresholds the tests used, and per shot its shares.
nlohmann::json coverage_json(const ir::Scene& scene, const CoverageResult& coverage) {
  nlohmann::json json;
  json["scene"] = scene.name;
  json["total_area_m2"] = coverage.total_area_m2;
  json["faces"] = coverage.views.size();
  json["summary"] = summary_json(coverage);
  json["thresholds"] = thresholds_json(scene.coverage);
  nlohmann::json shots = nlohmann::json::array();
  for (const auto& shot : coverage.shots) shots.push_back(shot_json(scene, coverage, shot));
  json["shots"] = shots;
  return json;
}

}  // namespace

Vector3f paper_color(int views) {
  if (views <= 0) return {1, 1, 1};
  if (views == 1) return {0.85f, 0.05f, 0.05f};
  return {0.05f, 0.7f, 0.1f};
}

Vector3f heat_color(int views, int max_views) {
  if (views <= 0) return {1, 1, 1};
  const float t = std::clamp((views - 1.0f) / std::max(1, max_views - 1), 0.0f, 1.0f);
  // Blue -> cyan -> yellow -> red.
  const Vector3f stops[4] = {
      {0.05f, 0.1f, 0.8f}, {0.05f, 0.7f, 0.8f}, {0.95f, 0.85f, 0.1f}, {0.85f, 0.05f, 0.05f}};
  const float x = t * 3;
  const int i = std::min(2, static_cast<int>(x));
  return stops[i] + (stops[i + 1] - stops[i]) * (x - i);
}

bool write_coverage_outputs(const ir::Scene& scene, const scene::StudioScene& studio,
                            const CoverageResult& coverage, const fs::path& dir, int picture_width,
                            std::string* error) {
  std::error_code ec;
  fs::create_directories(dir / "pictures", ec);
  if (ec) {
    *error = fmt::format("cannot create '{}': {}", (dir / "pictures").string(), ec.message());
    return false;
  }
  remove_abandoned_temporaries(dir);  // an interrupted run's half-written meshes and pictures
  remove_abandoned_temporaries(dir / "pictures");
  const FaceColors colors = face_colors(coverage);
  const PictureFrame frame(scene, picture_width);
  return write_coverage_meshes(dir, studio.object, coverage, colors, error) &&
         write_view_pictures(dir / "pictures", scene, studio, frame, colors.paper, error) &&
         write_progress_pictures(dir / "pictures", scene, studio, coverage, frame, error) &&
         rigc::write_file_atomically(dir / "coverage.json",
                                     coverage_json(scene, coverage).dump(2) + "\n", error);
}

void print_coverage_table(const ir::Scene& scene, const CoverageResult& coverage,
                          std::ostream& out) {
  out << fmt::format("{:<10} {:>7} {:>8} {:>7} {:>7} {:>7} {:>8} {:>8}\n", "shot", "new %",
                     "overlap", ">=1 %", ">=2 %", ">=3 %", "recon %", "fill %");
  for (const auto& shot : coverage.shots) {
    out << fmt::format("{:<10} {:>7.1f} {:>8.0f} {:>7.1f} {:>7.1f} {:>7.1f} {:>8.1f} {:>8.1f}\n",
                       scene.shots[shot.shot].name, 100 * shot.new_area_m2 / coverage.total_area_m2,
                       100 * shot.overlap_with_previous, 100 * shot.seen_1, 100 * shot.seen_2,
                       100 * shot.seen_3, 100 * shot.reconstructable, 100 * shot.frame_fill);
  }
}

}  // namespace rigc::analysis
