// Geometry for evaluation: similarity alignment (Eigen's Umeyama inside RANSAC); a ground-truth
// surface whose Embree BVH answers nearest-triangle queries (rtcPointQuery) and ray casts, sampled
// area-uniformly by Open3D; nearest-point distances through a nanoflann KD-tree; ICP, global
// registration and Poisson meshing from Open3D. No Open3D, Embree or nanoflann type appears here.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace rigc::eval {

using ir::Mat4;
using ir::Vec3;

// x -> scale * R * x + t.
struct Similarity {
  double scale = 1;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3 translation = Vec3::Zero();

  Vec3 apply(const Vec3& x) const { return scale * (rotation * x) + translation; }
  Mat4 matrix() const;
  static Similarity from_matrix(const Mat4& m);  // scale from the cube root of det
  Similarity inverse() const;
  // (a * b)(x) = a(b(x)).
  friend Similarity operator*(const Similarity& a, const Similarity& b);
};

// Least-squares similarity dst ≈ S(src) (Umeyama, through Eigen::umeyama); needs 3+ points.
std::optional<Similarity> fit_similarity(const std::vector<Vec3>& src,
                                         const std::vector<Vec3>& dst);

struct RobustSimilarity {
  Similarity transform;
  std::vector<int> inliers;  // indices into the correspondences
  double rms_inlier_error = 0;
};

// RANSAC over minimal 3-point samples, then a least-squares refit on the inliers. A pair is an
// inlier when |S(src) - dst| < threshold (dst units). nullopt when fewer than 3 pairs or no
// sample gets 3 inliers.
std::optional<RobustSimilarity> fit_similarity_ransac(const std::vector<Vec3>& src,
                                                      const std::vector<Vec3>& dst,
                                                      double threshold, int iterations = 1000,
                                                      std::uint64_t seed = 1);

// A camera to test visibility or render from: COLMAP's camera_from_world and pinhole intrinsics
// (lens distortion ignored: it moves points by a few pixels at most).
struct ViewCamera {
  Mat4 camera_from_world = Mat4::Identity();
  int width = 0, height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  Vec3 center() const;
};

struct RayHits {
  std::vector<float> t;  // inf where the ray misses
  std::vector<Eigen::Vector3f> normals;
};

struct IcpResult {
  Mat4 transform = Mat4::Identity();  // rigid, applied to the source points
  double fitness = 0;                 // fraction of points with a correspondence
  double inlier_rmse = 0;
  int correspondences = 0;
};

// The ground-truth triangle mesh, ready for queries. Thread-safe for concurrent const calls.
class Surface {
 public:
  // positions and triangles in one frame (meters for a rendered run).
  Surface(const std::vector<Eigen::Vector3f>& positions,
          const std::vector<std::array<std::uint32_t, 3>>& triangles);
  ~Surface();
  Surface(const Surface&) = delete;
  Surface& operator=(const Surface&) = delete;

  std::size_t triangle_count() const;
  double area() const;
  Eigen::AlignedBox3d bounds() const;

  // Distance to the nearest triangle, signed by that triangle's normal (CloudCompare's
  // point-to-mesh convention): positive on the side the normal points to (outside for a mesh
  // with outward normals), negative inside. When the nearest point is on an edge or vertex that
  // several triangles share, the triangle the point lies most squarely in front of or behind
  // gives the sign. NaN for non-finite points. Parallel; the result does not depend on threads.
  std::vector<double> signed_distance(const std::vector<Vec3>& points) const;

  // Area-uniform samples on the surface with their triangle normals (deterministic for a seed).
  void sample(int count, std::uint64_t seed, std::vector<Vec3>* points,
              std::vector<Vec3>* normals) const;

  // Indices of `points` (on the surface, with outward `normals`) that at least one camera sees:
  // in front, inside its image, facing it, and not occluded by the surface.
  std::vector<int> visible(const std::vector<Vec3>& points, const std::vector<Vec3>& normals,
                           const std::vector<ViewCamera>& cameras) const;

  // First hits of rays origin + t·direction, t > 0.
  RayHits cast_rays(const std::vector<Vec3>& origins, const std::vector<Vec3>& directions) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Rigid point-to-plane ICP of `source` onto `target` (with normals), from the identity.
IcpResult icp_point_to_plane(const std::vector<Vec3>& source, const std::vector<Vec3>& target,
                             const std::vector<Vec3>& target_normals,
                             double max_correspondence_distance, int max_iterations = 50);
// Point-to-point ICP that also estimates a scale (for clouds of unknown scale).
IcpResult icp_similarity(const std::vector<Vec3>& source, const std::vector<Vec3>& target,
                         double max_correspondence_distance, int max_iterations = 50);

// Global registration for clouds in unknown relative pose (same scale): FPFH features and RANSAC
// on voxel-downsampled copies, RANSAC's samples drawn from `seed`. Returns the rigid transform
// applied to `source`.
std::optional<Mat4> global_registration(const std::vector<Vec3>& source,
                                        const std::vector<Vec3>& target, double voxel_size,
                                        unsigned seed = 1);

// For every query point, the distance to the nearest point of `cloud` (KD-tree; parallel).
std::vector<double> nearest_distances(const std::vector<Vec3>& queries,
                                      const std::vector<Vec3>& cloud);

// Screened Poisson surface reconstruction of oriented points (normals estimated and oriented
// towards `view_points` when `normals` is empty). Vertices of low density are trimmed.
struct PoissonMesh {
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};
std::optional<PoissonMesh> poisson_mesh(const std::vector<Vec3>& points,
                                        const std::vector<Vec3>& view_points, int depth,
                                        std::string* error);

}  // namespace rigc::eval
