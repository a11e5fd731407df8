#include "raster/screen_setup.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

namespace rigc::raster {
namespace {

// Clips a camera-space triangle against z = kNear; emits 0, 1 or 2 triangles.
template <typename Emit>
void clip_near(const std::array<Vector3f, 3>& cam, Emit emit) {
  std::array<Vector3f, 4> out_p;
  std::array<Vector3f, 4> out_b;
  int count = 0;
  const Vector3f bary[3] = {Vector3f(1, 0, 0), Vector3f(0, 1, 0), Vector3f(0, 0, 1)};
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const bool in_i = cam[i].z() >= kNear, in_j = cam[j].z() >= kNear;
    if (in_i) {
      out_p[count] = cam[i];
      out_b[count++] = bary[i];
    }
    if (in_i != in_j) {
      const float t = (kNear - cam[i].z()) / (cam[j].z() - cam[i].z());
      out_p[count] = cam[i] + t * (cam[j] - cam[i]);
      out_b[count++] = bary[i] + t * (bary[j] - bary[i]);
    }
  }
  if (count < 3) return;
  emit(std::array<Vector3f, 3>{out_p[0], out_p[1], out_p[2]},
       std::array<Vector3f, 3>{out_b[0], out_b[1], out_b[2]});
  if (count == 4) {
    emit(std::array<Vector3f, 3>{out_p[0], out_p[2], out_p[3]},
         std::array<Vector3f, 3>{out_b[0], out_b[2], out_b[3]});
  }
}

// The canvas's pinhole projection, in float.
struct Projection {
  float fx, fy, cx, cy;
  int width, height;
};

// Projects camera-space triangle `p` into `s`; false when it has no area or misses the canvas.
[[gnu::always_inline]] inline bool project(const Projection& canvas, int source,
                                           const std::array<Vector3f, 3>& p, std::int32_t clipped,
                                           ScreenTriangle& s) {
  std::array<Vector2f, 3> screen;
  for (int c = 0; c < 3; ++c) {
    s.inv_z[c] = 1 / p[c].z();
    // Pixel centres at +0.5: u = fx·x/z + cx puts the image centre at cx.
    screen[c] = {canvas.fx * p[c].x() * s.inv_z[c] + canvas.cx,
                 canvas.fy * p[c].y() * s.inv_z[c] + canvas.cy};
  }
  const float area = edge(screen[0], screen[1], screen[2].x(), screen[2].y());
  if (std::abs(area) < 1e-10f) return false;
  const float min_x = std::min({screen[0].x(), screen[1].x(), screen[2].x()});
  const float max_x = std::max({screen[0].x(), screen[1].x(), screen[2].x()});
  const float min_y = std::min({screen[0].y(), screen[1].y(), screen[2].y()});
  const float max_y = std::max({screen[0].y(), screen[1].y(), screen[2].y()});
  if (max_x < 0 || max_y < 0 || min_x >= canvas.width || min_y >= canvas.height) return false;
  s.x0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_x)));
  s.y0 = static_cast<std::uint16_t>(std::max(0.0f, std::floor(min_y)));
  s.x1 = static_cast<std::uint16_t>(std::min<float>(canvas.width - 1, std::floor(max_x)));
  s.y1 = static_cast<std::uint16_t>(std::min<float>(canvas.height - 1, std::floor(max_y)));
  s.source = source;
  s.clipped = clipped;
  compute_planes(s, screen, 1 / area);
  return true;
}

// The screen triangles of one chunk of source triangles, with the clipped ones' corners.
struct SetupPart {
  std::vector<ScreenTriangle> tris;
  std::vector<std::array<Vector3f, 3>> clipped_bary;
};

// Transforms (camera_vertex(t, corner) -> camera space), culls, clips and projects triangles
// begin .. end.
template <typename CameraVertex, typename Cullable>
void setup_part(int begin, int end, const CameraVertex& camera_vertex, const Cullable& cullable,
                const Projection& canvas, SetupPart& part) {
  part.tris.reserve(end - begin);
  auto emit = [&](int source, const std::array<Vector3f, 3>& p, std::int32_t clipped) {
    ScreenTriangle s;
    if (!project(canvas, source, p, clipped, s)) return false;
    part.tris.push_back(s);
    return true;
  };
  for (int t = begin; t < end; ++t) {
    std::array<Vector3f, 3> cam;
    for (int c = 0; c < 3; ++c) cam[c] = camera_vertex(t, c);
    // Back faces of closed solids: the camera (at the origin) is behind their plane.
    if (cullable(t) && (cam[1] - cam[0]).cross(cam[2] - cam[0]).dot(cam[0]) >= 0) continue;
    const int in_front = (cam[0].z() >= kNear) + (cam[1].z() >= kNear) + (cam[2].z() >= kNear);
    if (in_front == 0) continue;
    if (in_front == 3) {
      emit(t, cam, -1);
      continue;
    }
    clip_near(cam, [&](const std::array<Vector3f, 3>& p, const std::array<Vector3f, 3>& b) {
      if (emit(t, p, static_cast<std::int32_t>(part.clipped_bary.size()))) {
        part.clipped_bary.push_back(b);
      }
    });
  }
}

// The parts joined in order into `setup`.
void join_parts(std::vector<SetupPart>& parts, ScreenSetup& setup) {
  const int chunks = static_cast<int>(parts.size());
  std::vector<size_t> tri_offset(chunks + 1, 0), clipped_offset(chunks + 1, 0);
  for (int c = 0; c < chunks; ++c) {
    tri_offset[c + 1] = tri_offset[c] + parts[c].tris.size();
    clipped_offset[c + 1] = clipped_offset[c] + parts[c].clipped_bary.size();
  }
  setup.tris.resize(tri_offset[chunks]);
  setup.clipped_bary.resize(clipped_offset[chunks]);
  tbb::parallel_for(0, chunks, [&](int c) {
    std::copy(parts[c].clipped_bary.begin(), parts[c].clipped_bary.end(),
              setup.clipped_bary.begin() + clipped_offset[c]);
    ScreenTriangle* out = setup.tris.data() + tri_offset[c];
    for (ScreenTriangle s : parts[c].tris) {
      if (s.clipped >= 0) s.clipped += static_cast<std::int32_t>(clipped_offset[c]);
      *out++ = s;
    }
    std::vector<ScreenTriangle>().swap(parts[c].tris);
  });
}

// The screen triangles binned into the canvas's tiles.
void bin_into_tiles(int width, int height, ScreenSetup& setup) {
  const int tiles_x = setup.tiles_x = (width + kTileSize - 1) / kTileSize;
  const int tiles_y = setup.tiles_y = (height + kTileSize - 1) / kTileSize;
  CellBins bins =
      bin_items(static_cast<int>(setup.tris.size()), tiles_x * tiles_y, [&](int i, auto&& fn) {
        const ScreenTriangle& t = setup.tris[i];
        for (int ty = t.y0 / kTileSize; ty <= t.y1 / kTileSize; ++ty) {
          for (int tx = t.x0 / kTileSize; tx <= t.x1 / kTileSize; ++tx) {
            fn(ty * tiles_x + tx);
          }
        }
      });
  setup.tile_start = std::move(bins.start);
  setup.tile_tris = std::move(bins.items);
}

// Transforms (camera_vertex(t, corner) -> camera space), clips, projects and bins every triangle.
// Chunks run in parallel and are joined in order, so the result (and any depth tie) matches a
// serial pass.
template <typename CameraVertex, typename Cullable>
ScreenSetup setup_screen(int total_tris, const CameraVertex& camera_vertex,
                         const Cullable& cullable, const dslr::Intrinsics& canvas) {
  const Projection projection = {static_cast<float>(canvas.fx),
                                 static_cast<float>(canvas.fy),
                                 static_cast<float>(canvas.cx),
                                 static_cast<float>(canvas.cy),
                                 canvas.width,
                                 canvas.height};
  constexpr int kChunk = 16384;
  const int chunks = (total_tris + kChunk - 1) / kChunk;
  std::vector<SetupPart> parts(chunks);
  tbb::parallel_for(0, chunks, [&](int chunk) {
    const int begin = chunk * kChunk, end = std::min(total_tris, begin + kChunk);
    setup_part(begin, end, camera_vertex, cullable, projection, parts[chunk]);
  });
  ScreenSetup setup;
  join_parts(parts, setup);
  bin_into_tiles(canvas.width, canvas.height, setup);
  return setup;
}

}  // namespace

FrameContext::FrameContext(const ir::Scene& scene, const scene::StudioScene& studio,
                           const FrameRequest& request)
    : object(studio.object),
      room(studio.studio),
      closed_studio_tris(studio.closed_studio_triangles),
      object_closed(studio.object_closed) {
  const ir::Mat4 world_from_object = ir::world_from_object(scene, request.turntable_angle_rad);
  object_rot = world_from_object.block<3, 3>(0, 0).cast<float>();
  object_t = world_from_object.block<3, 1>(0, 3).cast<float>();
  const ir::Mat4 camera_from_world = request.world_from_camera.inverse();
  cam_rot = camera_from_world.block<3, 3>(0, 0).cast<float>();
  cam_t = camera_from_world.block<3, 1>(0, 3).cast<float>();
  eye = request.world_from_camera.block<3, 1>(0, 3).cast<float>();
  object_tris = static_cast<int>(object.triangles.size());
  total_tris = object_tris + static_cast<int>(room.triangles.size());
}

ScreenSetup FrameContext::setup(const dslr::Intrinsics& canvas) const {
  // One affine map per mesh, written out: Eigen's generic product did not inline here.
  const Matrix3f object_to_cam = cam_rot * object_rot;
  const Vector3f object_to_cam_t = cam_rot * object_t + cam_t;
  auto apply = [](const Matrix3f& m, const Vector3f& t, const Vector3f& p) {
    return Vector3f(m(0, 0) * p.x() + m(0, 1) * p.y() + m(0, 2) * p.z() + t.x(),
                    m(1, 0) * p.x() + m(1, 1) * p.y() + m(1, 2) * p.z() + t.y(),
                    m(2, 0) * p.x() + m(2, 1) * p.y() + m(2, 2) * p.z() + t.z());
  };
  return setup_screen(
      total_tris,
      [&](int t, int c) {
        if (t < object_tris) {
          return apply(object_to_cam, object_to_cam_t, object.positions[object.triangles[t][c]]);
        }
        return apply(cam_rot, cam_t, room.positions[room.triangles[t - object_tris][c]]);
      },
      [&](int t) { return t < object_tris ? object_closed : t - object_tris < closed_studio_tris; },
      canvas);
}

}  // namespace rigc::raster
