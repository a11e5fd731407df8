#include "dslr/optics.h"

#include <tbb/blocked_range.h>
#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace rigc::dslr {

double coc_diameter_m(double focal_length_m, double f_number, double focus_m, double depth_m) {
  const double f = focal_length_m;
  if (!(focus_m > f) || !(depth_m > 0)) return 0;
  const double aperture = f / f_number;
  const double relative = std::isinf(depth_m) ? 1.0 : std::abs(depth_m - focus_m) / depth_m;
  return aperture * f * relative / (focus_m - f);
}

double hyperfocal_m(double focal_length_m, double f_number, double coc_m) {
  return focal_length_m * focal_length_m / (f_number * coc_m) + focal_length_m;
}

double diffraction_sigma_m(double f_number, double wavelength_m) {
  return 0.42 * wavelength_m * f_number;
}

namespace {

struct Tap {
  int dx, dy;
  float distance;
  float area;      // pixels this tap stands for
  float inv_soft;  // 1 / width of the coverage ramp at the disc edge
};

struct TapSet {
  std::vector<Tap> taps;  // sorted by distance
  // For a gather radius ceil(R): how many leading taps can be covered.
  std::vector<int> count_for_radius;
};

const TapSet& tap_set() {
  static const TapSet set = [] {
    TapSet s;
    constexpr double kDense = 6.5, kRatio = 1.25;
    const int d = static_cast<int>(kDense);
    for (int dy = -d; dy <= d; ++dy) {
      for (int dx = -d; dx <= d; ++dx) {
        const double r = std::hypot(dx, dy);
        if (r <= kDense) s.taps.push_back({dx, dy, float(r), 1.0f, 1.0f});
      }
    }
    int ring = 0;
    for (double inner = kDense; inner < kMaxCocRadiusPx + 1; inner *= kRatio, ++ring) {
      const double outer = inner * kRatio, width = outer - inner, rho = 0.5 * (inner + outer);
      const int n = static_cast<int>(std::lround(2 * std::numbers::pi * rho / width));
      const double area = std::numbers::pi * (outer * outer - inner * inner) / n;
      const double phase = ring * 2.399963;  // golden angle: rings do not line up
      for (int k = 0; k < n; ++k) {
        const double a = phase + 2 * std::numbers::pi * k / n;
        const int dx = static_cast<int>(std::lround(rho * std::cos(a)));
        const int dy = static_cast<int>(std::lround(rho * std::sin(a)));
        s.taps.push_back({dx, dy, float(std::hypot(dx, dy)), float(area), float(1 / width)});
      }
    }
    std::stable_sort(s.taps.begin(), s.taps.end(),
                     [](const Tap& a, const Tap& b) { return a.distance < b.distance; });
    s.count_for_radius.assign(kMaxCocRadiusPx + 2, 0);
    for (int radius = 0; radius < static_cast<int>(s.count_for_radius.size()); ++radius) {
      int count = 0;
      for (int t = 0; t < static_cast<int>(s.taps.size()); ++t) {
        const Tap& tap = s.taps[t];
        if (tap.distance - 0.5f / tap.inv_soft < radius) count = t + 1;
      }
      s.count_for_radius[radius] = count;
    }
    return s;
  }();
  return set;
}

struct DepthRadius {
  float z;       // metres, +inf for unknown or background
  float radius;  // blur disc radius in pixels, at least 0.5 (one pixel's own footprint)
};

constexpr int kTile = 16;
constexpr float kSameDepth = 0.02f;  // relative depth band counted as "the same surface"

template <bool kCheckBounds>
void gather_tile(const TapSet& set, int tap_count, int x0, int x1, int y0, int y1, int w, int h,
                 const float* rgb, const DepthRadius* zr, float* out) {
  const Tap* taps = set.taps.data();
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const std::size_t p = static_cast<std::size_t>(y) * w + x;
      const float zp = zr[p].z, rp = zr[p].radius;
      const float z_front = zp * (1 - kSameDepth), z_back = zp * (1 + kSameDepth);
      float wf = 0, ws = 0, wb = 0;
      float cf[3] = {0, 0, 0}, cs[3] = {0, 0, 0}, cb[3] = {0, 0, 0};
      for (int t = 0; t < tap_count; ++t) {
        const Tap& tap = taps[t];
        const int qx = x + tap.dx, qy = y + tap.dy;
        if constexpr (kCheckBounds) {
          if (qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        }
        const std::size_t q = static_cast<std::size_t>(qy) * w + qx;
        const DepthRadius s = zr[q];
        float* c;
        float weight;
        if (s.z <= z_back) {
          // In front or the same surface: q's disc must reach p; weight is q's energy per pixel.
          const float coverage = std::clamp((s.radius - tap.distance) * tap.inv_soft + 0.5f, 0.f, 1.f);
          if (coverage <= 0) continue;
          weight = tap.area * coverage / (std::numbers::pi_v<float> * s.radius * s.radius);
          if (s.z < z_front) {
            wf += weight;
            c = cf;
          } else {
            ws += weight;
            c = cs;
          }
        } else {
          // Behind p: seen only through p's own blur, never over a sharper p.
          const float coverage = std::clamp((rp - tap.distance) * tap.inv_soft + 0.5f, 0.f, 1.f);
          if (coverage <= 0) continue;
          weight = tap.area * coverage;
          wb += weight;
          c = cb;
        }
        const float* src = rgb + 3 * q;
        c[0] += weight * src[0];
        c[1] += weight * src[1];
        c[2] += weight * src[2];
      }
      float result[3];
      const float alpha_same = wb > 0 ? std::min(1.f, ws) : 1.f;
      for (int k = 0; k < 3; ++k) {
        result[k] = alpha_same * cs[k] / ws;  // ws > 0: p covers itself
        if (wb > 0) result[k] += (1 - alpha_same) * cb[k] / wb;
      }
      if (wf > 0) {
        const float alpha_front = std::min(1.f, wf);
        for (int k = 0; k < 3; ++k) {
          result[k] = alpha_front * cf[k] / wf + (1 - alpha_front) * result[k];
        }
      }
      out[3 * p] = result[0];
      out[3 * p + 1] = result[1];
      out[3 * p + 2] = result[2];
    }
  }
}

}  // namespace

void apply_depth_of_field(const ir::Camera& camera, double focus_distance_m,
                          const Intrinsics& canvas, const std::vector<float>& rgb,
                          const std::vector<float>& depth_m, std::vector<float>& out) {
  const int w = canvas.width, h = canvas.height;
  const std::size_t n = static_cast<std::size_t>(w) * h;
  out.resize(rgb.size());
  const double f = camera.focal_length_m, f_number = camera.aperture_f_number;
  const bool possible = depth_m.size() == n && focus_distance_m > f && f > 0;
  if (!possible) {
    std::copy(rgb.begin(), rgb.end(), out.begin());
    return;
  }
  // Sensor metres to canvas pixels: fx / f.
  const double px_per_m = canvas.fx / f;
  std::vector<DepthRadius> zr(n);
  const int tiles_x = (w + kTile - 1) / kTile, tiles_y = (h + kTile - 1) / kTile;
  std::vector<float> tile_max(static_cast<std::size_t>(tiles_x) * tiles_y, 0.5f);
  tbb::parallel_for(tbb::blocked_range<int>(0, tiles_y), [&](const tbb::blocked_range<int>& r) {
    for (int ty = r.begin(); ty < r.end(); ++ty) {
      for (int y = ty * kTile; y < std::min(h, (ty + 1) * kTile); ++y) {
        for (int x = 0; x < w; ++x) {
          const std::size_t p = static_cast<std::size_t>(y) * w + x;
          float z = depth_m[p];
          if (!(z > 0)) z = std::numeric_limits<float>::infinity();
          const double c = coc_diameter_m(f, f_number, focus_distance_m, z);
          const float radius = static_cast<float>(
              std::clamp(0.5 * c * px_per_m, 0.5, static_cast<double>(kMaxCocRadiusPx)));
          zr[p] = {z, radius};
          float& m = tile_max[static_cast<std::size_t>(ty) * tiles_x + x / kTile];
          m = std::max(m, radius);
        }
      }
    }
  });
  // The largest disc that reaches each tile: spread every tile's maximum over the tiles it covers.
  std::vector<float> reach(tile_max.size(), 0.5f);
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const float m = tile_max[static_cast<std::size_t>(ty) * tiles_x + tx];
      const int span = static_cast<int>(std::ceil(m / kTile));
      for (int sy = std::max(0, ty - span); sy <= std::min(tiles_y - 1, ty + span); ++sy) {
        for (int sx = std::max(0, tx - span); sx <= std::min(tiles_x - 1, tx + span); ++sx) {
          float& r = reach[static_cast<std::size_t>(sy) * tiles_x + sx];
          r = std::max(r, m);
        }
      }
    }
  }
  const TapSet& set = tap_set();
  tbb::parallel_for(
      tbb::blocked_range2d<int>(0, tiles_y, 1, 0, tiles_x, 4), [&](const tbb::blocked_range2d<int>& r) {
        for (int ty = r.rows().begin(); ty < r.rows().end(); ++ty) {
          for (int tx = r.cols().begin(); tx < r.cols().end(); ++tx) {
            const int x0 = tx * kTile, x1 = std::min(w, x0 + kTile);
            const int y0 = ty * kTile, y1 = std::min(h, y0 + kTile);
            const float radius = reach[static_cast<std::size_t>(ty) * tiles_x + tx];
            if (radius <= 0.5f) {  // everything here and around it is sharp
              for (int y = y0; y < y1; ++y) {
                const std::size_t a = 3 * (static_cast<std::size_t>(y) * w + x0);
                std::copy(rgb.begin() + a, rgb.begin() + a + 3 * (x1 - x0), out.begin() + a);
              }
              continue;
            }
            const int reach_px = static_cast<int>(std::ceil(radius));
            const int tap_count = set.count_for_radius[std::min<int>(
                reach_px, static_cast<int>(set.count_for_radius.size()) - 1)];
            const int margin = reach_px + 1;
            if (x0 - margin >= 0 && y0 - margin >= 0 && x1 + margin <= w && y1 + margin <= h) {
              gather_tile<false>(set, tap_count, x0, x1, y0, y1, w, h, rgb.data(), zr.data(),
                                 out.data());
            } else {
              gather_tile<true>(set, tap_count, x0, x1, y0, y1, w, h, rgb.data(), zr.data(),
                                out.data());
            }
          }
        }
      });
}

double apply_diffraction(const ir::Camera& camera, const Intrinsics& canvas,
                         std::vector<float>& rgb, std::vector<float>& scratch) {
  if (!(camera.focal_length_m > 0)) return 0;
  const double sigma =
      diffraction_sigma_m(camera.aperture_f_number) * canvas.fx / camera.focal_length_m;
  if (sigma < 0.2) return 0;
  const int radius = static_cast<int>(std::ceil(3 * sigma));
  std::vector<float> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k) sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (float& k : kernel) k = static_cast<float>(k / sum);
  const int w = canvas.width, h = canvas.height;
  scratch.resize(rgb.size());
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      const float* row = &rgb[3 * static_cast<std::size_t>(y) * w];
      float* dst = &scratch[3 * static_cast<std::size_t>(y) * w];
      for (int x = 0; x < w; ++x) {
        float acc[3] = {0, 0, 0};
        for (int k = -radius; k <= radius; ++k) {
          const int xs = std::clamp(x + k, 0, w - 1);
          const float kw = kernel[k + radius];
          for (int c = 0; c < 3; ++c) acc[c] += kw * row[3 * xs + c];
        }
        for (int c = 0; c < 3; ++c) dst[3 * x + c] = acc[c];
      }
    }
  });
  tbb::parallel_for(tbb::blocked_range<int>(0, h), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      float* dst = &rgb[3 * static_cast<std::size_t>(y) * w];
      for (int i = 0; i < 3 * w; ++i) dst[i] = 0;
      for (int k = -radius; k <= radius; ++k) {
        const int ys = std::clamp(y + k, 0, h - 1);
        const float kw = kernel[k + radius];
        const float* src = &scratch[3 * static_cast<std::size_t>(ys) * w];
        for (int i = 0; i < 3 * w; ++i) dst[i] += kw * src[i];
      }
    }
  });
  return sigma;
}

}  // namespace rigc::dslr
