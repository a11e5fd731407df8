// The fourth stage of `rigc eval`: the aligned reconstruction measured against the ground truth.
// Signed point-to-mesh distances (of the points, or of an Open3D Poisson mesh of them), Tanks and
// Temples' F-score, and the errors of the reconstructed cameras.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "eval/align.h"
#include "eval/colmap.h"
#include "eval/eval.h"
#include "eval/geometry.h"
#include "eval/inputs.h"
#include "eval/metrics.h"

namespace rigc::eval {

struct Measurements {
  std::vector<Vec3> points;         // the aligned points near the object (object_crop)
  std::vector<double> distance_mm;  // their signed distances
  DistanceStats stats;              // of the compared geometry: the points or the Poisson mesh
  DistanceStats point_stats;        // of the points
  FScore f;
};

// Fills eval.json's "compared", "signed_distance_mm", "poisson_mesh" (with --poisson, whose mesh
// goes to out/poisson_mesh.ply), "fscore" and, with planned cameras, "cameras".
// `reconstructed_mesh` (in the reconstruction's frame) is a mesh whose dense samples are
// `model`'s points: recall then measures the ground-truth samples against the mesh itself
// (CloudCompare's cloud-to-mesh both ways). The recall reference is the ground-truth samples the
// cameras see, or all of them when there is no camera.
// (Eight parameters, the last optional: every input of the measurement, each used.)
Measurements measure(const EvalOptions& options, const SparseModel& model, const GroundTruth& truth,
                     const Surface& surface, const Alignment& alignment,
                     const std::filesystem::path& out, nlohmann::json& report,
                     const Surface* reconstructed_mesh = nullptr);

}  // namespace rigc::eval
