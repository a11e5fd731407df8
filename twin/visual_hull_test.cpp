#include "twin/visual_hull.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace rigc::twin {
namespace {

using Vec3 = Eigen::Vector3d;

// A 320 x 240 camera at `eye` looking at `target`, +Z up.
eval::ViewCamera camera_at(const Vec3& eye, const Vec3& target) {
  const Vec3 forward = (target - eye).normalized();
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  const Vec3 down = forward.cross(right);
  eval::ViewCamera c;
  c.camera_from_world.topLeftCorner<3, 3>().row(0) = right.transpose();
  c.camera_from_world.topLeftCorner<3, 3>().row(1) = down.transpose();
  c.camera_from_world.topLeftCorner<3, 3>().row(2) = forward.transpose();
  c.camera_from_world.topRightCorner<3, 1>() = -c.camera_from_world.topLeftCorner<3, 3>() * eye;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 500;
  c.cx = 160;
  c.cy = 120;
  return c;
}

// The exact silhouette of a sphere: a pixel is in it when the ray through its centre hits it.
Silhouette sphere_silhouette(const eval::ViewCamera& c, const Vec3& centre, double radius) {
  Silhouette s;
  s.width = c.width;
  s.height = c.height;
  s.coverage.resize(static_cast<std::size_t>(s.width) * s.height);
  const Eigen::Matrix3d world_from_camera = c.camera_from_world.topLeftCorner<3, 3>().transpose();
  for (int y = 0; y < s.height; ++y) {
    for (int x = 0; x < s.width; ++x) {
      const Vec3 d = (world_from_camera * Vec3((x + 0.5 - c.cx) / c.fx, (y + 0.5 - c.cy) / c.fy, 1))
                         .normalized();
      const Vec3 to_centre = centre - c.center();
      const double miss = (to_centre - to_centre.dot(d) * d).norm();
      s.coverage[static_cast<std::size_t>(y) * s.width + x] = miss < radius ? 1.0f : 0.0f;
    }
  }
  return s;
}

struct Capture {
  std::vector<eval::ViewCamera> cameras;
  std::vector<Silhouette> silhouettes;
  std::vector<SilhouetteView> views() const {
    std::vector<SilhouetteView> v;
    for (std::size_t i = 0; i < cameras.size(); ++i) v.push_back({cameras[i], &silhouettes[i]});
    return v;
  }
};

// A sphere of 5 cm at (0.02, -0.01, 0.1) seen by 12 cameras on a ring 60 cm away, 20 cm above.
Capture sphere_capture() {
  Capture c;
  const Vec3 centre(0.02, -0.01, 0.1);
  for (int i = 0; i < 12; ++i) {
    const double a = 2 * M_PI * i / 12;
    c.cameras.push_back(
        camera_at(centre + Vec3(0.6 * std::cos(a), 0.6 * std::sin(a), 0.2), centre));
    c.silhouettes.push_back(sphere_silhouette(c.cameras.back(), centre, 0.05));
  }
  return c;
}

TEST(VisualHull, ASphereIsCarvedToItsSilhouettes) {
  const Capture c = sphere_capture();
  std::string error;
  const auto region = hull_search_region(c.views(), &error);
  ASSERT_TRUE(region) << error;
  EXPECT_TRUE(region->contains(Vec3(0.02, -0.01, 0.1)));
  const auto hull = carve_visual_hull(c.views(), *region, {96, 3}, &error);
  ASSERT_TRUE(hull) << error;
  // Twelve views bound a sphere by a polyhedron a little larger: no vertex inside the sphere by
  // more than a voxel, none further out than the cone of 12 views allows.
  for (const auto& p : hull->positions) {
    const double r = (p.cast<double>() - Vec3(0.02, -0.01, 0.1)).norm();
    ASSERT_GT(r, 0.05 - hull->voxel_m);
    ASSERT_LT(r, 0.05 / std::cos(M_PI / 12) * 1.12);
  }
  // Split for the colours: four triangles for one, the same silhouettes.
  const VisualHull finer = subdivided(*hull, 1);
  EXPECT_EQ(finer.triangles.size(), 4 * hull->triangles.size());
  for (std::size_t i = 0; i < c.cameras.size(); ++i) {
    EXPECT_GT(silhouette_iou(render_silhouette(c.cameras[i], *hull), c.silhouettes[i]), 0.95)
        << "view " << i;
    EXPECT_GT(silhouette_iou(render_silhouette(c.cameras[i], finer), c.silhouettes[i]), 0.95)
        << "view " << i;
  }
}

// Silhouettes grown by 3 pixels before carving grow the hull by about 3 pixels' width at the
// sphere's distance: its mean radius, not more than half again.
TEST(VisualHull, GrownSilhouettesCarveALargerHull) {
  const Capture c = sphere_capture();
  std::string error;
  const auto region = hull_search_region(c.views(), &error);
  ASSERT_TRUE(region) << error;
  auto mean_radius = [&](int grow_px) {
    const auto hull = carve_visual_hull(c.views(), *region, {64, 3, 0, grow_px}, &error);
    EXPECT_TRUE(hull) << error;
    double sum = 0;
    for (const auto& p : hull->positions) sum += (p.cast<double>() - Vec3(0.02, -0.01, 0.1)).norm();
    return sum / static_cast<double>(hull->positions.size());
  };
  const double pixel_m = (c.cameras[0].center() - Vec3(0.02, -0.01, 0.1)).norm() / c.cameras[0].fx;
  const double growth = mean_radius(3) - mean_radius(0);
  EXPECT_GT(growth, 2 * pixel_m);
  EXPECT_LT(growth, 4.5 * pixel_m);
}

TEST(VisualHull, SilhouettesThatKeepEverythingFoundNoBackdrop) {
  Capture c = sphere_capture();
  for (auto& s : c.silhouettes) std::fill(s.coverage.begin(), s.coverage.end(), 1.0f);
  std::string error;
  const Capture sphere = sphere_capture();
  const auto region = hull_search_region(sphere.views(), &error);
  ASSERT_TRUE(region) << error;
  EXPECT_FALSE(carve_visual_hull(c.views(), *region, {}, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("no backdrop was found"));
}

TEST(VisualHull, TooFewSilhouettesAreRefused) {
  Capture c = sphere_capture();
  c.cameras.resize(2);
  c.silhouettes.resize(2);
  std::string error;
  EXPECT_FALSE(hull_search_region(c.views(), &error));
  EXPECT_THAT(error, ::testing::HasSubstr("at least 3"));
  EXPECT_FALSE(
      carve_visual_hull(c.views(), Eigen::AlignedBox3d(Vec3::Zero(), Vec3::Ones()), {}, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("2 silhouettes"));
}

}  // namespace
}  // namespace rigc::twin
