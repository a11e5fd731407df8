#include "eval/geometry.h"

#include <embree3/rtcore.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <mutex>
#include <nanoflann.hpp>
#include <random>

namespace rigc::eval {

namespace o3d = open3d;

namespace {

void quiet_open3d() {
  static std::once_flag once;
  std::call_once(once,
                 [] { o3d::utility::SetVerbosityLevel(o3d::utility::VerbosityLevel::Error); });
}

o3d::geometry::PointCloud to_cloud(const std::vector<Vec3>& points,
                                   const std::vector<Vec3>* normals = nullptr) {
  o3d::geometry::PointCloud cloud;
  cloud.points_.assign(points.begin(), points.end());
  if (normals) cloud.normals_.assign(normals->begin(), normals->end());
  return cloud;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Similarity

Mat4 Similarity::matrix() const {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = scale * rotation;
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Similarity Similarity::from_matrix(const Mat4& m) {
  Similarity s;
  const Eigen::Matrix3d a = m.topLeftCorner<3, 3>();
  s.scale = std::cbrt(a.determinant());
  s.rotation = a / s.scale;
  s.translation = m.topRightCorner<3, 1>();
  return s;
}

Similarity Similarity::inverse() const {
  Similarity s;
  s.scale = 1 / scale;
  s.rotation = rotation.transpose();
  s.translation = -s.scale * (s.rotation * translation);
  return s;
}

Similarity operator*(const Similarity& a, const Similarity& b) {
  Similarity s;
  s.scale = a.scale * b.scale;
  s.rotation = a.rotation * b.rotation;
  s.translation = a.scale * (a.rotation * b.translation) + a.translation;
  return s;
}

std::optional<Similarity> fit_similarity(const std::vector<Vec3>& src,
                                         const std::vector<Vec3>& dst) {
  if (src.size() < 3 || src.size() != dst.size()) return std::nullopt;
  Eigen::Matrix3Xd a(3, src.size()), b(3, dst.size());
  for (std::size_t i = 0; i < src.size(); ++i) {
    a.col(i) = src[i];
    b.col(i) = dst[i];
  }
  const Eigen::Matrix4d m = Eigen::umeyama(a, b, true);
  if (!m.allFinite()) return std::nullopt;
  Similarity s = Similarity::from_matrix(m);
  if (!(s.scale > 0) || !std::isfinite(s.scale)) return std::nullopt;
  return s;
}

std::optional<RobustSimilarity> fit_similarity_ransac(const std::vector<Vec3>& src,
                                                      const std::vector<Vec3>& dst,
                                                      double threshold, int iterations,
                                                      std::uint64_t seed) {
  const int n = static_cast<int>(src.size());
  if (n < 3 || src.size() != dst.size()) return std::nullopt;
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> pick(0, n - 1);
  auto inliers_of = [&](const Similarity& s) {
    std::vector<int> in;
    for (int i = 0; i < n; ++i) {
      if ((s.apply(src[i]) - dst[i]).norm() < threshold) in.push_back(i);
    }
    return in;
  };
  std::vector<int> best;
  // Small sets: try every triple; large ones: random triples.
  auto consider = [&](int i, int j, int k) {
    if (i == j || j == k || i == k) return;
    auto s = fit_similarity({src[i], src[j], src[k]}, {dst[i], dst[j], dst[k]});
    if (!s) return;
    std::vector<int> in = inliers_of(*s);
    if (in.size() > best.size()) best = std::move(in);
  };
  if (static_cast<long>(n) * (n - 1) * (n - 2) / 6 <= iterations) {
    for (int i = 0; i < n; ++i)
      for (int j = i + 1; j < n; ++j)
        for (int k = j + 1; k < n; ++k) consider(i, j, k);
  } else {
    for (int it = 0; it < iterations; ++it) consider(pick(rng), pick(rng), pick(rng));
  }
  if (best.size() < 3) return std::nullopt;
  // Refit on the inliers until the set stops changing.
  RobustSimilarity result;
  for (int round = 0; round < 5; ++round) {
    std::vector<Vec3> a, b;
    for (int i : best) {
      a.push_back(src[i]);
      b.push_back(dst[i]);
    }
    auto s = fit_similarity(a, b);
    if (!s) return std::nullopt;
    result.transform = *s;
    std::vector<int> in = inliers_of(*s);
    if (in.size() < 3 || in == best) break;
    best = std::move(in);
  }
  result.inliers = best;
  double sum = 0;
  for (int i : best) sum += (result.transform.apply(src[i]) - dst[i]).squaredNorm();
  result.rms_inlier_error = std::sqrt(sum / static_cast<double>(best.size()));
  return result;
}

Vec3 ViewCamera::center() const {
  const Eigen::Matrix3d r = camera_from_world.topLeftCorner<3, 3>();
  return -r.transpose() * camera_from_world.topRightCorner<3, 1>();
}

// ---------------------------------------------------------------------------------------------
// Surface

namespace {

// The point of triangle abc nearest to p (Ericson, Real-Time Collision Detection, 5.1.5): the
// Voronoi region of p decides between a vertex, an edge and the face.
Vec3 closest_point_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  }
  const double denom = 1 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// One nearest-triangle query: the query point in double precision and the best triangle so far.
struct NearestTriangle {
  const float* vertices;
  const unsigned* indices;
  Vec3 point;
  // Embree culls with the float query point: the radius carries this much extra so that no
  // triangle nearer than the best is culled by rounding.
  float slack = 0;
  double best_squared = std::numeric_limits<double>::infinity();
  double best_facing = -1;  // see facing(); -1 until a tie needs it
  unsigned triangle = RTC_INVALID_GEOMETRY_ID;
  Vec3 closest = Vec3::Zero();
  Vec3 normal = Vec3::Zero();  // of the best triangle, not normalized

  Vec3 vertex(unsigned i) const {
    const float* v = vertices + 3 * std::size_t{i};
    return Vec3(v[0], v[1], v[2]);
  }
};

// How squarely `point` lies in front of or behind a triangle's plane: |cos| of the angle between
// the normal and point - closest (0 when either is 0).
double facing(const Vec3& point, const Vec3& closest, const Vec3& normal) {
  const double length = (point - closest).norm() * normal.norm();
  return length > 0 ? std::abs((point - closest).dot(normal)) / length : 0;
}

// Embree calls this for every triangle in a BVH leaf the query sphere reaches; shrinking the
// radius culls the rest of the tree.
bool nearest_triangle_callback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<NearestTriangle*>(args->userPtr);
  const unsigned* t = q->indices + 3 * std::size_t{args->primID};
  const Vec3 a = q->vertex(t[0]), b = q->vertex(t[1]), c = q->vertex(t[2]);
  const Vec3 p = closest_point_on_triangle(q->point, a, b, c);
  const double squared = (q->point - p).squaredNorm();
  const double tie = 1e-9 * q->best_squared;
  if (squared > q->best_squared + tie) return false;
  const Vec3 normal = (b - a).cross(c - a);
  double facing_here = -1;
  if (squared >= q->best_squared - tie) {
    // Triangles meeting at the nearest edge or vertex tie (up to rounding) and may disagree on
    // the sign: the one the point lies most squarely in front of or behind wins, then the lower
    // index, so the answer depends neither on the traversal order nor on the threads.
    facing_here = facing(q->point, p, normal);
    if (q->best_facing < 0) q->best_facing = facing(q->point, q->closest, q->normal);
    if (facing_here < q->best_facing ||
        (facing_here == q->best_facing && args->primID > q->triangle)) {
      return false;
    }
  }
  q->best_squared = squared;
  q->best_facing = facing_here;
  q->triangle = args->primID;
  q->closest = p;
  q->normal = normal;
  // Rounded up and widened by the tie band and the slack, so that tied triangles stay in.
  const float radius =
      std::nextafter(static_cast<float>(std::sqrt(squared * (1 + 2e-9))) + q->slack,
                     std::numeric_limits<float>::infinity());
  if (radius >= args->query->radius) return false;
  args->query->radius = radius;
  return true;
}

// Indices of the finite `points` in Morton (Z-curve) order of a 1024^3 grid over their bounds.
std::vector<std::uint32_t> spatial_order(const std::vector<Vec3>& points) {
  Eigen::AlignedBox3d box;
  for (const Vec3& p : points) {
    if (p.allFinite()) box.extend(p);
  }
  if (box.isEmpty()) return {};
  const Vec3 scale = 1023.0 / box.sizes().cwiseMax(1e-300).array();
  // Spreads the low 10 bits of v to every third bit.
  auto spread = [](std::uint64_t v) {
    v &= 0x3ff;
    v = (v | (v << 16)) & 0x30000ff;
    v = (v | (v << 8)) & 0x300f00f;
    v = (v | (v << 4)) & 0x30c30c3;
    v = (v | (v << 2)) & 0x9249249;
    return v;
  };
  // Key: the cell's code above the point's index (unique keys: a deterministic order; clouds of
  // 2^32 points or more are not expected).
  std::vector<std::uint64_t> keys(points.size(), ~std::uint64_t{0});
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        if (!points[i].allFinite()) continue;
                        const Eigen::Array3d cell = (points[i] - box.min()).array() * scale.array();
                        const std::uint64_t code =
                            spread(static_cast<std::uint64_t>(cell.x())) |
                            spread(static_cast<std::uint64_t>(cell.y())) << 1 |
                            spread(static_cast<std::uint64_t>(cell.z())) << 2;
                        keys[i] = code << 32 | i;
                      }
                    });
  tbb::parallel_sort(keys.begin(), keys.end());
  std::vector<std::uint32_t> order;
  order.reserve(keys.size());
  for (std::uint64_t key : keys) {
    if (key != ~std::uint64_t{0}) order.push_back(static_cast<std::uint32_t>(key));
  }
  return order;
}

}  // namespace

// One Embree BVH answers both ray casts and nearest-triangle queries (rtcPointQuery). The
// Open3D mesh is kept only for its area-uniform sampler: Debian's Open3D 0.16 build returns no
// hits from RaycastingScene's CastRays/TestOcclusions.
struct Surface::Impl {
  std::shared_ptr<o3d::geometry::TriangleMesh> legacy;  // with triangle normals, for sampling
  Eigen::AlignedBox3d box;
  std::size_t triangle_count = 0;
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  // Embree's own copies (alive as long as the scene), read by the nearest-triangle callback.
  const float* vertices = nullptr;
  const unsigned* indices = nullptr;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }

  void build_scene(const std::vector<Eigen::Vector3f>& positions,
                   const std::vector<std::array<std::uint32_t, 3>>& triangles) {
    device = rtcNewDevice(nullptr);
    scene = rtcNewScene(device);
    RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), positions.size()));
    for (std::size_t i = 0; i < positions.size(); ++i) {
      for (int k = 0; k < 3; ++k) v[3 * i + k] = positions[i][k];
    }
    auto* f = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
        g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), triangles.size()));
    for (std::size_t i = 0; i < triangles.size(); ++i) {
      for (int k = 0; k < 3; ++k) f[3 * i + k] = triangles[i][k];
    }
    vertices = v;
    indices = f;
    triangle_count = triangles.size();
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
  }

  static RTCRay make_ray(const Vec3& o, const Vec3& d, float tnear, float tfar) {
    RTCRay r;
    r.org_x = static_cast<float>(o.x());
    r.org_y = static_cast<float>(o.y());
    r.org_z = static_cast<float>(o.z());
    r.dir_x = static_cast<float>(d.x());
    r.dir_y = static_cast<float>(d.y());
    r.dir_z = static_cast<float>(d.z());
    r.tnear = tnear;
    r.tfar = tfar;
    r.time = 0;
    r.mask = 0xffffffffu;
    r.id = 0;
    r.flags = 0;
    return r;
  }
};

Surface::Surface(const std::vector<Eigen::Vector3f>& positions,
                 const std::vector<std::array<std::uint32_t, 3>>& triangles)
    : impl_(std::make_unique<Impl>()) {
  quiet_open3d();
  impl_->build_scene(positions, triangles);
  for (const auto& p : positions) impl_->box.extend(p.cast<double>());
  auto& legacy = impl_->legacy = std::make_shared<o3d::geometry::TriangleMesh>();
  legacy->vertices_.resize(positions.size());
  legacy->triangles_.resize(triangles.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, positions.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        legacy->vertices_[i] = positions[i].cast<double>();
                      }
                    });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, triangles.size(), 1 << 14),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        const auto& t = triangles[i];
                        legacy->triangles_[i] = Eigen::Vector3i(
                            static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2]));
                      }
                    });
  // Once here, so that sampling neither copies the mesh nor writes to it.
  legacy->ComputeTriangleNormals(true);
}

Surface::~Surface() = default;

std::size_t Surface::triangle_count() const {
  return impl_->triangle_count;
}

double Surface::area() const {
  return impl_->legacy->GetSurfaceArea();
}

Eigen::AlignedBox3d Surface::bounds() const {
  return impl_->box;
}

std::vector<double> Surface::signed_distance(const std::vector<Vec3>& points) const {
  std::vector<double> out(points.size(), std::numeric_limits<double>::quiet_NaN());
  if (points.empty() || impl_->triangle_count == 0) return out;
  // Queries in Z-curve order share BVH nodes in cache, and each starts from its predecessor's
  // triangle as an upper bound. Blocks of fixed size (not TBB's ranges) keep that chain, and so
  // the answers, independent of the scheduling.
  const std::vector<std::uint32_t> order = spatial_order(points);
  const std::size_t block = 256;
  tbb::parallel_for(std::size_t{0}, (order.size() + block - 1) / block, [&](std::size_t b) {
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    unsigned previous = RTC_INVALID_GEOMETRY_ID;
    for (std::size_t k = b * block; k < std::min(order.size(), (b + 1) * block); ++k) {
      const std::size_t i = order[k];
      NearestTriangle nearest{impl_->vertices, impl_->indices, points[i]};
      RTCPointQuery query;
      query.x = static_cast<float>(points[i].x());
      query.y = static_cast<float>(points[i].y());
      query.z = static_cast<float>(points[i].z());
      nearest.slack = 4 * std::numeric_limits<float>::epsilon() *
                      (std::abs(query.x) + std::abs(query.y) + std::abs(query.z));
      query.time = 0;
      query.radius = std::numeric_limits<float>::infinity();
      if (previous != RTC_INVALID_GEOMETRY_ID) {
        RTCPointQueryFunctionArguments hint{};
        hint.query = &query;
        hint.userPtr = &nearest;
        hint.primID = previous;
        nearest_triangle_callback(&hint);
      }
      rtcPointQuery(impl_->scene, &query, &context, nearest_triangle_callback, &nearest);
      if (nearest.triangle == RTC_INVALID_GEOMETRY_ID) continue;
      previous = nearest.triangle;
      const double distance = std::sqrt(nearest.best_squared);
      out[i] = (points[i] - nearest.closest).dot(nearest.normal) < 0 ? -distance : distance;
    }
  });
  return out;
}

void Surface::sample(int count, std::uint64_t seed, std::vector<Vec3>* points,
                     std::vector<Vec3>* normals) const {
  static std::mutex seed_mutex;  // Open3D's generator is global
  std::shared_ptr<o3d::geometry::PointCloud> cloud;
  {
    std::lock_guard<std::mutex> lock(seed_mutex);
    o3d::utility::random::Seed(static_cast<int>(seed & 0x7fffffff));
    // The mesh already has its triangle normals, so Open3D only reads it.
    cloud =
        impl_->legacy->SamplePointsUniformly(static_cast<std::size_t>(std::max(count, 0)), true);
  }
  points->assign(cloud->points_.begin(), cloud->points_.end());
  if (normals) normals->assign(cloud->normals_.begin(), cloud->normals_.end());
}

std::vector<int> Surface::visible(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                  const std::vector<ViewCamera>& cameras) const {
  const double offset = 1e-6 * std::max(impl_->box.diagonal().norm(), 1e-9);
  std::vector<Vec3> eyes;
  for (const ViewCamera& cam : cameras) eyes.push_back(cam.center());
  auto sees = [&](std::size_t c, std::size_t i, RTCIntersectContext* context) {
    const ViewCamera& cam = cameras[c];
    if ((eyes[c] - points[i]).dot(normals[i]) <= 0) return false;  // back-facing
    const Vec3 pc = cam.camera_from_world.topLeftCorner<3, 3>() * points[i] +
                    cam.camera_from_world.topRightCorner<3, 1>();
    if (pc.z() <= 0) return false;
    const double u = cam.fx * pc.x() / pc.z() + cam.cx;
    const double v = cam.fy * pc.y() / pc.z() + cam.cy;
    if (u < 0 || v < 0 || u >= cam.width || v >= cam.height) return false;
    const Vec3 origin = points[i] + offset * normals[i];
    RTCRay ray = Impl::make_ray(origin, eyes[c] - origin, 1e-5f, 1.0f);
    rtcOccluded1(impl_->scene, context, &ray);
    return ray.tfar >= 0;  // tfar becomes -inf when something is hit
  };
  // Each point tries the cameras until one sees it and writes only its own flag: the answer
  // does not depend on the scheduling.
  std::vector<char> seen(points.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 256),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      RTCIntersectContext context;
                      rtcInitIntersectContext(&context);
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        for (std::size_t c = 0; c < cameras.size() && !seen[i]; ++c) {
                          seen[i] = sees(c, i, &context);
                        }
                      }
                    });
  std::vector<int> out;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (seen[i]) out.push_back(static_cast<int>(i));
  }
  return out;
}

RayHits Surface::cast_rays(const std::vector<Vec3>& origins,
                           const std::vector<Vec3>& directions) const {
  RayHits hits;
  if (origins.empty()) return hits;
  hits.t.assign(origins.size(), std::numeric_limits<float>::infinity());
  hits.normals.assign(origins.size(), Eigen::Vector3f::Zero());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, origins.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      RTCIntersectContext context;
                      rtcInitIntersectContext(&context);
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        RTCRayHit rh;
                        rh.ray = Impl::make_ray(origins[i], directions[i], 0.0f,
                                                std::numeric_limits<float>::infinity());
                        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
                        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
                        rtcIntersect1(impl_->scene, &context, &rh);
                        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
                        hits.t[i] = rh.ray.tfar;
                        hits.normals[i] =
                            Eigen::Vector3f(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z).normalized();
                      }
                    });
  return hits;
}

// ---------------------------------------------------------------------------------------------
// Registration, distances, meshing

IcpResult icp_point_to_plane(const std::vector<Vec3>& source, const std::vector<Vec3>& target,
                             const std::vector<Vec3>& target_normals,
                             double max_correspondence_distance, int max_iterations) {
  quiet_open3d();
  namespace reg = o3d::pipelines::registration;
  const auto src = to_cloud(source);
  const auto tgt = to_cloud(target, &target_normals);
  const reg::RegistrationResult r =
      reg::RegistrationICP(src, tgt, max_correspondence_distance, Eigen::Matrix4d::Identity(),
                           reg::TransformationEstimationPointToPlane(),
                           reg::ICPConvergenceCriteria(1e-7, 1e-7, max_iterations));
  IcpResult out;
  out.transform = r.transformation_;
  out.fitness = r.fitness_;
  out.inlier_rmse = r.inlier_rmse_;
  out.correspondences = static_cast<int>(r.correspondence_set_.size());
  return out;
}

IcpResult icp_similarity(const std::vector<Vec3>& source, const std::vector<Vec3>& target,
                         double max_correspondence_distance, int max_iterations) {
  quiet_open3d();
  namespace reg = o3d::pipelines::registration;
  const auto src = to_cloud(source);
  const auto tgt = to_cloud(target);
  const reg::RegistrationResult r =
      reg::RegistrationICP(src, tgt, max_correspondence_distance, Eigen::Matrix4d::Identity(),
                           reg::TransformationEstimationPointToPoint(true),
                           reg::ICPConvergenceCriteria(1e-7, 1e-7, max_iterations));
  IcpResult out;
  out.transform = r.transformation_;
  out.fitness = r.fitness_;
  out.inlier_rmse = r.inlier_rmse_;
  out.correspondences = static_cast<int>(r.correspondence_set_.size());
  return out;
}

std::optional<Mat4> global_registration(const std::vector<Vec3>& source,
                                        const std::vector<Vec3>& target, double voxel_size,
                                        unsigned seed) {
  quiet_open3d();
  namespace reg = o3d::pipelines::registration;
  auto src = to_cloud(source).VoxelDownSample(voxel_size);
  auto tgt = to_cloud(target).VoxelDownSample(voxel_size);
  if (src->points_.size() < 10 || tgt->points_.size() < 10) return std::nullopt;
  const o3d::geometry::KDTreeSearchParamHybrid normal_param(2 * voxel_size, 30);
  src->EstimateNormals(normal_param);
  tgt->EstimateNormals(normal_param);
  const o3d::geometry::KDTreeSearchParamHybrid feature_param(5 * voxel_size, 100);
  auto src_fpfh = reg::ComputeFPFHFeature(*src, feature_param);
  auto tgt_fpfh = reg::ComputeFPFHFeature(*tgt, feature_param);
  const double distance = 1.5 * voxel_size;
  reg::CorrespondenceCheckerBasedOnEdgeLength edge(0.9);
  reg::CorrespondenceCheckerBasedOnDistance dist(distance);
  o3d::utility::random::Seed(static_cast<int>(seed));
  const reg::RegistrationResult r = reg::RegistrationRANSACBasedOnFeatureMatching(
      *src, *tgt, *src_fpfh, *tgt_fpfh, true, distance,
      reg::TransformationEstimationPointToPoint(false), 3, {edge, dist},
      reg::RANSACConvergenceCriteria(100000, 0.999));
  if (r.fitness_ <= 0) return std::nullopt;
  return Mat4(r.transformation_);
}

namespace {

// nanoflann's view of a span of a point vector (no copy).
struct CloudAdaptor {
  const Vec3* points;
  std::size_t count;
  std::size_t kdtree_get_point_count() const { return count; }
  double kdtree_get_pt(std::size_t i, std::size_t axis) const { return points[i][axis]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using KdTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, CloudAdaptor>,
                                        CloudAdaptor, 3, std::size_t>;

}  // namespace

std::vector<double> nearest_distances(const std::vector<Vec3>& queries,
                                      const std::vector<Vec3>& cloud) {
  std::vector<double> out(queries.size(), std::numeric_limits<double>::infinity());
  if (cloud.empty() || queries.empty()) return out;
  // nanoflann builds a tree on one thread: large clouds get one tree per part, built side by
  // side, and each query takes the nearest of the parts' answers (the same distance).
  const std::size_t parts = std::clamp<std::size_t>(cloud.size() / 500000, 1, 8);
  const std::size_t part_size = (cloud.size() + parts - 1) / parts;
  std::vector<CloudAdaptor> adaptors;
  for (std::size_t first = 0; first < cloud.size(); first += part_size) {
    adaptors.push_back({cloud.data() + first, std::min(part_size, cloud.size() - first)});
  }
  std::vector<std::unique_ptr<KdTree>> trees(adaptors.size());
  tbb::parallel_for(std::size_t{0}, adaptors.size(), [&](std::size_t k) {
    trees[k] = std::make_unique<KdTree>(3, adaptors[k],
                                        nanoflann::KDTreeSingleIndexAdaptorParams(20));  // builds
  });
  // Queries are const on the trees; each writes only its own entry.
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, queries.size(), 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i < range.end(); ++i) {
                        double best = std::numeric_limits<double>::infinity();
                        for (const auto& tree : trees) {
                          std::size_t nearest = 0;
                          double squared = 0;
                          nanoflann::KNNResultSet<double, std::size_t> result(1);
                          result.init(&nearest, &squared);
                          tree->findNeighbors(result, queries[i].data(), nanoflann::SearchParams());
                          best = std::min(best, squared);
                        }
                        out[i] = std::sqrt(best);
                      }
                    });
  return out;
}

std::optional<PoissonMesh> poisson_mesh(const std::vector<Vec3>& points,
                                        const std::vector<Vec3>& view_points, int depth,
                                        std::string* error) {
  quiet_open3d();
  if (points.size() < 100) {
    *error = "too few points to mesh (fewer than 100)";
    return std::nullopt;
  }
  auto cloud = to_cloud(points);
  cloud.EstimateNormals(o3d::geometry::KDTreeSearchParamKNN(20));
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 towards = (i < view_points.size() ? view_points[i] : Vec3::Zero()) - points[i];
    if (cloud.normals_[i].dot(towards) < 0) cloud.normals_[i] = -cloud.normals_[i];
  }
  auto [mesh, densities] =
      o3d::geometry::TriangleMesh::CreateFromPointCloudPoisson(cloud, depth, 0.0f, 1.1f, false);
  if (!mesh || mesh->triangles_.empty()) {
    *error = "Poisson reconstruction produced no triangles";
    return std::nullopt;
  }
  // Trim the surface Poisson invents far from the samples: the lowest 10 % of densities.
  std::vector<double> sorted = densities;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 10, sorted.end());
  const double cut = sorted[sorted.size() / 10];
  std::vector<bool> remove(densities.size());
  for (std::size_t i = 0; i < densities.size(); ++i) remove[i] = densities[i] < cut;
  mesh->RemoveVerticesByMask(remove);
  PoissonMesh out;
  for (const auto& v : mesh->vertices_) out.positions.push_back(v.cast<float>());
  for (const auto& t : mesh->triangles_) {
    out.triangles.push_back({static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
                             static_cast<std::uint32_t>(t[2])});
  }
  return out;
}

}  // namespace rigc::eval
