// `rigc eval --reconstruction FILE`: a point cloud or mesh another tool made (Metashape,
// RealityCapture, Meshroom, OpenMVS, a splatting trainer's points), measured against the ground
// truth the way the COLMAP path measures its points (eval/measure.h, eval/report.h). A mesh is
// measured by dense area-uniform samples of its surface (CloudCompare's cloud-to-mesh on sampled
// points), and recall by the ground-truth samples' distances to the mesh.
//
// Alignment: the tool's cameras (--cameras) fitted to the ground-truth poses, else global
// registration (FPFH + RANSAC, ICP) whose fitness must reach --min-fitness, or none (--no-align).
#pragma once

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "eval/eval.h"
#include "eval/geometry.h"
#include "eval/inputs.h"
#include "eval/report.h"

namespace rigc::eval {

// A reconstruction file's geometry: points (a cloud), or a triangle mesh.
struct ReconstructionGeometry {
  std::vector<Vec3> points;  // a cloud's points (empty for a mesh)
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  bool has_colors = false, has_normals = false;
  std::size_t dropped = 0;  // points or vertices with a non-finite coordinate, left out
  bool is_mesh() const { return !triangles.empty(); }
};

// PLY (binary or ASCII; a cloud when it has no faces), OBJ and STL through Open3D; glTF / GLB
// through RigC's model loader (Y-up converted to Z-up as for a ground-truth glTF); PCD, XYZ and
// PTS clouds through Open3D. nullopt with a one-line error naming the file.
std::optional<ReconstructionGeometry> load_reconstruction(const std::filesystem::path& path,
                                                          std::string* error);

// The rest of evaluate() for --reconstruction once the inputs are checked and the report begun:
// load, align, measure, write. Returns 0, 1 (the file or the cameras cannot be read or used) or
// 2 (the alignment failed or fits poorly: the figures are in eval.json and on the log).
int evaluate_reconstruction(const EvalOptions& options, const EvalInputs& inputs,
                            EvalReport& report, std::ostream& log, EvalSummary& summary,
                            std::chrono::steady_clock::time_point start);

}  // namespace rigc::eval
