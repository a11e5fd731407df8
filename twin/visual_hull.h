// The object as the photos' silhouettes bound it: a visual hull carved on a voxel grid (a point
// is kept when every photo shows the object there, or all but `max_misses`: the object must be
// in frame in all of them)
// and meshed at the silhouettes'
// edges by Open3D's marching cubes. A hull cannot carve what no silhouette shows: concavities
// (the space between columns seen end-on, a bowl's inside) stay filled (docs/twin.md).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "eval/geometry.h"
#include "eval/silhouette.h"

namespace rigc::twin {

// The photos' silhouettes are eval's (eval/silhouette.h).
using eval::read_silhouette;
using eval::Silhouette;
using eval::silhouette_iou;

struct SilhouetteView {
  eval::ViewCamera camera;  // its width and height are the silhouette's
  const Silhouette* silhouette = nullptr;
};

struct HullOptions {
  int resolution = 128;  // voxels along the region's longest side
  int min_views = 3;     // a point must fall inside this many photos to be kept
  // A point outside this many silhouettes is still kept: a key that cut a shaded part of the
  // object out of one photo would otherwise carve it from the hull in every view.
  int max_misses = 0;
  // Pixels each silhouette is grown by before carving: the photos' keys put a shaded rim on
  // either side of their thresholds, and a hull, the intersection of them all, comes out smaller
  // than every one.
  int grow_px = 0;
};

struct VisualHull {
  std::vector<Eigen::Vector3f> positions;               // the views' world frame
  std::vector<std::array<std::uint32_t, 3>> triangles;  // counter-clockwise seen from outside
  Eigen::AlignedBox3d region;                           // the grid carved
  double voxel_m = 0;                                   // the grid's spacing, in the views' units
  double filled_share = 0;                              // of the grid's points kept
};

// Where the object can be: a box around the point nearest to every view's ray through its
// silhouette's centroid, as large as the widest silhouette seen from the nearest view, doubled.
// nullopt with `error` when fewer than 3 views show any object or the rays do not meet.
std::optional<Eigen::AlignedBox3d> hull_search_region(const std::vector<SilhouetteView>& views,
                                                      std::string* error);

// Carves `region` at `options.resolution`, twice: coarsely over the region, then finely over the
// part kept (grown by two voxels). nullopt with `error` when fewer than 3 silhouettes are given,
// nothing is kept, or the hull fills the whole region (the silhouettes keep everything: no
// backdrop was found).
std::optional<VisualHull> carve_visual_hull(const std::vector<SilhouetteView>& views,
                                            const Eigen::AlignedBox3d& region,
                                            const HullOptions& options, std::string* error);

// `hull` with every triangle split into four, `times` times over (Open3D's midpoint
// subdivision): the same surface, with vertices closer together for the photos' colours.
VisualHull subdivided(const VisualHull& hull, int times);

// The silhouette `mesh` casts in `camera`: the share of each pixel covered, 0 or 1 at its centre.
Silhouette render_silhouette(const eval::ViewCamera& camera, const VisualHull& hull);

}  // namespace rigc::twin
