#include "twin/visual_hull.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/integration/UniformTSDFVolume.h>
#include <tbb/parallel_for.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

namespace rigc::twin {

namespace {

using eval::ViewCamera;
using Vec3 = Eigen::Vector3d;

// The silhouette smoothed over about a voxel's footprint, so that the carving's field crosses
// one half smoothly between grid points and marching cubes finds the edge between them. Two 1-D
// Gaussians: OIIO's 2-D convolve costs the kernel's area (a 77 px kernel took minutes).
Silhouette blurred(const Silhouette& s, double sigma_px) {
  if (sigma_px < 0.5) return s;
  const OIIO::ImageSpec spec(s.width, s.height, 1, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf in(spec, const_cast<float*>(s.coverage.data()));
  const float width = static_cast<float>(2 * std::ceil(3 * sigma_px) + 1);
  const OIIO::ImageBuf across = OIIO::ImageBufAlgo::make_kernel("gaussian", width, 1);
  const OIIO::ImageBuf down = OIIO::ImageBufAlgo::make_kernel("gaussian", 1, width);
  const OIIO::ImageBuf out =
      OIIO::ImageBufAlgo::convolve(OIIO::ImageBufAlgo::convolve(in, across), down);
  Silhouette b = s;
  out.get_pixels(OIIO::ROI(0, s.width, 0, s.height), OIIO::TypeDesc::FLOAT, b.coverage.data());
  return b;
}

// `s` grown by `r` pixels: the largest coverage within r, OIIO's square dilation.
Silhouette grown(const Silhouette& s, int r) {
  if (r <= 0) return s;
  const OIIO::ImageSpec spec(s.width, s.height, 1, OIIO::TypeDesc::FLOAT);
  OIIO::ImageBuf in(spec, const_cast<float*>(s.coverage.data()));
  const OIIO::ImageBuf out = OIIO::ImageBufAlgo::dilate(in, 2 * r + 1, 2 * r + 1);
  Silhouette g = s;
  out.get_pixels(OIIO::ROI(0, s.width, 0, s.height), OIIO::TypeDesc::FLOAT, g.coverage.data());
  return g;
}

// Bilinear coverage at continuous pixel coordinates (COLMAP's: a pixel's centre at +0.5).
float sample(const Silhouette& s, double u, double v) {
  const double x = u - 0.5, y = v - 0.5;
  const int x0 = std::clamp(static_cast<int>(std::floor(x)), 0, s.width - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(y)), 0, s.height - 2);
  const float fx = static_cast<float>(std::clamp(x - x0, 0.0, 1.0));
  const float fy = static_cast<float>(std::clamp(y - y0, 0.0, 1.0));
  const float top = s.at(x0, y0) * (1 - fx) + s.at(x0 + 1, y0) * fx;
  const float bottom = s.at(x0, y0 + 1) * (1 - fx) + s.at(x0 + 1, y0 + 1) * fx;
  return top * (1 - fy) + bottom * fy;
}

// Where `p` falls in `camera`'s image, if in front of it and inside.
bool project(const ViewCamera& c, const Vec3& p, double* u, double* v) {
  const Vec3 x =
      c.camera_from_world.topLeftCorner<3, 3>() * p + c.camera_from_world.topRightCorner<3, 1>();
  if (x.z() <= 0) return false;
  *u = c.fx * x.x() / x.z() + c.cx;
  *v = c.fy * x.y() / x.z() + c.cy;
  return *u >= 0.5 && *v >= 0.5 && *u <= c.width - 0.5 && *v <= c.height - 0.5;
}

// One grid's carving field: positive where every view that sees a point shows the object.
struct Grid {
  Vec3 origin;  // the first grid point
  double voxel = 0;
  int n = 0;                 // points a side
  std::vector<float> field;  // x-major, as Open3D's volume indexes
  Vec3 point(int i, int j, int k) const { return origin + voxel * Vec3(i, j, k); }
  std::size_t index(int i, int j, int k) const {
    return (static_cast<std::size_t>(i) * n + j) * n + k;
  }
};

Grid carve_grid(const std::vector<SilhouetteView>& views, const std::vector<Silhouette>& smooth,
                const Eigen::AlignedBox3d& region, int n, const HullOptions& options) {
  Grid g;
  g.n = n;
  g.voxel = region.sizes().maxCoeff() / (n - 1);
  g.origin = region.center() - Vec3::Constant(g.voxel * (n - 1) / 2.0);
  g.field.assign(static_cast<std::size_t>(n) * n * n, -0.5f);
  const int misses = std::max(0, options.max_misses);
  tbb::parallel_for(0, n, [&](int i) {
    std::vector<float> lowest;  // the smallest misses + 1 values, ascending
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const Vec3 p = g.point(i, j, k);
        lowest.assign(misses + 1, std::numeric_limits<float>::max());
        int seen = 0;
        for (std::size_t v = 0; v < views.size() && lowest.back() > -0.5f; ++v) {
          double u = 0, w = 0;
          // The object is in frame in every photo: what a photo cannot see is not the object.
          const float value =
              project(views[v].camera, p, &u, &w) ? sample(smooth[v], u, w) - 0.5f : -0.5f;
          seen += value > -0.5f;
          if (value < lowest.back()) {
            lowest.back() = value;
            std::sort(lowest.begin(), lowest.end());
          }
        }
        g.field[g.index(i, j, k)] = seen >= options.min_views ? lowest.back() : -0.5f;
      }
    }
  });
  return g;
}

// The box of the grid points kept, grown by `grow` voxels; empty when none is kept.
Eigen::AlignedBox3d kept_box(const Grid& g, double grow) {
  Eigen::AlignedBox3d box;
  for (int i = 0; i < g.n; ++i) {
    for (int j = 0; j < g.n; ++j) {
      for (int k = 0; k < g.n; ++k) {
        if (g.field[g.index(i, j, k)] > 0) box.extend(g.point(i, j, k));
      }
    }
  }
  if (!box.isEmpty()) {
    box.min() -= Vec3::Constant(grow * g.voxel);
    box.max() += Vec3::Constant(grow * g.voxel);
  }
  return box;
}

double kept_share(const Grid& g) {
  const auto kept = std::count_if(g.field.begin(), g.field.end(), [](float f) { return f > 0; });
  return static_cast<double>(kept) / static_cast<double>(g.field.size());
}

// `mesh`'s vertices and triangles as `hull`'s.
void take_mesh(const open3d::geometry::TriangleMesh& mesh, VisualHull& hull) {
  hull.positions.clear();
  hull.triangles.clear();
  for (const auto& v : mesh.vertices_) hull.positions.push_back(v.cast<float>());
  for (const auto& t : mesh.triangles_) {
    hull.triangles.push_back({static_cast<std::uint32_t>(t.x()), static_cast<std::uint32_t>(t.y()),
                              static_cast<std::uint32_t>(t.z())});
  }
}

// Open3D's marching cubes over the field (negative inside, as a TSDF is behind a surface).
void mesh_grid(const Grid& g, VisualHull& hull) {
  open3d::pipelines::integration::UniformTSDFVolume volume(
      g.voxel * g.n, g.n, g.voxel, open3d::pipelines::integration::TSDFVolumeColorType::NoColor,
      g.origin - Vec3::Constant(0.5 * g.voxel));
  std::vector<Eigen::Vector2d> tsdf(g.field.size());
  for (std::size_t i = 0; i < g.field.size(); ++i) {
    tsdf[i] = Eigen::Vector2d(std::clamp(-2.0 * g.field[i], -1.0, 1.0), 1.0);
  }
  volume.InjectVolumeTSDF(tsdf);
  const auto mesh = volume.ExtractTriangleMesh();
  mesh->RemoveDuplicatedVertices();
  mesh->RemoveDegenerateTriangles();
  take_mesh(*mesh, hull);
}

// A closed mesh's signed volume: positive when its triangles wind counter-clockwise outside.
double signed_volume(const VisualHull& hull) {
  double volume = 0;
  for (const auto& t : hull.triangles) {
    const Vec3 a = hull.positions[t[0]].cast<double>(), b = hull.positions[t[1]].cast<double>(),
               c = hull.positions[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6;
  }
  return volume;
}

// The centroid of a silhouette, in pixels (COLMAP's convention), and the radius that holds it.
bool silhouette_extent(const Silhouette& s, double* cu, double* cv, double* radius) {
  double sum = 0, su = 0, sv = 0;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      if (s.at(x, y) < 0.5f) continue;
      sum += 1;
      su += x + 0.5;
      sv += y + 0.5;
    }
  }
  if (sum == 0) return false;
  *cu = su / sum;
  *cv = sv / sum;
  double r2 = 0;
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      if (s.at(x, y) >= 0.5f)
        r2 = std::max(r2, std::pow(x + 0.5 - *cu, 2) + std::pow(y + 0.5 - *cv, 2));
    }
  }
  *radius = std::sqrt(r2);
  return true;
}

}  // namespace

std::optional<Eigen::AlignedBox3d> hull_search_region(const std::vector<SilhouetteView>& views,
                                                      std::string* error) {
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Vec3 b = Vec3::Zero();
  struct Seen {
    Vec3 centre;
    double radius_px, focal_px;
  };
  std::vector<Seen> seen;
  for (const auto& view : views) {
    double cu = 0, cv = 0, radius = 0;
    if (!silhouette_extent(*view.silhouette, &cu, &cv, &radius)) continue;
    const ViewCamera& c = view.camera;
    const Eigen::Matrix3d r = c.camera_from_world.topLeftCorner<3, 3>();
    const Vec3 centre = c.center();
    const Vec3 ray = (r.transpose() * Vec3((cu - c.cx) / c.fx, (cv - c.cy) / c.fy, 1)).normalized();
    const Eigen::Matrix3d off_ray = Eigen::Matrix3d::Identity() - ray * ray.transpose();
    a += off_ray;
    b += off_ray * centre;
    seen.push_back({centre, radius, std::min(c.fx, c.fy)});
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(a);
  if (seen.size() < 3 || !(svd.singularValues()(2) > 1e-6 * svd.singularValues()(0))) {
    *error = fmt::format(
        "{} of the {} silhouettes show an object{}: at least 3, seen from different directions, "
        "are needed to carve a hull",
        seen.size(), views.size(), seen.size() >= 3 ? " but their rays do not meet" : "");
    return std::nullopt;
  }
  const Vec3 object = a.ldlt().solve(b);
  double half = 0;
  for (const auto& s : seen)
    half = std::max(half, s.radius_px * (s.centre - object).norm() / s.focal_px);
  Eigen::AlignedBox3d box(object - Vec3::Constant(2 * half), object + Vec3::Constant(2 * half));
  return box;
}

std::optional<VisualHull> carve_visual_hull(const std::vector<SilhouetteView>& views,
                                            const Eigen::AlignedBox3d& region,
                                            const HullOptions& options, std::string* error) {
  if (views.size() < 3) {
    *error = fmt::format("{} silhouettes: at least 3 are needed to carve a hull", views.size());
    return std::nullopt;
  }
  std::vector<Silhouette> grown_silhouettes;  // once, for both passes
  for (const auto& view : views)
    grown_silhouettes.push_back(grown(*view.silhouette, options.grow_px));
  auto smoothed = [&](double voxel) {
    std::vector<Silhouette> out;
    for (std::size_t v = 0; v < views.size(); ++v) {
      const double distance = (views[v].camera.center() - region.center()).norm();
      out.push_back(blurred(grown_silhouettes[v], 0.5 * voxel * views[v].camera.fx / distance));
    }
    return out;
  };
  constexpr int kCoarse = 48;
  const Grid coarse = carve_grid(views, smoothed(region.sizes().maxCoeff() / (kCoarse - 1)), region,
                                 kCoarse, options);
  const double coarse_share = kept_share(coarse);
  const Eigen::AlignedBox3d kept = kept_box(coarse, 2);
  if (kept.isEmpty()) {
    *error =
        "no point is inside every silhouette that sees it: the silhouettes disagree (check "
        "the masks and the cameras)";
    return std::nullopt;
  }
  if (coarse_share > 0.9 || kept.contains(region)) {
    *error = fmt::format(
        "the hull fills {:.0f} % of the space the cameras look at: the silhouettes keep nearly "
        "everything (no backdrop was found; give --masks or a plain backdrop)",
        100 * coarse_share);
    return std::nullopt;
  }
  Eigen::AlignedBox3d fine_region = kept.intersection(region);
  const int n = std::max(8, options.resolution);
  const double fine_voxel = fine_region.sizes().maxCoeff() / (n - 1);
  const Grid fine = carve_grid(views, smoothed(fine_voxel), fine_region, n, options);
  VisualHull hull;
  hull.region = fine_region;
  hull.voxel_m = fine.voxel;
  hull.filled_share = kept_share(fine);
  mesh_grid(fine, hull);
  if (hull.triangles.empty()) {
    *error = "the hull has no surface at this resolution (raise --resolution)";
    return std::nullopt;
  }
  if (signed_volume(hull) < 0) {
    for (auto& t : hull.triangles) std::swap(t[1], t[2]);
  }
  return hull;
}

Silhouette render_silhouette(const ViewCamera& camera, const VisualHull& hull) {
  const eval::Surface surface(hull.positions, hull.triangles);
  Silhouette s;
  s.width = camera.width;
  s.height = camera.height;
  const std::size_t count = static_cast<std::size_t>(s.width) * s.height;
  std::vector<Vec3> origins(count, camera.center()), directions(count);
  const Eigen::Matrix3d world_from_camera =
      camera.camera_from_world.topLeftCorner<3, 3>().transpose();
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      directions[static_cast<std::size_t>(y) * s.width + x] =
          (world_from_camera *
           Vec3((x + 0.5 - camera.cx) / camera.fx, (y + 0.5 - camera.cy) / camera.fy, 1))
              .normalized();
    }
  }
  const eval::RayHits hits = surface.cast_rays(origins, directions);
  s.coverage.resize(count);
  for (std::size_t i = 0; i < count; ++i) s.coverage[i] = std::isfinite(hits.t[i]) ? 1.0f : 0.0f;
  return s;
}

VisualHull subdivided(const VisualHull& hull, int times) {
  if (times <= 0) return hull;
  open3d::geometry::TriangleMesh mesh;
  for (const auto& p : hull.positions) mesh.vertices_.push_back(p.cast<double>());
  for (const auto& t : hull.triangles) {
    mesh.triangles_.emplace_back(static_cast<int>(t[0]), static_cast<int>(t[1]),
                                 static_cast<int>(t[2]));
  }
  VisualHull out = hull;
  take_mesh(*mesh.SubdivideMidpoint(times), out);
  return out;
}

}  // namespace rigc::twin
