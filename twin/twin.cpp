#include "twin/twin.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "assets/mesh_io.h"
#include "eval/align.h"
#include "eval/colmap.h"
#include "eval/eval.h"
#include "eval/inputs.h"
#include "eval/photo_masks.h"
#include "eval/pose_accuracy.h"
#include "io/atomic_file.h"
#include "twin/photo_colors.h"
#include "twin/ring_views.h"
#include "twin/scene_text.h"
#include "twin/twin_frame.h"
#include "twin/twin_render.h"
#include "twin/visual_hull.h"

namespace rigc::twin {

namespace fs = std::filesystem;
using nlohmann::json;
using Vec3 = Eigen::Vector3d;

namespace {

constexpr int kUserError = 1;
constexpr int kToolError = 2;
// Pixels the silhouettes are grown by before carving (twin/visual_hull.h).
constexpr int kHullGrowPx = 1;

bool check_options(const TwinOptions& o, std::string* error) {
  if (o.photos_dir.empty() || o.output_dir.empty()) {
    *error = "give the photos' folder and -o DIR";
  } else if (o.resolution < 16 || o.resolution > 512) {
    *error = fmt::format("--resolution {} is outside 16 .. 512 voxels", o.resolution);
  } else if (o.max_misses < 0 || o.max_misses > 8) {
    *error = fmt::format("--max-misses {} is outside 0 .. 8 silhouettes", o.max_misses);
  } else if (o.object_height_m && !(*o.object_height_m > 0.001 && *o.object_height_m < 100)) {
    *error = fmt::format("--object-height {} m is outside 1 mm .. 100 m", *o.object_height_m);
  } else if (o.reference_cameras.empty() && !o.object_height_m) {
    *error =
        "a registration has no scale: give --reference-cameras FILE (calibrated, metres) or "
        "--object-height (e.g. 20cm)";
  } else {
    return true;
  }
  return false;
}

// The camera's pinhole at the photo's size (a calibration may be of another size).
eval::ViewCamera view_of(const eval::KnownCamera& known, int width, int height) {
  eval::ViewCamera c = eval::view_camera(*known.intrinsics, known.camera_from_world);
  const double scale = c.width > 0 ? static_cast<double>(width) / c.width : 1;
  c.width = width;
  c.height = height;
  c.fx *= scale;
  c.fy *= scale;
  c.cx *= scale;
  c.cy *= scale;
  return c;
}

// The cameras of the photos: the reference's (every photo), or the registration's (those that
// registered). Names in the photos' order.
std::optional<std::vector<std::pair<std::string, eval::ViewCamera>>> capture_cameras(
    const TwinOptions& o, const eval::EvalInputs& in, std::ostream& log, int* exit_code,
    std::string* error) {
  std::vector<std::pair<std::string, eval::ViewCamera>> cameras;
  if (!in.reference.empty()) {
    for (const auto& name : in.images.names) {
      const auto& known = in.reference.at(name);
      if (!known.intrinsics || known.intrinsics->params.size() < 3) {
        *exit_code = kUserError;
        *error = fmt::format("{} gives no intrinsics for {}: the twin needs the calibration",
                             o.reference_cameras, name);
        return std::nullopt;
      }
      const auto [w, h] = in.images.size.at(name);
      cameras.emplace_back(name, view_of(known, w, h));
    }
    return cameras;
  }
  eval::EvalOptions eo;
  eo.photos_dir = o.photos_dir;
  eo.output_dir = in.out.string();
  eo.sfm.colmap = o.colmap;
  eo.sfm.matcher = o.matcher;
  eo.photos.masks_dir = o.masks_dir;
  eo.photos.allow_partial = true;
  eo.quiet = o.quiet;
  eval::EvalSummary summary;
  const int rc = eval::evaluate(eo, log, &summary);
  if (rc != 0 || !summary.reconstructed) {
    *exit_code = rc == 1 ? kUserError : kToolError;
    *error = fmt::format("the photos did not register ({}); see {}", summary.failure,
                         (in.out / "eval.json").string());
    return std::nullopt;
  }
  auto model = eval::read_sparse_model(in.out / "colmap" / "model_txt", error);
  if (!model) {
    *exit_code = kToolError;
    return std::nullopt;
  }
  std::map<std::string, eval::ViewCamera> by_name;
  for (const auto& im : model->images) {
    const run::ColmapCamera* camera = model->camera_of(im);
    if (!camera) continue;  // none: read_sparse_model has checked the ids
    eval::KnownCamera known{im.camera_from_world, *camera};
    const auto [w, h] = in.images.size.at(im.name);
    by_name[im.name] = view_of(known, w, h);
  }
  for (const auto& name : in.images.names) {
    if (by_name.count(name)) cameras.emplace_back(name, by_name[name]);
  }
  return cameras;
}

// A photo's pixels in linear RGB.
std::optional<std::vector<Eigen::Vector3f>> read_linear(const fs::path& path, int w, int h,
                                                        std::string* error) {
  OIIO::ImageBuf in(path.string());
  if (!in.read(0, 0, true, OIIO::TypeDesc::FLOAT) || in.spec().width != w ||
      in.spec().height != h) {
    *error = fmt::format("cannot read the pixels of {}", path.string());
    return std::nullopt;
  }
  OIIO::ImageBuf rgb = in.spec().nchannels >= 3 ? OIIO::ImageBufAlgo::channels(in, 3, {0, 1, 2})
                                                : OIIO::ImageBufAlgo::channels(in, 3, {0, 0, 0});
  const OIIO::ImageBuf linear = OIIO::ImageBufAlgo::colorconvert(rgb, "sRGB", "linear");
  std::vector<Eigen::Vector3f> pixels(static_cast<std::size_t>(w) * h);
  linear.get_pixels(OIIO::ROI(0, w, 0, h, 0, 1, 0, 3), OIIO::TypeDesc::FLOAT, pixels.data());
  return pixels;
}

// The masks (eval/photo_masks.h: --masks, else a key on the backdrop) and pixels of the photos
// that have a camera.
std::optional<std::vector<CapturedPhoto>> captured_photos(
    const TwinOptions& o, const eval::EvalInputs& in,
    const std::vector<std::pair<std::string, eval::ViewCamera>>& cameras, std::ostream& log,
    json& report, std::string* error) {
  eval::PhotoMaskOptions mo;
  mo.masks_dir = o.masks_dir;
  mo.grow_px = 0;  // the silhouette itself
  mo.quiet = o.quiet;
  const auto masks = eval::make_photo_masks(in.images, mo, in.out, log, error);
  if (!masks) return std::nullopt;
  report["masks"] = masks->report;
  std::vector<CapturedPhoto> photos;
  std::vector<std::string> whole;  // masks that keep (nearly) the whole photo: no backdrop
  for (const auto& [name, camera] : cameras) {
    const fs::path mask = masks->dir / (fs::path(name).stem().string() + ".png");
    if (masks->dir.empty() || !fs::exists(mask)) continue;
    auto silhouette = read_silhouette(mask, error);
    auto linear = silhouette ? read_linear(in.images.dir / name, camera.width, camera.height, error)
                             : std::nullopt;
    if (!linear) return std::nullopt;
    const auto& c = silhouette->coverage;
    if (std::count_if(c.begin(), c.end(), [](float v) { return v >= 0.5f; }) >
        0.9 * static_cast<double>(c.size())) {
      whole.push_back(name);
      continue;
    }
    photos.push_back({name, camera, std::move(*silhouette), std::move(*linear)});
  }
  if (!whole.empty() && photos.empty()) {
    *error = fmt::format(
        "the masks keep more than 90 % of every photo ({} ...): no backdrop was found (give "
        "--masks or shoot on a plain backdrop)",
        whole.front());
    return std::nullopt;
  }
  if (!whole.empty() && !o.quiet) {
    log << fmt::format(
        "rigc twin: warning: left out {} photos whose masks keep more than 90 % "
        "of them (no backdrop found), {} first\n",
        whole.size(), whole.front());
  }
  return photos;
}

// The backdrop's colour: the median of the photos' pixels outside their silhouettes.
ir::Vec3 backdrop_color(const std::vector<CapturedPhoto>& photos) {
  std::array<std::vector<float>, 3> channels;
  for (const auto& p : photos) {
    for (std::size_t i = 0; i < p.linear.size(); i += 7) {
      if (p.silhouette.coverage[i] >= 0.5f) continue;
      for (int k = 0; k < 3; ++k) channels[k].push_back(p.linear[i][k]);
    }
  }
  ir::Vec3 color(0.02, 0.02, 0.02);
  for (int k = 0; k < 3; ++k) {
    auto& v = channels[k];
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    color[k] = v[v.size() / 2];
  }
  return color;
}

json vec_json(const Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

// The twin's scene: the hull (its bounds in the object frame) and the cameras moved there, the
// studio guessed.
TwinScene twin_scene(const TwinOptions& o, const Eigen::AlignedBox3d& box,
                     const std::vector<CapturedPhoto>& photos, const eval::Similarity& to_object) {
  TwinScene t;
  t.name = fs::path(o.photos_dir).filename().string() + "-twin";
  if (t.name == "-twin") t.name = "twin";
  t.source = o.reference_cameras.empty()
                 ? fmt::format("the photos in {} and their registration", o.photos_dir)
                 : fmt::format("the photos in {} and the cameras of {}", o.photos_dir,
                               o.reference_cameras);
  t.mesh_file = "object.ply";
  t.object_size = box.sizes();
  t.backdrop_linear = backdrop_color(photos);
  // A thin stand in the backdrop's colour, as the photos' support was (check warns that the
  // object overhangs it): a table as wide as the object showed as a dark disc in every view.
  t.table_diameter_m = std::max(0.01, 0.2 * std::min(box.sizes().x(), box.sizes().y()));
  t.camera = photos.front().camera;
  Vec3 towards = Vec3::Zero();
  double distance = 0;
  for (const auto& p : photos) {
    const eval::ViewCamera c = in_object_frame(p.camera, to_object);
    t.shots.emplace_back(p.name, c);
    towards += (c.center() - box.center()).normalized();
    distance += (c.center() - box.center()).norm() / static_cast<double>(photos.size());
  }
  // The key from the cameras' side, above them; a ring all round puts it where the first stood.
  Vec3 side(towards.x(), towards.y(), 0);
  if (side.norm() < 0.3 * static_cast<double>(photos.size())) {
    const Vec3 first = t.shots.front().second.center() - box.center();
    side = Vec3(first.x(), first.y(), 0);
  }
  side = side.norm() > 0 ? Vec3(side.normalized()) : Vec3(0, -1, 0);
  const Vec3 key = box.center() + 1.5 * distance * (0.87 * side + 0.5 * Vec3::UnitZ());
  t.lights.key_position = key + Vec3(0, 0, t.table_height_m);
  return t;
}

bool write_twin_mesh(const VisualHull& hull, const std::vector<Eigen::Vector3f>& colors,
                     const fs::path& path, std::string* error) {
  ir::Mesh mesh;
  mesh.positions = hull.positions;
  mesh.triangles = hull.triangles;
  mesh.normals = vertex_normals(hull);
  mesh.colors = colors;
  return write_ply(path.string(), mesh, error);
}

std::vector<eval::ViewCamera> view_cameras_of(const std::vector<CapturedPhoto>& photos) {
  std::vector<eval::ViewCamera> cameras;
  for (const auto& p : photos) cameras.push_back(p.camera);
  return cameras;
}

// How many times the hull's triangles are split for its colours: until a triangle's side is at
// most 1.5 photo pixels on the object (the median photo's, at the hull's centre), at most
// twice. Colours at the voxels' spacing blur the photos' fine texture, which SfM matches.
int color_subdivisions(const VisualHull& hull, const std::vector<eval::ViewCamera>& cameras) {
  constexpr int kMost = 2;
  std::vector<double> pixel_m;
  for (const auto& c : cameras) {
    pixel_m.push_back((c.center() - hull.region.center()).norm() / c.fx);
  }
  if (pixel_m.empty()) return 0;
  std::nth_element(pixel_m.begin(), pixel_m.begin() + pixel_m.size() / 2, pixel_m.end());
  const double side_m = 1.5 * pixel_m[pixel_m.size() / 2];
  int times = 0;
  for (double edge = hull.voxel_m; edge > side_m && times < kMost; edge /= 2) ++times;
  return times;
}

int fail(std::ostream& log, int code, const std::string& why) {
  log << "rigc twin: error: " << why << "\n";
  return code;
}

}  // namespace

int make_twin(const TwinOptions& o, std::ostream& log) {
  std::string error;
  if (!check_options(o, &error)) return fail(log, kUserError, error);
  const fs::path out = o.output_dir;
  eval::EvalOptions eo;
  eo.photos_dir = o.photos_dir;
  eo.output_dir = (out / "eval").string();
  eo.photos.reference_cameras = o.reference_cameras;
  eo.photos.masks_dir = o.masks_dir;
  eo.quiet = o.quiet;
  eval::EvalSummary summary;
  const auto in = eval::gather_inputs(eo, log, summary);
  if (!in) return kUserError;
  if (!in->images.one_size()) {
    return fail(log, kUserError,
                fmt::format("the photos in {} differ in size: a twin has one camera (give the "
                            "photos of one camera at one size)",
                            o.photos_dir));
  }
  int exit_code = kUserError;
  const auto cameras = capture_cameras(o, *in, log, &exit_code, &error);
  if (!cameras) return fail(log, exit_code, error);
  json report;
  const auto photos = captured_photos(o, *in, *cameras, log, report, &error);
  if (!photos) return fail(log, kUserError, error);
  std::vector<SilhouetteView> views;
  for (const auto& p : *photos) views.push_back({p.camera, &p.silhouette});
  const auto region = hull_search_region(views, &error);
  const auto carved =
      region
          ? carve_visual_hull(views, *region, {o.resolution, 3, o.max_misses, kHullGrowPx}, &error)
          : std::nullopt;
  if (!carved) return fail(log, kUserError, error);
  const std::vector<eval::ViewCamera> cameras_of_photos = view_cameras_of(*photos);
  const int subdivisions = color_subdivisions(*carved, cameras_of_photos);
  const VisualHull hull = subdivided(*carved, subdivisions);

  // The capture's frame to the object frame, the hull moved with it.
  const Vec3 up = up_of_cameras(cameras_of_photos, hull.region.center());
  eval::Similarity to_object = object_from_capture(up, hull.positions);
  VisualHull placed = hull;
  for (auto& p : placed.positions) p = to_object.apply(p.cast<double>()).cast<float>();
  Eigen::AlignedBox3d box;
  for (const auto& p : placed.positions) box.extend(p.cast<double>());
  // A registration's scale from the object's height; resting on z = 0 and centred, the placed
  // hull scales about the origin.
  const double scale = o.object_height_m ? *o.object_height_m / box.sizes().z() : 1;
  if (scale != 1) {
    eval::Similarity scaling;
    scaling.scale = scale;
    to_object = scaling * to_object;
    for (auto& p : placed.positions) p *= static_cast<float>(scale);
    box = Eigen::AlignedBox3d(scale * box.min(), scale * box.max());
    placed.voxel_m *= scale;
  }
  std::vector<ColorPhoto> color_photos;
  for (const auto& p : *photos) color_photos.push_back({p.camera, p.linear});
  const auto colors = color_vertices(hull, color_photos);
  if (!write_twin_mesh(placed, colors, out / "object.ply", &error)) {
    return fail(log, kToolError, error);
  }
  TwinScene scene = twin_scene(o, box, *photos, to_object);
  const fs::path scene_path = out / "scene.yaml";
  if (!write_file_atomically(scene_path, scene_yaml(scene), &error)) {
    return fail(log, kToolError, error);
  }
  report["cameras"] = {{"source", o.reference_cameras.empty() ? "registration" : "reference"},
                       {"photos", cameras->size()},
                       {"with_silhouettes", photos->size()}};
  report["hull"] = {{"vertices", placed.positions.size()},
                    {"triangles", placed.triangles.size()},
                    {"voxel_mm", 1000 * placed.voxel_m},
                    {"resolution", o.resolution},
                    {"filled_share", hull.filled_share},
                    {"subdivisions", subdivisions},
                    {"size_m", vec_json(scene.object_size)},
                    {"up_in_capture_frame", vec_json(up)},
                    {"scale", scale}};
  report["scene"] = scene_path.string();
  if (!o.quiet) {
    log << fmt::format(
        "rigc twin: hull of {} photos' silhouettes, {} triangles ({:.1f} mm voxels), "
        "{:.1f} x {:.1f} x {:.1f} cm; wrote {}\n",
        photos->size(), placed.triangles.size(), 1000 * placed.voxel_m, 100 * scene.object_size.x(),
        100 * scene.object_size.y(), 100 * scene.object_size.z(), scene_path.string());
  }
  if (o.render) {
    const int rc = render_and_compare(scene_path, scene, *photos, out, report, log, &error);
    if (rc != 0) return fail(log, rc, error);
    const json& c = report["comparison"];
    if (!o.quiet) {
      log << fmt::format(
          "rigc twin: rendered {} views: silhouette IoU against the photos' masks median {:.3f}, "
          "lowest {:.3f}; {}\n",
          photos->size(), c["median_silhouette_iou"].get<double>(),
          c["min_silhouette_iou"].get<double>(), c["contact_sheet"].get<std::string>());
    }
  }
  if (o.ring_views > 0) {
    TwinScene ring = scene;
    ring.name += fmt::format("-ring-{}", o.ring_views);
    std::vector<eval::ViewCamera> real;
    for (const auto& [name, camera] : scene.shots) real.push_back(camera);
    ring.shots.clear();
    const auto views = ring_views(real, box.center(), o.ring_views);
    for (std::size_t k = 0; k < views.size(); ++k) {
      ring.shots.emplace_back(
          fmt::format("view {} of {} on the real cameras' ring", k + 1, views.size()), views[k]);
    }
    const fs::path ring_path = out / fmt::format("ring_{}.yaml", o.ring_views);
    if (!write_file_atomically(ring_path, scene_yaml(ring), &error)) {
      return fail(log, kToolError, error);
    }
    report["ring_scene"] = ring_path.string();
  }
  if (!write_file_atomically(out / "twin.json", report.dump(2) + "\n", &error)) {
    return fail(log, kToolError, error);
  }
  return 0;
}

}  // namespace rigc::twin
