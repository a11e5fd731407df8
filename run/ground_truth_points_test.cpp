#include "run/ground_truth_points.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <set>

#include "eval/colmap.h"
#include "eval/geometry.h"
#include "eval/reconstruction_test_support.h"
#include "tests/test_support.h"

namespace rigc::run {
namespace {

using eval::test_inputs::make_statue_run;

TEST(GroundTruthPoints, LieOnTheSurfaceAndProjectWhereTheirTracksSay) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path());
  ASSERT_TRUE(r);
  const auto& pts = r->points.points;
  ASSERT_GT(pts.size(), 2500u);  // of 5000 samples: the base faces the table, the rest is seen
  const eval::Surface surface(ir::object_frame_positions(r->scene.object),
                              r->scene.object.mesh.triangles);
  std::vector<ir::Vec3> positions;
  for (const auto& p : pts) positions.push_back(p.position);
  for (double d : surface.signed_distance(positions)) ASSERT_LT(std::abs(d), 1e-6);
  std::set<int> colours;
  std::size_t observations = 0;
  for (const auto& p : pts) {
    ASSERT_FALSE(p.track.empty());
    colours.insert(p.rgb[0]);
    for (const auto& o : p.track) {
      const ir::Vec2 uv = project_opencv(r->camera.params(),
                                         camera_from_object(r->scene.shots[o.shot]), p.position);
      EXPECT_NEAR(uv.x(), o.x, 1e-9);
      EXPECT_NEAR(uv.y(), o.y, 1e-9);
      ++observations;
    }
  }
  EXPECT_GT(colours.size(), 20u);  // the speckle pattern, not one flat grey
  std::size_t listed = 0;
  for (const auto& image : r->points.per_image) listed += image.size();
  EXPECT_EQ(listed, observations);
}

// The points take the mesh's vertex colours (here one colour, unlike the statue's grey) in place
// of the material's base colour.
TEST(GroundTruthPoints, TakeTheVertexColours) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path(), 500);
  ASSERT_TRUE(r);
  ir::Scene scene = r->scene;
  for (auto& material : scene.materials) material.pattern.kind = ir::PatternKind::kNone;
  scene.object.mesh.colors.assign(scene.object.mesh.positions.size(), {0.5f, 0.1f, 0.02f});
  const GroundTruthPoints points = sample_ground_truth_points(scene, r->shots, r->camera, 500);
  ASSERT_GT(points.points.size(), 100u);
  for (const auto& p : points.points) {
    EXPECT_EQ(p.rgb, (std::array<std::uint8_t, 3>{188, 89, 39}));  // sRGB of the linear colour
  }
}

// Every observation is a point its camera sees unoccluded: a ray from the camera centre hits the
// surface first at the point (Embree, through eval's Surface).
TEST(GroundTruthPoints, ObservationsAreNotHiddenByTheObject) {
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path());
  ASSERT_TRUE(r);
  const eval::Surface surface(ir::object_frame_positions(r->scene.object),
                              r->scene.object.mesh.triangles);
  std::vector<ir::Vec3> origins, directions;
  std::vector<double> distances;
  for (const auto& p : r->points.points) {
    for (const auto& o : p.track) {
      const ir::Vec3 c = r->scene.shots[o.shot].object_from_camera.topRightCorner<3, 1>();
      origins.push_back(c);
      directions.push_back((p.position - c).normalized());
      distances.push_back((p.position - c).norm());
    }
  }
  const eval::RayHits hits = surface.cast_rays(origins, directions);
  std::size_t hidden = 0;
  for (std::size_t i = 0; i < distances.size(); ++i) {
    hidden += hits.t[i] < distances[i] - 2e-3;  // something 2 mm or more in front
  }
  // The depth buffer is at most 640 px wide: a few points at silhouettes may slip through.
  EXPECT_LT(static_cast<double>(hidden) / distances.size(), 0.01)
      << hidden << " of " << distances.size();
}

// COLMAP itself reads the model back (text to binary and back to text): points, tracks and the
// images' POINTS2D agree.
TEST(GroundTruthPoints, ColmapReadsTheModelBack) {
  RIGC_REQUIRE_TOOL(std::system("colmap -h > /dev/null 2>&1") == 0, "colmap");
  rigc::testing::TempDir dir;
  const auto r = make_statue_run(dir.path(), 2000);
  ASSERT_TRUE(r);
  std::filesystem::create_directories(dir.path() / "bin");
  std::filesystem::create_directories(dir.path() / "txt");
  for (const auto& [in, out, type] : {std::tuple{r->dir / "sparse", dir.path() / "bin", "BIN"},
                                      std::tuple{dir.path() / "bin", dir.path() / "txt", "TXT"}}) {
    const auto result =
        rigc::testing::run_process({"colmap", "model_converter", "--input_path", in.string(),
                                    "--output_path", out.string(), "--output_type", type});
    ASSERT_EQ(result.exit_code, 0) << result.out << result.err;
  }
  std::string error;
  const auto model = eval::read_sparse_model(dir.path() / "txt", &error);
  ASSERT_TRUE(model) << error;
  EXPECT_EQ(model->images.size(), r->shots.size());
  ASSERT_EQ(model->points.size(), r->points.points.size());
  std::size_t observations = 0;
  for (const auto& p : r->points.points) observations += p.track.size();
  EXPECT_NEAR(model->mean_track_length(),
              static_cast<double>(observations) / r->points.points.size(), 1e-9);
}

}  // namespace
}  // namespace rigc::run
