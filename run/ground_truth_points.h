// Points on the ground-truth surface that the shots see, with their colours and tracks: the
// points3D.txt of the run's COLMAP model (and the points of bundle.out), so that tools which
// start from an SfM model (Gaussian-splatting trainers, MVS) can start from the ground truth.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "ir/ir.h"
#include "run/colmap_text.h"

namespace rigc::run {

struct GroundTruthObservation {
  int shot = 0;         // index into the `shots` list given to sample_ground_truth_points
  int point2d = 0;      // its index among that image's observations (COLMAP's POINT2D_IDX)
  double x = 0, y = 0;  // pixel, COLMAP's convention (pixel centres at +0.5)
};

struct GroundTruthPoint {
  ir::Vec3 position = ir::Vec3::Zero();      // object frame (COLMAP's world)
  std::array<std::uint8_t, 3> rgb{0, 0, 0};  // the surface's albedo, sRGB
  std::vector<GroundTruthObservation> track;
};

struct GroundTruthPoints {
  std::vector<GroundTruthPoint> points;
  // Per entry of `shots`, the observations of its image in POINT2D_IDX order: (point, track entry).
  std::vector<std::vector<std::pair<int, int>>> per_image;
};

// `count` area-uniform samples of the object's surface (deterministic), kept when at least one of
// `shots` (indices into scene.shots) sees them: in front, inside the image of `camera`, facing the
// camera, and not hidden by the object (a depth buffer of the object per shot, the
// image's size up to 640 px wide). Colour: base colour x texture x surface pattern.
GroundTruthPoints sample_ground_truth_points(const ir::Scene& scene, const std::vector<int>& shots,
                                             const OutputCamera& camera, int count);

}  // namespace rigc::run
