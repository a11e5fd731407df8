#include "run/bundler.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "eval/camera_files.h"
#include "eval/reconstruction_test_support.h"

using ::testing::HasSubstr;

namespace rigc::run {
namespace {

// bundle.out read back by a Bundler reader (eval's, which `rigc eval --cameras` uses) gives the
// ground-truth poses, the names, and the points with their views.
TEST(Bundler, ReadsBackAsTheGroundTruthPoses) {
  rigc::testing::TempDir dir;
  const auto r = eval::test_inputs::make_statue_run(dir.path(), 1000);
  ASSERT_TRUE(r);
  std::string error;
  const auto images = eval::read_bundler(r->dir / "bundle.out", r->dir / "bundle.list.txt", &error);
  ASSERT_TRUE(images) << error;
  ASSERT_EQ(images->size(), r->shots.size());
  for (std::size_t i = 0; i < images->size(); ++i) {
    const ir::Shot& shot = r->scene.shots[r->shots[i]];
    EXPECT_EQ((*images)[i].name, image_file_name(r->scene.camera, shot));
    EXPECT_LT(((*images)[i].camera_from_world - camera_from_object(shot)).norm(), 1e-9);
  }
  // The header's counts and the first point: position, colour, its views from the image centre.
  std::ifstream out(r->dir / "bundle.out");
  std::string header;
  std::getline(out, header);
  std::size_t cameras = 0, points = 0;
  out >> cameras >> points;
  EXPECT_EQ(cameras, r->shots.size());
  ASSERT_EQ(points, r->points.points.size());
  for (std::size_t i = 0; i < 5 * cameras; ++i) {
    double skip[3];
    out >> skip[0] >> skip[1] >> skip[2];
  }
  const GroundTruthPoint& p = r->points.points.front();
  ir::Vec3 position;
  int rgb[3], views = 0;
  out >> position.x() >> position.y() >> position.z() >> rgb[0] >> rgb[1] >> rgb[2] >> views;
  EXPECT_LT((position - p.position).norm(), 1e-8);
  EXPECT_EQ(rgb[1], p.rgb[1]);
  ASSERT_EQ(views, static_cast<int>(p.track.size()));
  int camera = 0, key = 0;
  double x = 0, y = 0;
  out >> camera >> key >> x >> y;
  EXPECT_EQ(camera, p.track[0].shot);
  EXPECT_EQ(key, p.track[0].point2d);
  EXPECT_NEAR(x, p.track[0].x - r->camera.width / 2.0, 1e-3);
  EXPECT_NEAR(y, r->camera.height / 2.0 - p.track[0].y, 1e-3);
}

TEST(Bundler, AListThatDoesNotMatchIsAnError) {
  rigc::testing::TempDir dir;
  rigc::testing::write_text(dir.file("b.out"), "# Bundle file v0.3\n2 0\n");
  rigc::testing::write_text(dir.file("b.list.txt"), "a.jpg\n");
  std::string error;
  EXPECT_FALSE(eval::read_bundler(dir.file("b.out"), dir.file("b.list.txt"), &error));
  EXPECT_THAT(error, HasSubstr("lists 1 images"));
}

// Bundler states one focal length and no principal point: a camera with fx != fy beyond a body's
// rounding, or its principal point off the centre, gets no bundle.out rather than a wrong one.
TEST(Bundler, DescribesOnlyCamerasWithOneFocalLengthAndACentredPrincipalPoint) {
  ir::Camera camera;
  camera.width_px = 640;
  camera.height_px = 480;
  camera.fx = 1520.4;
  camera.fy = 1522;  // 0.1 %: a body's rounding
  camera.cx = 320;
  camera.cy = 240;
  EXPECT_EQ(bundler_camera_problem(camera, 0.5), "");
  camera.fy = 1545.9;
  EXPECT_THAT(bundler_camera_problem(camera, 1), HasSubstr("one focal length"));
  camera.fy = 1520.4;
  camera.cx = 302.3;
  EXPECT_THAT(bundler_camera_problem(camera, 1),
              HasSubstr("principal point at the image centre (320, "
                        "240), this one at (302.3, 240)"));
}

}  // namespace
}  // namespace rigc::run
