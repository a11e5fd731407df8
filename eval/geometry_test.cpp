// Nearest-triangle and nearest-point queries against exact answers, their sign at shared edges and
// vertices, and independence from the thread count; percentiles against a sorted copy.
#include "eval/geometry.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "eval/metrics.h"

namespace rigc::eval {
namespace {

using Triangles = std::vector<std::array<std::uint32_t, 3>>;

// The box [-h, h]^3 as 12 outward-facing triangles.
void box_mesh(float h, std::vector<Eigen::Vector3f>* v, Triangles* t) {
  for (int i = 0; i < 8; ++i) v->emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    t->push_back({q[0], q[1], q[2]});
    t->push_back({q[0], q[2], q[3]});
  }
}

// Exact signed distance to the box [-h, h]^3.
double box_distance(const Vec3& p, double h) {
  const Vec3 d = p.cwiseAbs() - Vec3::Constant(h);
  return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
}

TEST(EvalDistance, MatchesTheExactBoxDistanceEverywhere) {
  std::vector<Eigen::Vector3f> v;
  Triangles t;
  box_mesh(0.5f, &v, &t);
  const Surface surface(v, t);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.5, 1.5);
  std::vector<Vec3> points;
  for (int i = 0; i < 20000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  points.emplace_back(0.5, 0.5, 0.5);  // on a corner
  points.emplace_back(NAN, 0, 0);
  const std::vector<double> d = surface.signed_distance(points);
  ASSERT_EQ(d.size(), points.size());
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    ASSERT_NEAR(d[i], box_distance(points[i], 0.5), 1e-9) << points[i].transpose();
  }
  EXPECT_TRUE(std::isnan(d.back()));
}

TEST(EvalDistance, SharedVertexTakesTheSignOfTheFaceThePointIsMostInFrontOf) {
  // A square pyramid with a sharp apex at z = 1; the face whose normal points to -x comes first,
  // so "first" or "lowest index" alone would pick it.
  const std::vector<Eigen::Vector3f> v = {
      {-0.1f, -0.1f, 0}, {0.1f, -0.1f, 0}, {0.1f, 0.1f, 0}, {-0.1f, 0.1f, 0}, {0, 0, 1}};
  const Triangles t = {{3, 0, 4}, {0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {0, 3, 2}, {0, 2, 1}};
  const Surface surface(v, t);
  // Above the apex and slightly towards +x: the apex is nearest, and the -x face's plane is on
  // the wrong side of the point.
  const std::vector<double> d = surface.signed_distance({Vec3(0.05, 0, 1.2), Vec3(0, 0, 0.5)});
  EXPECT_NEAR(d[0], std::sqrt(0.05 * 0.05 + 0.2 * 0.2), 1e-9);
  EXPECT_LT(d[1], 0);  // inside
}

TEST(EvalDistance, ResultsDoNotDependOnTheThreadCount) {
  std::vector<Eigen::Vector3f> v;
  Triangles t;
  box_mesh(0.5f, &v, &t);
  const Surface surface(v, t);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> points, cloud;
  for (int i = 0; i < 50000; ++i) points.emplace_back(u(rng), u(rng), u(rng));
  for (int i = 0; i < 20000; ++i) cloud.emplace_back(u(rng), u(rng), u(rng));
  std::vector<double> one_thread, one_thread_nearest;
  {
    const tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    one_thread = surface.signed_distance(points);
    one_thread_nearest = nearest_distances(points, cloud);
  }
  EXPECT_EQ(surface.signed_distance(points), one_thread);
  EXPECT_EQ(nearest_distances(points, cloud), one_thread_nearest);
}

TEST(EvalDistance, NearestDistancesMatchBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> queries, cloud;
  for (int i = 0; i < 300; ++i) queries.emplace_back(u(rng), u(rng), u(rng));
  // Small clouds get one tree; large ones a tree per part (here three), queried in turn.
  for (const int cloud_size : {2000, 1600000}) {
    cloud.clear();
    for (int i = 0; i < cloud_size; ++i) cloud.emplace_back(u(rng), u(rng), u(rng));
    const std::vector<double> d = nearest_distances(queries, cloud);
    ASSERT_EQ(d.size(), queries.size());
    for (std::size_t i = 0; i<queries.size(); i += cloud_size> 2000 ? 10 : 1) {
      double best = std::numeric_limits<double>::infinity();
      for (const Vec3& c : cloud) best = std::min(best, (queries[i] - c).norm());
      EXPECT_DOUBLE_EQ(d[i], best) << cloud_size;
    }
  }
  EXPECT_TRUE(std::isinf(nearest_distances(queries, {}).front()));
}

TEST(EvalDistance, PercentilesEqualThoseOfASortedCopy) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.1, 1);
  for (std::size_t n : {1u, 2u, 7u, 10u, 1001u}) {
    std::vector<double> d;
    for (std::size_t i = 0; i < n; ++i) d.push_back(g(rng));
    std::vector<double> sorted = d, absolute;
    std::sort(sorted.begin(), sorted.end());
    for (double x : d) absolute.push_back(std::abs(x));
    std::sort(absolute.begin(), absolute.end());
    auto at = [](const std::vector<double>& s, double q) {
      const double pos = q * static_cast<double>(s.size() - 1);
      const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
      const std::size_t hi = std::min(lo + 1, s.size() - 1);
      return s[lo] * (1 - (pos - lo)) + s[hi] * (pos - lo);
    };
    const DistanceStats s = distance_stats(d);
    EXPECT_EQ(s.median, at(sorted, 0.5)) << n;
    EXPECT_EQ(s.p90_abs, at(absolute, 0.9)) << n;
    EXPECT_EQ(s.min, sorted.front());
    EXPECT_EQ(s.max, sorted.back());
  }
}

}  // namespace
}  // namespace rigc::eval
