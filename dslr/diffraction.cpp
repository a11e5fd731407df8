#include "dslr/diffraction.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <type_traits>
#include <utility>

#include "dslr/buffer_pool.h"
#include "dslr/image_view.h"
#include "dslr/simd.h"

// The 32-byte vectors are only passed between inlined functions, so GCC's note on their ABI
// without AVX does not apply.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace rigc::dslr {

double diffraction_sigma_m(double f_number, double wavelength_m) {
  return 0.42 * wavelength_m * f_number;
}

int diffraction_radius_px(double sigma_px) {
  // exp(-r² / 2σ²) >= 1e-3 for r <= σ·sqrt(2 ln 1000).
  const double kept = sigma_px * std::sqrt(2 * std::log(1000.0));
  return std::max(1, static_cast<int>(std::min(std::ceil(3 * sigma_px), std::floor(kept))));
}

namespace {

using Floats = simd::F32x8;
using simd::load8;
constexpr int kLanes = 8;

// The normalised weights of taps -radius .. radius.
std::vector<float> gaussian_kernel(double sigma, int radius) {
  std::vector<float> kernel(2 * radius + 1);
  double sum = 0;
  for (int k = -radius; k <= radius; ++k)
    sum += kernel[k + radius] = std::exp(-0.5 * k * k / (sigma * sigma));
  for (float& k : kernel) k = static_cast<float>(k / sum);
  return kernel;
}

// fn(std::integral_constant<int, taps>) where the tap count is one of the common ones (radius
// 1 to 4: about f/5.7 to f/38 on a 6D at full size), so its loops unroll with the weights and
// rows in registers; the caller's generic loops run otherwise.
template <typename Fn>
void with_common_tap_count(int taps, Fn&& fn) {
  [&]<int... kTaps>(std::integer_sequence<int, kTaps...>) {
    static_cast<void>(((taps == kTaps && (fn(std::integral_constant<int, kTaps>{}), true)) || ...));
  }
  (std::integer_sequence<int, 3, 5, 7, 9>{});
}

// The separable Gaussian in one pass, in place: each band of rows keeps the horizontally blurred
// rows its vertical taps need in a ring (2·radius + 1 rows: three at f/13 on a 6D, about 200 KB,
// which stays in cache), so the frame is read once and written once where it lies (a second
// output frame would have its lines read in first).
//
// Rows within `radius` of a border between two bands are read by both, and the band below may
// write them before the band above has read them, and the other way round. They are blurred
// horizontally before any band writes (into `border_rows_`), and both bands take them from
// there. Bands are at least 2·radius tall: no row is near two borders.
class GaussianBlur {
 public:
  // Over `rgb`, which must not be empty.
  GaussianBlur(ImageView<float> rgb, double sigma, int radius)
      : rgb_(rgb.values),
        w_(rgb.width),
        h_(rgb.height),
        radius_(radius),
        taps_(2 * radius + 1),
        kernel_(gaussian_kernel(sigma, radius)),
        row_values_(3 * static_cast<std::size_t>(rgb.width)),
        band_rows_(std::max(96, 2 * radius)),
        bands_((rgb.height + band_rows_ - 1) / band_rows_),
        borders_(bands_ - 1),
        border_span_(2 * radius),
        border_rows_(take_floats(static_cast<std::size_t>(borders_) * border_span_ * row_values_)) {
  }
  ~GaussianBlur() { recycle(std::move(border_rows_)); }

  void run() {
    blur_border_rows();
    tbb::parallel_for(tbb::blocked_range<int>(0, bands_, 1), [&](const tbb::blocked_range<int>& r) {
      std::vector<float> ring(static_cast<std::size_t>(taps_) * row_values_);
      std::vector<const float*> rows(taps_);
      for (int band = r.begin(); band < r.end(); ++band) {
        blur_band(band, ring, rows);
      }
    });
  }

 private:
  // Row y (clamped to the frame) blurred horizontally into dst.
  void blur_row(int y, float* dst) const;
  // Output row `dst` from the horizontally blurred rows y - radius .. y + radius, top first.
  void blur_column(float* dst, const std::vector<const float*>& rows) const;

  // The horizontally blurred row y from `border_rows_`, or null when y is near no border.
  float* border_row(int y) {
    const int k = (y + radius_) / band_rows_ - 1;  // the last border at or above row y + radius
    if (k < 0 || k >= borders_) return nullptr;
    const int from = (k + 1) * band_rows_ - radius_;
    if (y < from || y >= from + border_span_) return nullptr;
    return &border_rows_[(static_cast<std::size_t>(k) * border_span_ + (y - from)) * row_values_];
  }

  void blur_border_rows() {
    tbb::parallel_for(0, borders_ * border_span_, [&](int i) {
      const int y = (i / border_span_ + 1) * band_rows_ - radius_ + i % border_span_;
      blur_row(y, border_row(y));
    });
  }

  // `ring`: 2·radius + 1 rows; `rows`: as many pointers.
  void blur_band(int band, std::vector<float>& ring, std::vector<const float*>& rows) {
    auto ring_row = [&](int y) {  // the slot of row y (y may lie past the frame's edges)
      return &ring[static_cast<std::size_t>(((y % taps_) + taps_) % taps_) * row_values_];
    };
    auto fill = [&](int y) {
      if (!border_row(y)) blur_row(y, ring_row(y));
    };
    auto blurred = [&](int y) -> const float* {
      const float* kept = border_row(y);
      return kept ? kept : ring_row(y);
    };
    const int y0 = band * band_rows_, y1 = std::min(h_, y0 + band_rows_);
    for (int y = y0 - radius_; y < y0 + radius_; ++y) fill(y);
    for (int y = y0; y < y1; ++y) {
      // Row y + radius is read before row y is written (and rows past it later still).
      fill(y + radius_);
      for (int k = -radius_; k <= radius_; ++k) rows[k + radius_] = blurred(y + k);
      blur_column(&rgb_[row_values_ * y], rows);
    }
  }

  float* rgb_;
  const int w_, h_, radius_, taps_;
  const std::vector<float> kernel_;
  const std::size_t row_values_;
  const int band_rows_, bands_, borders_;
  const int border_span_;  // rows [border - radius, border + radius)
  std::vector<float> border_rows_;
};

void GaussianBlur::blur_row(int y, float* dst) const {
  const int w = w_, radius = radius_;
  const std::vector<float>& kernel = kernel_;
  const float* row = &rgb_[row_values_ * std::clamp(y, 0, h_ - 1)];
  // On interleaved rows a tap k is an offset of 3k values, so the interior is one contiguous
  // multiply-add per tap; only the first and last `radius` pixels clamp.
  const int inner_begin = std::min(w, radius), inner_end = std::max(inner_begin, w - radius);
  // Eight values at a time, summed over the taps in a register and stored once.
  int i = 3 * inner_begin;
  with_common_tap_count(static_cast<int>(kernel.size()), [&](auto fixed) {
    // Weights as locals: a float store could alias the kernel vector's floats.
    constexpr int kFixed = decltype(fixed)::value;
    constexpr int kFixedRadius = kFixed / 2;
    std::array<float, kFixed> weight;
    std::copy_n(kernel.begin(), kFixed, weight.begin());
    for (; i + kLanes <= 3 * inner_end; i += kLanes) {
      Floats acc = {};
      for (int k = -kFixedRadius; k <= kFixedRadius; ++k) {
        acc += weight[k + kFixedRadius] * load8(row + i + 3 * k);
      }
      std::memcpy(dst + i, &acc, sizeof acc);
    }
  });
  for (; i + kLanes <= 3 * inner_end; i += kLanes) {
    Floats acc = {};
    for (int k = -radius; k <= radius; ++k) acc += kernel[k + radius] * load8(row + i + 3 * k);
    std::memcpy(dst + i, &acc, sizeof acc);
  }
  for (; i < 3 * inner_end; ++i) {
    float acc = 0;
    for (int k = -radius; k <= radius; ++k) acc += kernel[k + radius] * row[i + 3 * k];
    dst[i] = acc;
  }
  auto clamped = [&](int x) {
    float acc[3] = {0, 0, 0};
    for (int k = -radius; k <= radius; ++k) {
      const int xs = std::clamp(x + k, 0, w - 1);
      for (int c = 0; c < 3; ++c) acc[c] += kernel[k + radius] * row[3 * xs + c];
    }
    for (int c = 0; c < 3; ++c) dst[3 * x + c] = acc[c];
  };
  for (int x = 0; x < inner_begin; ++x) clamped(x);
  for (int x = inner_end; x < w; ++x) clamped(x);
}

void GaussianBlur::blur_column(float* dst, const std::vector<const float*>& rows) const {
  const std::vector<float>& kernel = kernel_;
  const int taps = taps_;
  const std::size_t row_values = row_values_;
  std::size_t i = 0;
  with_common_tap_count(static_cast<int>(kernel.size()), [&](auto fixed) {
    constexpr int kFixed = decltype(fixed)::value;
    std::array<float, kFixed> weight;
    std::array<const float*, kFixed> source;
    std::copy_n(kernel.begin(), kFixed, weight.begin());
    std::copy_n(rows.begin(), kFixed, source.begin());
    for (; i + kLanes <= row_values; i += kLanes) {
      Floats acc = {};
      for (int t = 0; t < kFixed; ++t) acc += weight[t] * load8(source[t] + i);
      std::memcpy(dst + i, &acc, sizeof acc);
    }
  });
  for (; i + kLanes <= row_values; i += kLanes) {
    Floats acc = {};
    for (int t = 0; t < taps; ++t) acc += kernel[t] * load8(rows[t] + i);
    std::memcpy(dst + i, &acc, sizeof acc);
  }
  for (; i < row_values; ++i) {
    float acc = 0;
    for (int t = 0; t < taps; ++t) acc += kernel[t] * rows[t][i];
    dst[i] = acc;
  }
}

}  // namespace

double apply_diffraction(const ir::Camera& camera, const Intrinsics& canvas,
                         std::vector<float>& rgb) {
  if (!(camera.focal_length_m > 0)) return 0;
  const double sigma =
      diffraction_sigma_m(camera.aperture_f_number) * canvas.fx / camera.focal_length_m;
  if (sigma < 0.2) return 0;
  const ImageView<float> image = view_of(rgb, canvas.width, canvas.height);
  if (image.empty()) return sigma;
  GaussianBlur(image, sigma, diffraction_radius_px(sigma)).run();
  return sigma;
}

}  // namespace rigc::dslr
