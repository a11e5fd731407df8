// What `rigc coverage` writes: coloured meshes (PLY, GLB), pictures, coverage.json, a table.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>

#include "analysis/coverage.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::analysis {

// Per-face colours as the paper draws them: white unseen, red one view, green two or more.
Eigen::Vector3f paper_color(int views);
// Heat map by view count: white 0, then blue (1) through yellow to red (`max_views` or more).
Eigen::Vector3f heat_color(int views, int max_views);

// Writes into `dir`: coverage.ply/.glb (paper colours), views.ply/.glb (heat map),
// pictures/view_*.png, pictures/after_shot_*.png (cumulative), coverage.json. Atomic files.
bool write_coverage_outputs(const ir::Scene& scene, const scene::StudioScene& studio,
                            const CoverageResult& coverage, const std::filesystem::path& dir,
                            int picture_width, std::string* error);

// The terminal table: per shot, new area and cumulative shares.
void print_coverage_table(const ir::Scene& scene, const CoverageResult& coverage,
                          std::ostream& out);

}  // namespace rigc::analysis
