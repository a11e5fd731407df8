// Internal to the rasterizer: a frame's geometry (the object turned to its angle, the camera) and
// its screen setup, every triangle transformed, clipped, projected and binned into tiles.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "raster/raster_common.h"
#include "raster/rasterizer.h"
#include "scene/studio_scene.h"

namespace rigc::raster {

struct ScreenSetup {
  std::vector<ScreenTriangle> tris;
  std::vector<std::array<Vector3f, 3>> clipped_bary;  // per clipped triangle, its corners'
  // Triangles per tile: tile_tris[tile_start[tile] .. tile_start[tile + 1]), in triangle order.
  std::vector<std::int32_t> tile_start;
  std::vector<std::int32_t> tile_tris;
  int tiles_x = 0;
  int tiles_y = 0;

  // Barycentrics in the source triangle of a point with barycentrics b in screen triangle t.
  Vector3f source_bary(const ScreenTriangle& t, const Vector3f& b) const {
    if (t.clipped < 0) return b;
    const auto& corner = clipped_bary[t.clipped];
    return b.x() * corner[0] + b.y() * corner[1] + b.z() * corner[2];
  }
};

// Where everything is for one frame: the object turned to its angle, the camera.
struct FrameContext {
  FrameContext(const ir::Scene& scene, const scene::StudioScene& studio,
               const FrameRequest& request);
  // Object triangles come first, then the studio's.
  Vector3f world_vertex(int tri, int corner) const {
    if (tri < object_tris) {
      return object_rot * object.positions[object.triangles[tri][corner]] + object_t;
    }
    return room.positions[room.triangles[tri - object_tris][corner]];
  }
  // Transforms, clips, projects and bins every triangle for `canvas`.
  ScreenSetup setup(const dslr::Intrinsics& canvas) const;

  const scene::Geometry& object;
  const scene::Geometry& room;
  Matrix3f object_rot, cam_rot;
  Vector3f object_t, cam_t, eye;
  int closed_studio_tris = 0;
  bool object_closed = false;
  int object_tris = 0, total_tris = 0;
};

}  // namespace rigc::raster
