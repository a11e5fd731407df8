#include "run/camera_csv.h"

#include <gtest/gtest.h>

#include <sstream>

#include "eval/reconstruction_test_support.h"

namespace rigc::run {
namespace {

TEST(CameraCsv, OmegaPhiKappaRoundTrips) {
  for (const ir::Vec3& angles : {ir::Vec3(0.3, -0.2, 1.1), ir::Vec3(1.5, 0.1, -2.9)}) {
    const Eigen::Matrix3d r = rotation_from_omega_phi_kappa(angles);
    EXPECT_LT((omega_phi_kappa(r) - angles).norm(), 1e-12);
  }
  // A camera looking level along +Y (OpenCV: x right = +X, y down = -Z, z forward = +Y) has
  // omega 90 deg: Rx(90) turns the photogrammetric camera's -Z view onto +Y.
  Eigen::Matrix3d level;
  level << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  EXPECT_LT((omega_phi_kappa(level) - ir::Vec3(M_PI / 2, 0, 0)).norm(), 1e-12);
}

// Each line gives back the shot's centre and rotation.
TEST(CameraCsv, LinesGiveBackThePoses) {
  rigc::testing::TempDir dir;
  const auto r = eval::test_inputs::make_statue_run(dir.path(), 100);
  ASSERT_TRUE(r);
  std::istringstream text(rigc::testing::read_text((r->dir / "cameras.csv").string()));
  std::string line;
  std::getline(text, line);
  EXPECT_EQ(line.front(), '#');
  std::getline(text, line);
  EXPECT_EQ(line, "label,x,y,z,omega,phi,kappa");
  for (int index : r->shots) {
    ASSERT_TRUE(std::getline(text, line));
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream words(line);
    std::string name;
    ir::Vec3 c, a;
    words >> name >> c.x() >> c.y() >> c.z() >> a.x() >> a.y() >> a.z();
    const ir::Shot& shot = r->scene.shots[index];
    EXPECT_EQ(name, image_file_name(r->scene.camera, shot));
    EXPECT_LT((c - shot.object_from_camera.topRightCorner<3, 1>()).norm(), 1e-8);
    const Eigen::Matrix3d rotation = rotation_from_omega_phi_kappa(a * M_PI / 180);
    EXPECT_LT((rotation - camera_from_object(shot).topLeftCorner<3, 3>()).norm(), 1e-7);
  }
}

}  // namespace
}  // namespace rigc::run
