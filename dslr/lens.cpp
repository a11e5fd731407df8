#include "dslr/lens.h"

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>

#include "dslr/buffer_pool.h"
#include "dslr/simd.h"

namespace rigc::dslr {

Intrinsics sensor_intrinsics(const ir::Camera& camera, double scale) {
  Intrinsics k;
  k.width = std::max(1, static_cast<int>(std::lround(camera.width_px * scale)));
  k.height = std::max(1, static_cast<int>(std::lround(camera.height_px * scale)));
  const double sx = static_cast<double>(k.width) / camera.width_px;
  const double sy = static_cast<double>(k.height) / camera.height_px;
  const double fx =
      camera.fx > 0 ? camera.fx : camera.focal_length_m * camera.width_px / camera.sensor_width_m;
  const double fy =
      camera.fy > 0 ? camera.fy : camera.focal_length_m * camera.height_px / camera.sensor_height_m;
  k.fx = fx * sx;
  k.fy = fy * sy;
  k.cx = (camera.cx > 0 ? camera.cx : camera.width_px / 2.0) * sx;
  k.cy = (camera.cy > 0 ? camera.cy : camera.height_px / 2.0) * sy;
  return k;
}

ir::Camera camera_at_scale(const ir::Camera& camera, double scale) {
  const Intrinsics k = sensor_intrinsics(camera, scale);
  ir::Camera scaled = camera;
  scaled.width_px = k.width;
  scaled.height_px = k.height;
  scaled.fx = k.fx;
  scaled.fy = k.fy;
  scaled.cx = k.cx;
  scaled.cy = k.cy;
  return scaled;
}

ir::Vec2 distort_normalized(const ir::Distortion& d, double x, double y) {
  return d.apply(x, y);
}

bool try_undistort_normalized(const ir::Distortion& d, double x, double y, ir::Vec2* undistorted,
                              const ir::Vec2* guess) {
  auto newton = [&](double ux, double uy) -> bool {
    for (int iteration = 0; iteration < 30; ++iteration) {
      const ir::Vec2 distorted = d.apply(ux, uy);
      const double fx = distorted.x() - x, fy = distorted.y() - y;
      const Eigen::Matrix2d j = d.jacobian(ux, uy);
      const double jxx = j(0, 0), jxy = j(0, 1), jyy = j(1, 1);
      const double det = jxx * jyy - jxy * jxy;
      // A non-positive Jacobian means we are past the fold: the lens maps no point here.
      if (!(det > 1e-12)) return false;
      const double sx = (jyy * fx - jxy * fy) / det;
      const double sy = (jxx * fy - jxy * fx) / det;
      ux -= sx;
      uy -= sy;
      if (!std::isfinite(ux) || !std::isfinite(uy) || ux * ux + uy * uy > 1e6) return false;
      if (sx * sx + sy * sy < 1e-28) {
        *undistorted = {ux, uy};
        return true;
      }
    }
    return false;
  };
  if (guess != nullptr && newton(guess->x(), guess->y())) return true;
  return newton(x, y);
}

ir::Vec2 undistort_normalized(const ir::Distortion& d, double x, double y) {
  ir::Vec2 u;
  return try_undistort_normalized(d, x, y, &u) ? u : ir::Vec2(x, y);
}

RenderGeometry render_geometry_for(const ir::Camera& camera, double scale) {
  const Intrinsics sensor = sensor_intrinsics(camera, scale);
  RenderGeometry geometry;
  static_cast<Intrinsics&>(geometry) = sensor;
  if (!camera.effects.distortion || camera.distortion.is_zero()) return geometry;

  const double w = sensor.width, h = sensor.height;
  double u_min = std::numeric_limits<double>::infinity(), u_max = -u_min;
  double v_min = u_min, v_max = -u_min;
  bool unreachable = false;
  ir::Vec2 guess(0, 0);
  auto visit = [&](double u, double v) {
    ir::Vec2 xu;
    if (!try_undistort_normalized(camera.distortion, (u - sensor.cx) / sensor.fx,
                                  (v - sensor.cy) / sensor.fy, &xu, &guess)) {
      unreachable = true;
      return;
    }
    guess = xu;
    const double uu = sensor.fx * xu.x() + sensor.cx, vv = sensor.fy * xu.y() + sensor.cy;
    u_min = std::min(u_min, uu), u_max = std::max(u_max, uu);
    v_min = std::min(v_min, vv), v_max = std::max(v_max, vv);
  };
  // The border, every pixel edge, then a coarse interior grid for unusual coefficient mixes.
  for (int i = 0; i <= sensor.width; ++i) visit(i, 0);
  for (int j = 0; j <= sensor.height; ++j) visit(w, j);
  for (int i = sensor.width; i >= 0; --i) visit(i, h);
  for (int j = sensor.height; j >= 0; --j) visit(0, j);
  for (int a = 1; a < 32; ++a) {
    for (int b = 1; b < 32; ++b) visit(w * a / 32, h * b / 32);
  }
  if (!(u_min <= u_max)) {
    geometry.clipped = true;
    return geometry;
  }
  // Equal padding on both sides keeps the principal point where it was relative to the centre
  // (centred stays centred: renderers need no lens shift).
  constexpr double kMargin = 2;
  const double need_x = std::max(kMargin - u_min, u_max + kMargin - w);
  const double need_y = std::max(kMargin - v_min, v_max + kMargin - h);
  const int cap_x = sensor.width / 2, cap_y = sensor.height / 2;
  const int pad_x = std::min(cap_x, static_cast<int>(std::ceil(need_x)));
  const int pad_y = std::min(cap_y, static_cast<int>(std::ceil(need_y)));
  geometry.clipped = unreachable || need_x > cap_x || need_y > cap_y;
  geometry.width = std::max(1, sensor.width + 2 * pad_x);
  geometry.height = std::max(1, sensor.height + 2 * pad_y);
  geometry.cx = sensor.cx + pad_x;
  geometry.cy = sensor.cy + pad_y;
  return geometry;
}

double vignetting_gain(double fraction_lost, double r2, double r2_corner) {
  if (fraction_lost <= 0 || r2_corner <= 0) return 1;
  auto cos4 = [](double q) { return 1 / ((1 + q) * (1 + q)); };
  return 1 - fraction_lost * (1 - cos4(r2)) / (1 - cos4(r2_corner));
}

namespace {

// Where sensor positions land on the canvas, solved exactly on a grid of nodes kMapStep pixels
// apart and interpolated bilinearly in between. The map is smooth: a small fraction of a pixel
// off (the tests bound it), for 1/64 of the Newton solves.
constexpr int kMapStep = 8;

struct CanvasMap {
  int nodes_x = 0, nodes_y = 0;
  std::vector<double> u, v;  // canvas index-space position (pixel centres at integers)
  std::vector<double> gain;  // vignetting
  std::vector<char> valid;   // false beyond the fold of the lens

  std::size_t node(int a, int b) const { return static_cast<std::size_t>(b) * nodes_x + a; }
};

CanvasMap build_canvas_map(const ir::Distortion& distortion, bool distort, double vignetting,
                           double r2_corner, const Intrinsics& sensor, const Intrinsics& canvas) {
  CanvasMap map;
  map.nodes_x = sensor.width / kMapStep + 2;
  map.nodes_y = sensor.height / kMapStep + 2;
  const std::size_t n = static_cast<std::size_t>(map.nodes_x) * map.nodes_y;
  map.u.resize(n);
  map.v.resize(n);
  map.gain.resize(n);
  map.valid.resize(n);
  tbb::parallel_for(
      tbb::blocked_range<int>(0, map.nodes_y), [&](const tbb::blocked_range<int>& rows) {
        for (int b = rows.begin(); b < rows.end(); ++b) {
          const double yd = (b * kMapStep - sensor.cy) / sensor.fy;
          ir::Vec2 guess(0, yd);
          for (int a = 0; a < map.nodes_x; ++a) {
            const double xd = (a * kMapStep - sensor.cx) / sensor.fx;
            ir::Vec2 xu(xd, yd);
            const bool ok = !distort || try_undistort_normalized(distortion, xd, yd, &xu, &guess);
            if (ok) guess = xu;
            const std::size_t k = map.node(a, b);
            map.valid[k] = ok;
            map.u[k] = canvas.fx * xu.x() + canvas.cx - 0.5;
            map.v[k] = canvas.fy * xu.y() + canvas.cy - 0.5;
            map.gain[k] = vignetting_gain(vignetting, xd * xd + yd * yd, r2_corner);
          }
        }
      });
  return map;
}

// The map depends only on the lens and the two grids, the same for every shot of a run: the last
// one is kept (building it solves the distortion at ~300 000 nodes at full resolution).
std::shared_ptr<const CanvasMap> canvas_map_for(const ir::Distortion& distortion, bool distort,
                                                double vignetting, double r2_corner,
                                                const Intrinsics& sensor,
                                                const Intrinsics& canvas) {
  const std::array<double, 20> key = {distortion.k1,
                                      distortion.k2,
                                      distortion.p1,
                                      distortion.p2,
                                      distortion.k3,
                                      double(distort),
                                      vignetting,
                                      r2_corner,
                                      double(sensor.width),
                                      double(sensor.height),
                                      sensor.fx,
                                      sensor.fy,
                                      sensor.cx,
                                      sensor.cy,
                                      double(canvas.width),
                                      double(canvas.height),
                                      canvas.fx,
                                      canvas.fy,
                                      canvas.cx,
                                      canvas.cy};
  static std::mutex mutex;
  static std::array<double, 20> kept_key;
  static std::shared_ptr<const CanvasMap> kept;
  std::lock_guard lock(mutex);
  if (!kept || kept_key != key) {
    kept = std::make_shared<const CanvasMap>(
        build_canvas_map(distortion, distort, vignetting, r2_corner, sensor, canvas));
    kept_key = key;
  }
  return kept;
}

bool same_grid(const Intrinsics& a, const Intrinsics& b) {
  auto close = [](double p, double q) {
    return std::abs(p - q) <= 1e-9 * std::max(1.0, std::abs(p));
  };
  return a.width == b.width && a.height == b.height && close(a.fx, b.fx) && close(a.fy, b.fy) &&
         close(a.cx, b.cx) && close(a.cy, b.cy);
}

// The largest normalised radius² of the sensor's corners (vignetting_gain's r2_corner).
double corner_radius_sq(const Intrinsics& sensor) {
  double r2_corner = 0;
  for (double u : {0.0, double(sensor.width)}) {
    for (double v : {0.0, double(sensor.height)}) {
      const double x = (u - sensor.cx) / sensor.fx, y = (v - sensor.cy) / sensor.fy;
      r2_corner = std::max(r2_corner, x * x + y * y);
    }
  }
  return r2_corner;
}

// The buffers of one warp as plain pointers, copied into a local by each row loop: the mask's
// byte stores may alias any memory, so data pointers read out of the vectors (or out of memory
// the loop does not own) would be loaded again after every pixel.
struct WarpBuffers {
  const float* canvas_rgb;
  const float* canvas_depth;
  const std::uint8_t* canvas_mask;
  int cw, ch;  // the canvas's size
  float* sensor_rgb;
  float* sensor_depth;
  std::uint8_t* sensor_mask;
  bool has_depth, has_mask;
};

// Bilinear from the canvas at (uc, vc), scaled by the vignetting gain, into sensor pixel o; depth
// and mask from the nearest canvas pixel. Away from the canvas's border the four taps need no
// clamping.
[[gnu::always_inline]] inline void sample_canvas(const WarpBuffers& buffers, std::size_t o,
                                                 float uc, float vc, float gain) {
  const int cw = buffers.cw, ch = buffers.ch;
  const float* const canvas_rgb = buffers.canvas_rgb;
  const float fu = std::floor(uc), fv = std::floor(vc);
  const float au = uc - fu, av = vc - fv;
  const int iu = static_cast<int>(fu), iv = static_cast<int>(fv);
  const float *p00, *p10, *p01, *p11;
  int ni, nj;
  if (iu >= 0 && iv >= 0 && iu + 1 < cw && iv + 1 < ch) {
    p00 = &canvas_rgb[3 * (static_cast<std::size_t>(iv) * cw + iu)];
    p10 = p00 + 3;
    p01 = p00 + 3 * static_cast<std::size_t>(cw);
    p11 = p01 + 3;
    ni = iu + (au >= 0.5f);
    nj = iv + (av >= 0.5f);
  } else {
    const int i0 = std::clamp(iu, 0, cw - 1), i1 = std::clamp(iu + 1, 0, cw - 1);
    const int j0 = std::clamp(iv, 0, ch - 1), j1 = std::clamp(iv + 1, 0, ch - 1);
    p00 = &canvas_rgb[3 * (static_cast<std::size_t>(j0) * cw + i0)];
    p10 = &canvas_rgb[3 * (static_cast<std::size_t>(j0) * cw + i1)];
    p01 = &canvas_rgb[3 * (static_cast<std::size_t>(j1) * cw + i0)];
    p11 = &canvas_rgb[3 * (static_cast<std::size_t>(j1) * cw + i1)];
    ni = std::clamp(iu + (au >= 0.5f), 0, cw - 1);
    nj = std::clamp(iv + (av >= 0.5f), 0, ch - 1);
  }
  for (int c = 0; c < 3; ++c) {
    const float top = p00[c] + au * (p10[c] - p00[c]);
    const float bottom = p01[c] + au * (p11[c] - p01[c]);
    buffers.sensor_rgb[3 * o + c] = (top + av * (bottom - top)) * gain;
  }
  const std::size_t nearest = static_cast<std::size_t>(nj) * cw + ni;
  if (buffers.has_depth) buffers.sensor_depth[o] = buffers.canvas_depth[nearest];
  if (buffers.has_mask) buffers.sensor_mask[o] = buffers.canvas_mask[nearest];
}

// The mask bytes of a cell: per lane k, column iu + k or the next one (`right`), row `upper` or
// the next one (`down`).
[[gnu::always_inline]] inline void nearest_mask_bytes(const std::uint8_t* upper,
                                                      const std::uint8_t* lower, simd::I32x8 right,
                                                      simd::I32x8 down, std::uint8_t* dst) {
#if defined(__AVX2__)
  // Lane masks narrowed to bytes; the eight mask bytes picked from four loads.
  auto bytes_of = [](simd::I32x8 lanes) {
    const __m256i wide = reinterpret_cast<__m256i>(lanes);
    const __m128i words =
        _mm_packs_epi32(_mm256_castsi256_si128(wide), _mm256_extracti128_si256(wide, 1));
    return _mm_packs_epi16(words, words);
  };
  auto load_bytes = [](const std::uint8_t* p) {
    return _mm_loadl_epi64(reinterpret_cast<const __m128i*>(p));
  };
  const __m128i take_right = bytes_of(right), take_lower = bytes_of(down);
  const __m128i from_upper = _mm_blendv_epi8(load_bytes(upper), load_bytes(upper + 1), take_right);
  const __m128i from_lower = _mm_blendv_epi8(load_bytes(lower), load_bytes(lower + 1), take_right);
  _mm_storel_epi64(reinterpret_cast<__m128i*>(dst),
                   _mm_blendv_epi8(from_upper, from_lower, take_lower));
#else
  for (int k = 0; k < kMapStep; ++k) dst[k] = (down[k] ? lower : upper)[k + (right[k] ? 1 : 0)];
#endif
}

// A whole cell (kMapStep pixels from sensor pixel o, between two nodes: position u0 + t·du,
// v0 + t·dv, gain g0 + t·dg) whose eight pixels read eight neighbouring canvas columns of one
// pair of rows (the distortion shifts a cell by a fraction of a pixel, it rarely stretches it
// across one): its 24 values are blended eight at a time from contiguous loads, the same
// arithmetic as sample_canvas per value. False (nothing written) otherwise.
[[gnu::always_inline]] inline bool warp_contiguous_cell(const WarpBuffers& buffers, std::size_t o,
                                                        float u0, float du, float v0, float dv,
                                                        float g0, float dg) {
  static_assert(kMapStep == 8, "a cell is one 8-lane register of pixels");
  using simd::F32x8;
  using simd::I32x8;
  const int cw = buffers.cw, ch = buffers.ch;
  const F32x8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
  const F32x8 ta = (lane + 0.5f) / kMapStep;
  const F32x8 uc = u0 + ta * du, vc = v0 + ta * dv, gain = g0 + ta * dg;
  const F32x8 fu = simd::floor(uc), fv = simd::floor(vc);
  const float first_u = fu[0], first_v = fv[0];
  if (simd::any((fu != first_u + lane) | (fv != first_v))) return false;
  const int iu = static_cast<int>(first_u), iv = static_cast<int>(first_v);
  if (!(iu >= 0 && iv >= 0 && iu + kMapStep < cw && iv + 1 < ch)) return false;
  const F32x8 au = uc - fu, av = vc - fv;
  const float* top = &buffers.canvas_rgb[3 * (static_cast<std::size_t>(iv) * cw + iu)];
  const float* bottom = top + 3 * static_cast<std::size_t>(cw);
  float* dst = &buffers.sensor_rgb[3 * o];
  // Value 8·part + lane is channel (8·part + lane) % 3 of pixel (8·part + lane) / 3.
  static constexpr I32x8 kPixelOf[3] = {
      {0, 0, 0, 1, 1, 1, 2, 2}, {2, 3, 3, 3, 4, 4, 4, 5}, {5, 5, 6, 6, 6, 7, 7, 7}};
  using simd::load8;
  for (int part = 0; part < 3; ++part) {
    const F32x8 a = simd::permute(au, kPixelOf[part]);
    const F32x8 b = simd::permute(av, kPixelOf[part]);
    const F32x8 g = simd::permute(gain, kPixelOf[part]);
    const F32x8 p00 = load8(top + 8 * part), p10 = load8(top + 8 * part + 3);
    const F32x8 p01 = load8(bottom + 8 * part), p11 = load8(bottom + 8 * part + 3);
    const F32x8 upper = p00 + a * (p10 - p00);
    const F32x8 lower = p01 + a * (p11 - p01);
    const F32x8 value = (upper + b * (lower - upper)) * g;
    std::memcpy(dst + 8 * part, &value, sizeof value);
  }
  // Depth and mask from the nearest canvas pixel: column iu + k or the next one, row iv or the
  // next one.
  const I32x8 right = au >= 0.5f, down = av >= 0.5f;
  if (buffers.has_mask) {
    const std::uint8_t* upper = &buffers.canvas_mask[static_cast<std::size_t>(iv) * cw + iu];
    nearest_mask_bytes(upper, upper + cw, right, down, &buffers.sensor_mask[o]);
  }
  if (buffers.has_depth) {
    const float* upper = &buffers.canvas_depth[static_cast<std::size_t>(iv) * cw + iu];
    const float* lower = upper + cw;
    const F32x8 from_upper = right ? load8(upper + 1) : load8(upper);
    const F32x8 from_lower = right ? load8(lower + 1) : load8(lower);
    const F32x8 nearest = down ? from_lower : from_upper;
    std::memcpy(&buffers.sensor_depth[o], &nearest, sizeof nearest);
  }
  return true;
}

// The canvas map interpolated to one sensor row, node by node, the gain scaled by the signal.
struct MapRow {
  std::vector<float> u, v, gain;
  std::vector<char> valid;

  explicit MapRow(int nodes) : u(nodes), v(nodes), gain(nodes), valid(nodes) {}

  void interpolate(const CanvasMap& map, int j, double signal_scale) {
    const double gy = (j + 0.5) / kMapStep;
    const int b = static_cast<int>(gy);
    const double tb = gy - b;
    for (int a = 0; a < map.nodes_x; ++a) {
      const std::size_t k0 = map.node(a, b), k1 = k0 + map.nodes_x;
      u[a] = static_cast<float>((1 - tb) * map.u[k0] + tb * map.u[k1]);
      v[a] = static_cast<float>((1 - tb) * map.v[k0] + tb * map.v[k1]);
      gain[a] = static_cast<float>(signal_scale * ((1 - tb) * map.gain[k0] + tb * map.gain[k1]));
      valid[a] = map.valid[k0] && map.valid[k1];
    }
  }
};

// One warp from the canvas onto the sensor grid.
struct SensorWarp {
  const ir::Camera& camera;
  const Intrinsics& sensor;
  const Intrinsics& canvas;
  double signal_scale;
  double vignetting;  // the fraction of light lost in the corners, 0 when off
  double r2_corner;
  WarpBuffers buffers;

  // Same grid, no distortion: each value times its vignetting gain.
  void copy_rows(const std::vector<float>& rgb, const std::vector<float>& depth_m,
                 const std::vector<std::uint8_t>& mask, SensorImage& out) const;
  void warp_rows(const CanvasMap& map) const;
  void warp_row(int j, const MapRow& row_map) const;
  // Next to the fold the grid cannot be interpolated: pixel (i, j) solved exactly.
  void warp_pixel_exactly(int i, int j, WarpBuffers local) const;
};

void SensorWarp::copy_rows(const std::vector<float>& rgb, const std::vector<float>& depth_m,
                           const std::vector<std::uint8_t>& mask, SensorImage& out) const {
  const bool has_depth = buffers.has_depth, has_mask = buffers.has_mask;
  tbb::parallel_for(
      tbb::blocked_range<int>(0, sensor.height), [&](const tbb::blocked_range<int>& rows) {
        for (int j = rows.begin(); j < rows.end(); ++j) {
          const double yd = (j + 0.5 - sensor.cy) / sensor.fy;
          const std::size_t row = static_cast<std::size_t>(j) * sensor.width;
          for (int i = 0; i < sensor.width; ++i) {
            const double xd = (i + 0.5 - sensor.cx) / sensor.fx;
            const float gain = static_cast<float>(
                signal_scale *
                (vignetting > 0 ? vignetting_gain(vignetting, xd * xd + yd * yd, r2_corner) : 1));
            for (int c = 0; c < 3; ++c) out.rgb[3 * (row + i) + c] = rgb[3 * (row + i) + c] * gain;
          }
          if (has_depth) std::copy_n(&depth_m[row], sensor.width, &out.depth_m[row]);
          if (has_mask) std::copy_n(&mask[row], sensor.width, &out.mask[row]);
        }
      });
}

void SensorWarp::warp_rows(const CanvasMap& map) const {
  tbb::parallel_for(tbb::blocked_range<int>(0, sensor.height),
                    [&](const tbb::blocked_range<int>& rows) {
                      MapRow row_map(map.nodes_x);
                      for (int j = rows.begin(); j < rows.end(); ++j) {
                        row_map.interpolate(map, j, signal_scale);
                        warp_row(j, row_map);
                      }
                    });
}

// Node to node: the map's cells are kMapStep pixels wide.
void SensorWarp::warp_row(int j, const MapRow& row_map) const {
  // Locals throughout (see WarpBuffers).
  const WarpBuffers local = buffers;
  const float* const node_u = row_map.u.data();
  const float* const node_v = row_map.v.data();
  const float* const node_gain = row_map.gain.data();
  const char* const node_valid = row_map.valid.data();
  const int width = sensor.width;
  const std::size_t row = static_cast<std::size_t>(j) * width;
  for (int a = 0; a * kMapStep < width; ++a) {
    const int i_begin = a * kMapStep, i_end = std::min(width, i_begin + kMapStep);
    if (!(node_valid[a] && node_valid[a + 1])) {
      for (int i = i_begin; i < i_end; ++i) warp_pixel_exactly(i, j, local);
      continue;
    }
    const float u0 = node_u[a], du = node_u[a + 1] - u0;
    const float v0 = node_v[a], dv = node_v[a + 1] - v0;
    const float g0 = node_gain[a], dg = node_gain[a + 1] - g0;
    if (i_end - i_begin == kMapStep &&
        warp_contiguous_cell(local, row + i_begin, u0, du, v0, dv, g0, dg)) {
      continue;
    }
    for (int i = i_begin; i < i_end; ++i) {
      const float ta = (i - i_begin + 0.5f) / kMapStep;
      sample_canvas(local, row + i, u0 + ta * du, v0 + ta * dv, g0 + ta * dg);
    }
  }
}

void SensorWarp::warp_pixel_exactly(int i, int j, WarpBuffers local) const {
  const std::size_t o = static_cast<std::size_t>(j) * sensor.width + i;
  const double xd = (i + 0.5 - sensor.cx) / sensor.fx;
  const double yd = (j + 0.5 - sensor.cy) / sensor.fy;
  ir::Vec2 xu;
  if (!try_undistort_normalized(camera.distortion, xd, yd, &xu)) {
    for (int c = 0; c < 3; ++c) local.sensor_rgb[3 * o + c] = 0;  // no light arrives here
    if (local.has_depth) local.sensor_depth[o] = std::numeric_limits<float>::infinity();
    if (local.has_mask) local.sensor_mask[o] = 0;
    return;
  }
  sample_canvas(
      local, o, static_cast<float>(canvas.fx * xu.x() + canvas.cx - 0.5),
      static_cast<float>(canvas.fy * xu.y() + canvas.cy - 0.5),
      static_cast<float>(signal_scale * vignetting_gain(vignetting, xd * xd + yd * yd, r2_corner)));
}

}  // namespace

SensorImage warp_to_sensor(const ir::Camera& camera, const Intrinsics& sensor,
                           const Intrinsics& canvas, const std::vector<float>& rgb,
                           const std::vector<float>& depth_m, const std::vector<std::uint8_t>& mask,
                           std::vector<float> storage, double signal_scale) {
  SensorImage out;
  out.intrinsics = sensor;
  const std::size_t n = static_cast<std::size_t>(sensor.width) * sensor.height;
  out.rgb = std::move(storage);
  out.rgb.resize(3 * n);
  const bool has_depth = !depth_m.empty(), has_mask = !mask.empty();
  // Every pixel is written below.
  if (has_depth) out.depth_m = take_floats(n);
  if (has_mask) out.mask = take_bytes(n);

  const bool distort = camera.effects.distortion && !camera.distortion.is_zero();
  const double vignetting = camera.effects.vignetting ? std::clamp(camera.vignetting, 0.0, 1.0) : 0;
  const SensorWarp warp{camera,
                        sensor,
                        canvas,
                        signal_scale,
                        vignetting,
                        corner_radius_sq(sensor),
                        {rgb.data(), depth_m.data(), mask.data(), canvas.width, canvas.height,
                         out.rgb.data(), out.depth_m.data(), out.mask.data(), has_depth, has_mask}};
  if (!distort && same_grid(sensor, canvas)) {
    warp.copy_rows(rgb, depth_m, mask, out);
    return out;
  }
  const std::shared_ptr<const CanvasMap> map =
      canvas_map_for(camera.distortion, distort, vignetting, warp.r2_corner, sensor, canvas);
  warp.warp_rows(*map);
  return out;
}

}  // namespace rigc::dslr
