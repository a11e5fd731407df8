#include "eval/geometry.h"

#include <embree3/rtcore.h>
#include <open3d/geometry/KDTreeSearchParam.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/geometry/TriangleMesh.h>
#include <open3d/pipelines/registration/CorrespondenceChecker.h>
#include <open3d/pipelines/registration/Feature.h>
#include <open3d/pipelines/registration/Registration.h>
#include <open3d/pipelines/registration/TransformationEstimation.h>
#include <open3d/t/geometry/RaycastingScene.h>
#include <open3d/utility/Logging.h>
#include <open3d/utility/Random.h>
#include <tbb/parallel_for.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <random>

namespace rigc::eval {

namespace o3d = open3d;
using o3d::core::Tensor;

namespace {

void quiet_open3d() {
  static std::once_flag once;
  std::call_once(once,
                 [] { o3d::utility::SetVerbosityLevel(o3d::utility::VerbosityLevel::Error); });
}

Tensor points_tensor(const std::vector<Vec3>& points) {
  std::vector<float> flat(points.size() * 3);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (int k = 0; k < 3; ++k) flat[3 * i + k] = static_cast<float>(points[i][k]);
  }
  return Tensor(std::move(flat), {static_cast<int64_t>(points.size()), 3}, o3d::core::Float32);
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

// Nearest-triangle queries through Open3D's RaycastingScene; rays through Embree directly
// (Debian's Open3D 0.16 build returns no hits from CastRays/TestOcclusions).
struct Surface::Impl {
  o3d::t::geometry::RaycastingScene scene;
  std::shared_ptr<o3d::geometry::TriangleMesh> legacy;
  RTCDevice device = nullptr;
  RTCScene rays = nullptr;

  ~Impl() {
    if (rays) rtcReleaseScene(rays);
    if (device) rtcReleaseDevice(device);
  }

  void build_rays(const std::vector<Eigen::Vector3f>& positions,
                  const std::vector<std::array<std::uint32_t, 3>>& triangles) {
    device = rtcNewDevice(nullptr);
    rays = rtcNewScene(device);
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
    rtcCommitGeometry(g);
    rtcAttachGeometry(rays, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(rays);
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
  std::vector<float> v(positions.size() * 3);
  for (std::size_t i = 0; i < positions.size(); ++i) {
    for (int k = 0; k < 3; ++k) v[3 * i + k] = positions[i][k];
  }
  std::vector<std::uint32_t> f(triangles.size() * 3);
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    for (int k = 0; k < 3; ++k) f[3 * i + k] = triangles[i][k];
  }
  impl_->scene.AddTriangles(
      Tensor(std::move(v), {static_cast<int64_t>(positions.size()), 3}, o3d::core::Float32),
      Tensor(std::move(f), {static_cast<int64_t>(triangles.size()), 3}, o3d::core::UInt32));
  impl_->build_rays(positions, triangles);
  impl_->legacy = std::make_shared<o3d::geometry::TriangleMesh>();
  impl_->legacy->vertices_.reserve(positions.size());
  for (const auto& p : positions) impl_->legacy->vertices_.push_back(p.cast<double>());
  impl_->legacy->triangles_.reserve(triangles.size());
  for (const auto& t : triangles) {
    impl_->legacy->triangles_.emplace_back(static_cast<int>(t[0]), static_cast<int>(t[1]),
                                           static_cast<int>(t[2]));
  }
}

Surface::~Surface() = default;

std::size_t Surface::triangle_count() const {
  return impl_->legacy->triangles_.size();
}

double Surface::area() const {
  return impl_->legacy->GetSurfaceArea();
}

Eigen::AlignedBox3d Surface::bounds() const {
  Eigen::AlignedBox3d box;
  for (const auto& p : impl_->legacy->vertices_) box.extend(p);
  return box;
}

std::vector<double> Surface::signed_distance(const std::vector<Vec3>& points) const {
  std::vector<double> out(points.size(), std::numeric_limits<double>::quiet_NaN());
  if (points.empty()) return out;
  auto result = impl_->scene.ComputeClosestPoints(points_tensor(points));
  const Tensor closest = result["points"].Contiguous();
  const Tensor normals = result["primitive_normals"].Contiguous();
  const float* c = closest.GetDataPtr<float>();
  const float* nrm = normals.GetDataPtr<float>();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 q(c[3 * i], c[3 * i + 1], c[3 * i + 2]);
    const Vec3 n(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
    const Vec3 d = points[i] - q;
    const double dist = d.norm();
    out[i] = d.dot(n) < 0 ? -dist : dist;
  }
  return out;
}

void Surface::sample(int count, std::uint64_t seed, std::vector<Vec3>* points,
                     std::vector<Vec3>* normals) const {
  static std::mutex seed_mutex;  // Open3D's generator is global
  std::shared_ptr<o3d::geometry::PointCloud> cloud;
  {
    std::lock_guard<std::mutex> lock(seed_mutex);
    o3d::utility::random::Seed(static_cast<int>(seed & 0x7fffffff));
    auto mesh = std::make_shared<o3d::geometry::TriangleMesh>(*impl_->legacy);
    mesh->ComputeTriangleNormals(true);
    cloud = mesh->SamplePointsUniformly(static_cast<std::size_t>(std::max(count, 0)), true);
  }
  points->assign(cloud->points_.begin(), cloud->points_.end());
  if (normals) normals->assign(cloud->normals_.begin(), cloud->normals_.end());
}

std::vector<int> Surface::visible(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                                  const std::vector<ViewCamera>& cameras) const {
  std::vector<char> seen(points.size(), 0);
  const Eigen::AlignedBox3d box = bounds();
  const double offset = 1e-6 * std::max(box.diagonal().norm(), 1e-9);
  for (const ViewCamera& cam : cameras) {
    const Vec3 eye = cam.center();
    std::vector<int> candidates;
    std::vector<Vec3> origins, directions;
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (seen[i]) continue;
      const Vec3 to_eye = eye - points[i];
      if (to_eye.dot(normals[i]) <= 0) continue;  // back-facing
      const Vec3 pc = cam.camera_from_world.topLeftCorner<3, 3>() * points[i] +
                      cam.camera_from_world.topRightCorner<3, 1>();
      if (pc.z() <= 0) continue;
      const double u = cam.fx * pc.x() / pc.z() + cam.cx;
      const double v = cam.fy * pc.y() / pc.z() + cam.cy;
      if (u < 0 || v < 0 || u >= cam.width || v >= cam.height) continue;
      candidates.push_back(static_cast<int>(i));
      const Vec3 origin = points[i] + offset * normals[i];
      origins.push_back(origin);
      directions.push_back(eye - origin);
    }
    if (candidates.empty()) continue;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, candidates.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
                        RTCIntersectContext context;
                        rtcInitIntersectContext(&context);
                        for (std::size_t k = range.begin(); k < range.end(); ++k) {
                          RTCRay ray = Impl::make_ray(origins[k], directions[k], 1e-5f, 1.0f);
                          rtcOccluded1(impl_->rays, &context, &ray);
                          // tfar becomes -inf when something is hit.
                          if (ray.tfar >= 0) seen[candidates[k]] = 1;
                        }
                      });
  }
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
                        rtcIntersect1(impl_->rays, &context, &rh);
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
                                        const std::vector<Vec3>& target, double voxel_size) {
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
  o3d::utility::random::Seed(1);
  const reg::RegistrationResult r = reg::RegistrationRANSACBasedOnFeatureMatching(
      *src, *tgt, *src_fpfh, *tgt_fpfh, true, distance,
      reg::TransformationEstimationPointToPoint(false), 3, {edge, dist},
      reg::RANSACConvergenceCriteria(100000, 0.999));
  if (r.fitness_ <= 0) return std::nullopt;
  return Mat4(r.transformation_);
}

std::vector<double> nearest_distances(const std::vector<Vec3>& queries,
                                      const std::vector<Vec3>& cloud) {
  quiet_open3d();
  if (cloud.empty()) {
    return std::vector<double>(queries.size(), std::numeric_limits<double>::infinity());
  }
  auto q = to_cloud(queries);
  const auto c = to_cloud(cloud);
  return q.ComputePointCloudDistance(c);
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
