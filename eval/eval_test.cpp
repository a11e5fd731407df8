#include "eval/eval.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "assets/mesh_io.h"
#include "compiler/frontend.h"
#include "eval/align.h"
#include "eval/colmap.h"
#include "eval/eval_test_support.h"
#include "eval/geometry.h"
#include "eval/metrics.h"
#include "eval/reconstruction_test_support.h"
#include "run/manifest.h"
#include "tests/test_support.h"

using ::testing::HasSubstr;
using ::testing::Not;

namespace rigc::eval {
namespace {

namespace fs = std::filesystem;
using test_inputs::cube;
using test_inputs::write_cube_ply;
using test_inputs::write_small_image;

TEST(EvalAlign, RansacRecoversKnownSimilarityDespiteOutliers) {
  Similarity truth;
  truth.scale = 0.037;
  truth.rotation = Eigen::AngleAxisd(0.7, Vec3(0.2, -1, 0.4).normalized()).toRotationMatrix();
  truth.translation = Vec3(0.3, -2.0, 0.75);
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 10);
  std::vector<Vec3> src, dst;
  for (int i = 0; i < 30; ++i) {
    const Vec3 p(g(rng), g(rng), g(rng));
    src.push_back(p);
    Vec3 q = truth.apply(p);
    if (i % 5 == 0) q += Vec3(0.5, -0.3, 0.2);  // 20 % gross outliers
    dst.push_back(q);
  }
  auto fit = fit_similarity_ransac(src, dst, 0.01, 500, 1);
  ASSERT_TRUE(fit.has_value());
  EXPECT_EQ(fit->inliers.size(), 24u);
  EXPECT_NEAR(fit->transform.scale, truth.scale, 1e-12);
  EXPECT_LT((fit->transform.rotation - truth.rotation).norm(), 1e-9);
  EXPECT_LT((fit->transform.translation - truth.translation).norm(), 1e-9);
  EXPECT_LT(fit->rms_inlier_error, 1e-9);
  // Composition and inverse.
  const Similarity id = fit->transform * fit->transform.inverse();
  EXPECT_NEAR(id.scale, 1, 1e-12);
  EXPECT_LT((id.apply(Vec3(1, 2, 3)) - Vec3(1, 2, 3)).norm(), 1e-9);
  EXPECT_LT((Similarity::from_matrix(truth.matrix()).matrix() - truth.matrix()).norm(), 1e-12);
}

TEST(EvalAlign, PointsInsideKeepsTheSerialFiltersPointsInOrder) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> points(300000);
  for (auto& p : points) p = Vec3(u(rng), u(rng), u(rng));
  const Eigen::AlignedBox3d box(Vec3(-0.5, -0.5, -0.5), Vec3(0.5, 0.5, 0.5));
  std::vector<Vec3> inside;
  std::vector<std::size_t> inside_index;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (box.contains(points[i])) {
      inside.push_back(points[i]);
      inside_index.push_back(i);
    }
  }
  ASSERT_GT(inside.size(), 30000u);
  std::vector<std::size_t> indices;
  EXPECT_EQ(points_inside(points, box, std::numeric_limits<std::size_t>::max(), &indices), inside);
  EXPECT_EQ(indices, inside_index);
  // A limit keeps every nth, from the first.
  const std::size_t stride = (inside.size() + 9999) / 10000;
  const std::vector<Vec3> strided = points_inside(points, box, 10000);
  ASSERT_EQ(strided.size(), (inside.size() + stride - 1) / stride);
  EXPECT_LE(strided.size(), 10000u);
  for (std::size_t k = 0; k < strided.size(); ++k) EXPECT_EQ(strided[k], inside[k * stride]);
  EXPECT_TRUE(points_inside({}, box).empty());
}

TEST(EvalAlign, TooFewPairsIsNoAlignment) {
  EXPECT_FALSE(
      fit_similarity_ransac({Vec3(0, 0, 0), Vec3(1, 0, 0)}, {Vec3(0, 0, 0), Vec3(1, 0, 0)}, 0.1)
          .has_value());
}

TEST(EvalDistance, SignIsNegativeInsideAndPositiveOutside) {
  std::vector<Eigen::Vector3f> v;
  std::vector<std::array<std::uint32_t, 3>> t;
  cube(0.5, &v, &t);
  Surface surface(v, t);
  EXPECT_NEAR(surface.area(), 6.0, 1e-9);
  const auto d = surface.signed_distance(
      {Vec3(0, 0, 0.6), Vec3(0, 0, 0.4), Vec3(0.7, 0.1, 0.2), Vec3(-0.45, 0, 0), Vec3(0, 0, 0)});
  EXPECT_NEAR(d[0], 0.1, 1e-6);
  EXPECT_NEAR(d[1], -0.1, 1e-6);
  EXPECT_NEAR(d[2], 0.2, 1e-6);
  EXPECT_NEAR(d[3], -0.05, 1e-6);
  EXPECT_NEAR(d[4], -0.5, 1e-6);
}

TEST(EvalDistance, StatsOfKnownValues) {
  const DistanceStats s = distance_stats({-2, -1, 0, 1, 2, 6, NAN});
  EXPECT_EQ(s.count, 6u);
  EXPECT_NEAR(s.mean, 1.0, 1e-12);
  EXPECT_NEAR(s.median, 0.5, 1e-12);
  EXPECT_NEAR(s.stddev, std::sqrt((9 + 4 + 1 + 0 + 1 + 25) / 5.0), 1e-12);
  EXPECT_NEAR(s.p90_abs, 4.0, 1e-12);  // |d| sorted 0 1 1 2 2 6: 90 % at 4.5 -> 2 + 0.5 * 4
}

TEST(EvalFScore, PerturbedSamplingMatchesExpectedValue) {
  std::vector<Eigen::Vector3f> v;
  std::vector<std::array<std::uint32_t, 3>> t;
  cube(0.5, &v, &t);
  Surface surface(v, t);
  std::vector<Vec3> truth, normals;
  surface.sample(2000, 3, &truth, &normals);
  ASSERT_EQ(truth.size(), 2000u);
  const double tau = 0.001;
  // A quarter of the points pushed 5 tau off the surface (outwards), the rest exact: precision
  // and recall are both 0.75 (samples are ~5 cm apart, far more than tau).
  std::vector<Vec3> reconstruction = truth;
  for (std::size_t i = 0; i < reconstruction.size(); i += 4)
    reconstruction[i] += 5 * tau * normals[i];
  const auto d = surface.signed_distance(reconstruction);
  for (std::size_t i = 0; i < d.size(); i += 4) EXPECT_NEAR(d[i], 5 * tau, 1e-6);
  const FScore f = f_score(d, nearest_distances(truth, reconstruction), tau);
  EXPECT_NEAR(f.precision, 0.75, 1e-9);
  EXPECT_NEAR(f.recall, 0.75, 0.003);
  EXPECT_NEAR(f.fscore, 0.75, 0.003);
  // The definition on its own.
  const FScore g = f_score({0, 0.5, 2, 3}, {0, 0.1}, 1.0);
  EXPECT_DOUBLE_EQ(g.precision, 0.5);
  EXPECT_DOUBLE_EQ(g.recall, 1.0);
  EXPECT_NEAR(g.fscore, 2 * 0.5 / 1.5, 1e-12);
}

TEST(EvalVisibility, OneCameraSeesOneFaceOfACube) {
  std::vector<Eigen::Vector3f> v;
  std::vector<std::array<std::uint32_t, 3>> t;
  cube(0.5, &v, &t);
  Surface surface(v, t);
  std::vector<Vec3> samples, normals;
  surface.sample(6000, 1, &samples, &normals);
  // A camera on +X looking at the origin: camera +Z = world -X, +X = world +Y, +Y = world -Z.
  ViewCamera cam;
  Eigen::Matrix3d r;
  r << 0, 1, 0, 0, 0, -1, -1, 0, 0;
  cam.camera_from_world.topLeftCorner<3, 3>() = r;
  cam.camera_from_world.topRightCorner<3, 1>() = -r * Vec3(4, 0, 0);
  cam.width = 1000;
  cam.height = 1000;
  cam.fx = cam.fy = 2000;
  cam.cx = cam.cy = 500;
  EXPECT_LT((cam.center() - Vec3(4, 0, 0)).norm(), 1e-12);
  const std::vector<int> seen = surface.visible(samples, normals, {cam});
  EXPECT_NEAR(static_cast<double>(seen.size()) / samples.size(), 1.0 / 6, 0.02);
  for (int i : seen) EXPECT_NEAR(samples[i].x(), 0.5, 1e-5);
  const RayHits hits =
      surface.cast_rays({Vec3(4, 0, 0), Vec3(4, 0, 0)}, {Vec3(-2, 0, 0), Vec3(0, 0, 1)});
  ASSERT_EQ(hits.t.size(), 2u);
  EXPECT_NEAR(hits.t[0], 1.75, 1e-5);  // in units of the direction's length
  EXPECT_NEAR(std::abs(hits.normals[0].x()), 1.0, 1e-5);
  EXPECT_FALSE(std::isfinite(hits.t[1]));
}

TEST(EvalColmap, ReadsPointsWithTracks) {
  rigc::testing::TempDir dir;
  rigc::testing::write_text(dir.file("points3D.txt"),
                            "# comment\n1 0.5 -1 2 10 20 30 0.25 1 0 2 5 3 7\n"
                            "2 0 0 0 0 0 0 0.75 1 1 2 2\n");
  std::string error;
  auto points = read_colmap_points(dir.file("points3D.txt"), &error);
  ASSERT_TRUE(points.has_value()) << error;
  ASSERT_EQ(points->size(), 2u);
  EXPECT_EQ((*points)[0].track_images, (std::vector<int>{1, 2, 3}));
  EXPECT_DOUBLE_EQ((*points)[0].position.y(), -1);
  SparseModel model;
  model.points = *points;
  EXPECT_DOUBLE_EQ(model.mean_track_length(), 2.5);
  EXPECT_DOUBLE_EQ(model.mean_reprojection_error(), (0.25 * 3 + 0.75 * 2) / 5);
  rigc::testing::write_text(dir.file("bad.txt"), "1 2 x\n");
  EXPECT_FALSE(read_colmap_points(dir.file("bad.txt"), &error).has_value());
  EXPECT_THAT(error, HasSubstr("bad.txt:1"));
}

// Optical axis of a camera at azimuth `azimuth_deg` and elevation `elevation_deg` looking at the
// origin.
Vec3 axis_towards_origin(double azimuth_deg, double elevation_deg) {
  const double a = azimuth_deg * M_PI / 180, e = elevation_deg * M_PI / 180;
  return -Vec3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
}

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b)) * 180 / M_PI;
}

// Partners of every view in `pairs`.
std::vector<std::vector<int>> partners(int count, const std::vector<std::pair<int, int>>& pairs) {
  std::vector<std::vector<int>> p(count);
  for (const auto& [i, j] : pairs) {
    p[i].push_back(j);
    p[j].push_back(i);
  }
  return p;
}

bool connected(int count, const std::vector<std::pair<int, int>>& pairs) {
  const auto p = partners(count, pairs);
  std::vector<bool> seen(count, false);
  std::vector<int> stack = {0};
  seen[0] = true;
  int reached = 1;
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    for (int j : p[i]) {
      if (!seen[j]) {
        seen[j] = true;
        ++reached;
        stack.push_back(j);
      }
    }
  }
  return reached == count;
}

TEST(EvalNeighbourPairs, TurntableRingPairsNearViewsAndWrapsAround) {
  // The paper scene at 24 steps of 15 deg: each view with the 3 before and the 3 after it.
  std::vector<Vec3> axes;
  for (int i = 0; i < 24; ++i) axes.push_back(axis_towards_origin(15.0 * i, -9.5));
  const auto pairs = neighbour_pairs(axes);
  EXPECT_EQ(pairs.size(), 72u);  // of 276
  for (const auto& [i, j] : pairs) {
    EXPECT_LT(i, j);
    const int steps = std::min(j - i, 24 - (j - i));
    EXPECT_LE(steps, 3) << i << " " << j;
  }
  auto has = [&](int i, int j) {
    return std::find(pairs.begin(), pairs.end(), std::make_pair(i, j)) != pairs.end();
  };
  EXPECT_TRUE(has(0, 1));
  EXPECT_TRUE(has(0, 23));  // wrap-around
  EXPECT_TRUE(has(0, 21));
  EXPECT_TRUE(has(2, 23));
  EXPECT_FALSE(has(0, 4));
  EXPECT_FALSE(has(0, 20));
  EXPECT_TRUE(std::is_sorted(pairs.begin(), pairs.end()));
  // A narrower angle keeps fewer.
  NeighbourPairOptions narrow;
  narrow.max_angle_deg = 30;
  EXPECT_EQ(neighbour_pairs(axes, narrow).size(), 48u);
}

TEST(EvalNeighbourPairs, SparseRingStaysConnectedAndDenseRingIsCapped) {
  // 6 views 60 deg apart: none within 45 deg, the nearest two still pair.
  std::vector<Vec3> sparse;
  for (int i = 0; i < 6; ++i) sparse.push_back(axis_towards_origin(60.0 * i, 0));
  const auto sparse_pairs = neighbour_pairs(sparse);
  EXPECT_EQ(sparse_pairs.size(), 6u);
  EXPECT_TRUE(connected(6, sparse_pairs));
  // 72 views 5 deg apart: 18 within 45 deg, the nearest 10 (5 on each side) kept.
  std::vector<Vec3> dense;
  for (int i = 0; i < 72; ++i) dense.push_back(axis_towards_origin(5.0 * i, 0));
  const auto dense_pairs = neighbour_pairs(dense);
  EXPECT_EQ(dense_pairs.size(), 72u * 5);
  for (const auto& [i, j] : dense_pairs) EXPECT_LE(angle_deg(dense[i], dense[j]), 25.001);
}

TEST(EvalNeighbourPairs, MultiRingPairsAcrossRings) {
  // scenes/multi-ring.yaml's orbits: 16 views at 10 deg elevation, 12 at 35, 6 at 65.
  std::vector<Vec3> axes;
  std::vector<int> ring;
  const std::array<std::pair<int, double>, 3> rings = {{{16, 10}, {12, 35}, {6, 65}}};
  for (int r = 0; r < 3; ++r) {
    for (int i = 0; i < rings[r].first; ++i) {
      axes.push_back(axis_towards_origin(360.0 * i / rings[r].first, rings[r].second));
      ring.push_back(r);
    }
  }
  const int count = static_cast<int>(axes.size());
  const auto pairs = neighbour_pairs(axes);
  EXPECT_TRUE(connected(count, pairs));
  int across = 0;
  for (const auto& [i, j] : pairs) {
    if (ring[i] != ring[j]) ++across;
  }
  EXPECT_GT(across, 0);
  EXPECT_LT(pairs.size(), static_cast<std::size_t>(count * (count - 1) / 2) / 3);
  // A pair is within 45 deg, or one of its views' two nearest (which keep sparse views linked).
  auto second_nearest_deg = [&](int i) {
    std::vector<double> angles;
    for (int k = 0; k < count; ++k) {
      if (k != i) angles.push_back(angle_deg(axes[i], axes[k]));
    }
    std::sort(angles.begin(), angles.end());
    return angles[1];
  };
  for (const auto& [i, j] : pairs) {
    const double a = angle_deg(axes[i], axes[j]);
    EXPECT_TRUE(a <= 45.001 || a <= second_nearest_deg(i) + 1e-9 ||
                a <= second_nearest_deg(j) + 1e-9)
        << i << " " << j << " " << a;
  }
  for (const auto& p : partners(count, pairs)) EXPECT_GE(p.size(), 2u);
}

TEST(EvalNeighbourPairs, PairListNamesTheImages) {
  rigc::testing::TempDir dir;
  std::string error;
  ASSERT_TRUE(
      write_pair_list(dir.file("pairs.txt"), {"a.jpg", "b.jpg", "c.jpg"}, {{0, 1}, {1, 2}}, &error))
      << error;
  std::ifstream in(dir.file("pairs.txt"));
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "a.jpg b.jpg\nb.jpg c.jpg\n");
}

TEST(EvalPictures, HeatColoursFollowCloudCompare) {
  using C = std::array<std::uint8_t, 3>;
  EXPECT_EQ(signed_distance_color(-1, 1), (C{0, 0, 255}));
  EXPECT_EQ(signed_distance_color(0, 1), (C{0, 255, 0}));
  EXPECT_EQ(signed_distance_color(5, 1), (C{255, 0, 0}));
}

TEST(EvalOptions, CheckRefusesFieldsOutOfRangeBeforeAnythingRuns) {
  EvalOptions o;
  std::string error;
  EXPECT_FALSE(o.check(&error)) << "neither a run nor photos";
  o.run_dir = "run";
  EXPECT_TRUE(o.check(&error)) << error;
  o.photos_dir = "photos";
  EXPECT_FALSE(o.check(&error)) << "both a run and photos";
  o.photos_dir.clear();
  auto refused = [&](auto change) {
    EvalOptions bad = o;
    change(bad);
    return !bad.check(&error);
  };
  EXPECT_TRUE(refused([](EvalOptions& b) { b.sfm.colmap.clear(); }));
  EXPECT_TRUE(refused([](EvalOptions& b) { b.sfm.neighbour_angle_deg = 0; }));
  EXPECT_TRUE(refused([](EvalOptions& b) { b.sfm.neighbour_angle_deg = NAN; }));
  EXPECT_TRUE(refused([](EvalOptions& b) { b.metrics.poisson_depth = 0; }));
  EXPECT_TRUE(refused([](EvalOptions& b) { b.metrics.tau_mm = -1; }));
  EXPECT_TRUE(refused([](EvalOptions& b) { b.metrics.ground_truth_samples = 0; }));
  EXPECT_TRUE(refused([](EvalOptions& b) { b.metrics.color_range_mm = -2; }));
  // evaluate() refuses them as a user error, and writes nothing.
  rigc::testing::TempDir dir;
  EvalOptions bad = o;
  bad.run_dir = dir.file("run");
  bad.metrics.tau_mm = 0;
  std::ostringstream log;
  EXPECT_EQ(evaluate(bad, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("rigc eval: error: the F-score threshold is 0 mm"));
  EXPECT_FALSE(fs::exists(dir.path() / "run"));
}

TEST(EvalCommand, NeighboursMatcherNeedsEveryImagesPlannedPose) {
  rigc::testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  for (const char* name : {"a.jpg", "b.jpg", "c.jpg"})
    write_small_image(dir.file("photos/") + name);
  write_cube_ply(dir.file("cube.ply"));
  EvalOptions o;
  o.photos_dir = dir.file("photos");
  o.ground_truth = dir.file("cube.ply");
  o.sfm.matcher = Matcher::neighbours;
  o.sfm.colmap = dir.file("no-such-colmap");
  std::ostringstream log;
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("planned pose"));
}

// Options for evaluating dir/photos against a cube (written here) into dir/eval, with a COLMAP
// that does not exist: for the checks that come before COLMAP runs.
EvalOptions photos_without_colmap(const rigc::testing::TempDir& dir) {
  write_cube_ply(dir.file("cube.ply"));
  EvalOptions o;
  o.photos_dir = dir.file("photos");
  o.ground_truth = dir.file("cube.ply");
  o.output_dir = dir.file("eval");
  o.sfm.colmap = dir.file("no-such-colmap");
  return o;
}

// COLMAP's extractor only logs a file it cannot read, and its matcher then aborts without naming
// it: eval reads every image's header first and names the ones that fail.
// The run's exact ground truth as the "COLMAP model", with one false match added: a point
// triangulated from two views, centimetres off the surface. Only --min-track 2 measures it.
TEST(EvalCommand, TwoViewPointsAreLeftOutOfTheMeasurement) {
  rigc::testing::TempDir dir;
  const auto run = test_inputs::make_statue_run(dir.path());
  ASSERT_TRUE(run);
  const fs::path model = dir.path() / "eval" / "colmap" / "model_txt";
  fs::create_directories(model);
  for (const char* name : {"cameras.txt", "images.txt", "points3D.txt"}) {
    fs::copy_file(run->dir / "sparse" / name, model / name);
  }
  std::string error;
  const auto truth = read_colmap_points(model / "points3D.txt", &error);
  ASSERT_TRUE(truth) << error;
  long long_tracks = 0, all = static_cast<long>(truth->size()) + 1;
  for (const auto& p : *truth) long_tracks += p.track_images.size() >= 3;
  ASSERT_GT(long_tracks, 1000);
  // Inside the statue's body, centimetres from its surface.
  Vec3 blunder = Vec3::Zero();
  for (const auto& p : *truth) blunder += p.position / static_cast<double>(truth->size());
  const Point3D& near = truth->front();
  std::ofstream(model / "points3D.txt", std::ios::app)
      << fmt::format("999999 {} {} {} 128 128 128 0.5 {} 0 {} 0\n", blunder.x(), blunder.y(),
                     blunder.z(), near.track_images.at(0), near.track_images.at(1));

  EvalOptions o;
  o.run_dir = run->dir.string();
  o.scene = run->scene_file.string();
  o.output_dir = (dir.path() / "eval").string();
  o.sfm.reuse_colmap = true;
  o.quiet = true;
  o.metrics.ground_truth_samples = 20000;
  std::ostringstream log;
  EvalSummary three;
  ASSERT_EQ(evaluate(o, log, &three), 0) << log.str();
  EXPECT_EQ(three.points, long_tracks);
  EXPECT_LT(three.std_mm, 0.05);
  EXPECT_EQ(three.report["reconstruction"]["points_in_model"], all);
  o.sfm.min_track_length = 2;
  EvalSummary two;
  ASSERT_EQ(evaluate(o, log, &two), 0) << log.str();
  EXPECT_EQ(two.points, all - static_cast<long>(std::count_if(
                                  truth->begin(), truth->end(),
                                  [](const Point3D& p) { return p.track_images.size() < 2; })));
  const auto& d = two.report["signed_distance_mm"];
  EXPECT_GT(std::max(-d["min"].get<double>(), d["max"].get<double>()), 10) << "the false match";
  EXPECT_GT(two.std_mm, 10 * three.std_mm);
}

TEST(EvalCommand, UnreadableImagesAreNamedBeforeColmapRuns) {
  rigc::testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  for (const char* name : {"a.jpg", "b.jpg", "d.png"})
    write_small_image(dir.file("photos/") + name);
  rigc::testing::write_text(dir.file("photos/c.jpg"), "not an image");
  const EvalOptions o = photos_without_colmap(dir);
  std::ostringstream log;
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("1 of the 4 images cannot be read"));
  EXPECT_THAT(log.str(), HasSubstr("c.jpg"));
  EXPECT_THAT(log.str(), Not(HasSubstr("d.png"))) << "a PNG is read too: " << log.str();
  EXPECT_FALSE(fs::exists(dir.path() / "eval")) << "nothing is written";
}

TEST(EvalCommand, ACameraFileThatDoesNotFitTheImagesIsAUserError) {
  rigc::testing::TempDir dir;
  fs::create_directories(dir.path() / "run" / "images");
  fs::create_directories(dir.path() / "run" / "sparse");
  for (const char* name : {"a.jpg", "b.jpg"}) write_small_image(dir.file("run/images/") + name);
  write_cube_ply(dir.file("cube.ply"));
  rigc::testing::write_text(dir.file("run/sparse/images.txt"),
                            "1 1 0 0 0 0 0 1 1 a.jpg\n\n2 1 0 0 0 0.1 0 1 1 b.jpg\n\n");
  EvalOptions o;
  o.run_dir = dir.file("run");
  o.ground_truth = dir.file("cube.ply");
  o.output_dir = dir.file("eval");
  o.sfm.colmap = dir.file("no-such-colmap");
  // The images are 64 x 64, the camera 64 x 3.
  rigc::testing::write_text(dir.file("run/sparse/cameras.txt"),
                            "1 OPENCV 64 3 80 80 32 32 0 0 0 0\n");
  std::ostringstream log;
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("a.jpg is 64x64 pixels, but"));
  EXPECT_THAT(log.str(), HasSubstr("gives the camera as 64x3"));
  EXPECT_FALSE(fs::exists(dir.path() / "eval")) << "a refused input leaves nothing behind";
  // An empty camera file is named (not a bare "rigc eval: error: ").
  rigc::testing::write_text(dir.file("run/sparse/cameras.txt"), "");
  log.str("");
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("cameras.txt lists no camera"));
  // Thumbnails are too small for SIFT: a user error, not COLMAP's failure.
  fs::create_directories(dir.path() / "tiny");
  for (const char* name : {"a.png", "b.png"}) write_small_image(dir.file("tiny/") + name, 1);
  o = EvalOptions{};
  o.photos_dir = dir.file("tiny");
  o.ground_truth = dir.file("cube.ply");
  o.sfm.colmap = dir.file("no-such-colmap");
  log.str("");
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("a.png is 1x1 pixels: too small"));
  // A photos folder that is not there is named as such.
  o = EvalOptions{};
  o.photos_dir = dir.file("nothere");
  o.ground_truth = dir.file("cube.ply");
  log.str("");
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("nothere does not exist"));
}

TEST(EvalCommand, ABrokenManifestIsNamedAndAnotherObjectIsWarnedAbout) {
  rigc::testing::TempDir dir;
  fs::create_directories(dir.path() / "run" / "images");
  for (const char* name : {"a.jpg", "b.jpg"}) write_small_image(dir.file("run/images/") + name);
  EvalOptions o;
  o.run_dir = dir.file("run");
  o.output_dir = dir.file("eval");
  o.sfm.colmap = dir.file("no-such-colmap");
  std::ostringstream log;
  rigc::testing::write_text(dir.file("run/manifest.json"), "{");
  EXPECT_EQ(evaluate(o, log, nullptr), 1);
  EXPECT_THAT(log.str(), HasSubstr("manifest.json is not valid JSON"));
  // Rendered from one object, measured against the paper scene's statue: said, then measured.
  o.scene = rigc::testing::source_path("scenes/paper-turntable.yaml");
  DiagnosticEngine diag;
  rigc::testing::silence_diagnostics(diag);
  auto paper = compile_scene_file(o.scene, diag);
  ASSERT_TRUE(paper);
  const std::string paper_hash = run::object_geometry_hash(*paper);
  auto scaled = *paper;  // the same mesh fitted 1 % taller: another ground truth
  scaled.object.object_from_mesh.topLeftCorner<3, 3>() *= 1.01;
  ASSERT_NE(run::object_geometry_hash(scaled), paper_hash);
  for (const std::string& hash : {paper_hash, std::string("0123")}) {
    rigc::testing::write_text(
        dir.file("run/manifest.json"),
        R"({"inputs": {"object_sha256": ")" + hash + R"(", "source_file": "x.yaml"}})");
    log.str("");
    EXPECT_EQ(evaluate(o, log, nullptr), 2) << log.str();  // then the missing COLMAP
    const bool warned = log.str().find("warning: the object of") != std::string::npos;
    EXPECT_EQ(warned, hash != paper_hash) << log.str();
  }
}

// 16-bit photos go to COLMAP as 8-bit copies; one whose header reads but whose pixels do not is
// the input's fault (exit 1), named, not a tool failure.
TEST(EvalCommand, ASixteenBitPhotoWithBrokenPixelsIsAUserError) {
  rigc::testing::TempDir dir;
  fs::create_directories(dir.path() / "photos");
  for (const char* name : {"a.png", "b.png"}) {
    const std::string path = dir.file("photos/") + name;
    const OIIO::ImageSpec spec(64, 64, 3, OIIO::TypeDesc::UINT16);
    std::vector<std::uint16_t> pixels(64 * 64 * 3);
    for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint16_t>(i * 977);
    auto out = OIIO::ImageOutput::create(path);
    ASSERT_TRUE(out && out->open(path, spec));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT16, pixels.data()));
    ASSERT_TRUE(out->close());
  }
  fs::resize_file(dir.path() / "photos" / "b.png",
                  fs::file_size(dir.path() / "photos" / "b.png") / 2);
  const EvalOptions o = photos_without_colmap(dir);
  std::ostringstream log;
  EXPECT_EQ(evaluate(o, log, nullptr), 1) << log.str();
  // The pre-check reads each photo's end (and last row), so a photo cut short is named before any
  // conversion.
  EXPECT_THAT(log.str(), HasSubstr("b.png: is cut short"));
}

}  // namespace
}  // namespace rigc::eval
