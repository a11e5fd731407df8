#include "eval/metrics.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "dslr/image_io.h"
#include "io/atomic_file.h"
#include "io/files.h"

namespace rigc::eval {

namespace fs = std::filesystem;

namespace {

// The q-quantile with linear interpolation between the order statistics at floor and ceil of
// q·(n-1), as on a sorted copy, but by selection: `values` is reordered, not sorted.
double percentile(std::vector<double>& values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const double pos = q * static_cast<double>(values.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  const double f = pos - static_cast<double>(lo);
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo), values.end());
  const double at_lo = values[lo];
  // After the selection everything past lo is >= values[lo]: the next order statistic is the
  // smallest of them.
  const double at_hi =
      hi == lo ? at_lo
               : *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(hi), values.end());
  return at_lo * (1 - f) + at_hi * f;
}

// 8-bit RGB canvas, written as a PNG through OpenImageIO.
struct Canvas {
  int width, height;
  std::vector<std::uint8_t> rgb;
  Canvas(int w, int h, std::array<std::uint8_t, 3> background)
      : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3) {
    for (std::size_t i = 0; i < rgb.size(); i += 3) std::memcpy(&rgb[i], background.data(), 3);
  }
  void set(int x, int y, std::array<std::uint8_t, 3> c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    std::memcpy(&rgb[(static_cast<std::size_t>(y) * width + x) * 3], c.data(), 3);
  }
  void rect(int x0, int y0, int x1, int y1, std::array<std::uint8_t, 3> c) {
    for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
      for (int x = std::max(0, x0); x < std::min(width, x1); ++x) set(x, y, c);
  }
};

struct Label {
  int x, y;
  std::string text;
  int size;
  OIIO::ImageBufAlgo::TextAlignX align = OIIO::ImageBufAlgo::TextAlignX::Left;
};

bool write_canvas(const fs::path& path, const Canvas& canvas, const std::vector<Label>& labels,
                  float text_grey, std::string* error) {
  OIIO::ImageSpec spec(canvas.width, canvas.height, 3, OIIO::TypeDesc::UINT8);
  OIIO::ImageBuf copy(spec);
  copy.set_pixels(OIIO::ROI::All(), OIIO::TypeDesc::UINT8, canvas.rgb.data());
  const float colour[3] = {text_grey, text_grey, text_grey};
  for (const Label& l : labels) {
    // Needs a font (fonts-dejavu); without one the picture just has no text.
    OIIO::ImageBufAlgo::render_text(copy, l.x, l.y, l.text, l.size, "DejaVuSans", colour, l.align);
  }
  return dslr::write_image_buffer(path, copy, error);
}

}  // namespace

DistanceStats distance_stats(const std::vector<double>& d) {
  DistanceStats s;
  std::vector<double> values, absolute;
  values.reserve(d.size());
  for (double x : d) {
    if (std::isfinite(x)) values.push_back(x);
  }
  s.count = values.size();
  if (values.empty()) return s;
  double sum = 0, sum_abs = 0, sum_sq = 0;
  absolute.reserve(values.size());
  for (double x : values) {
    sum += x;
    sum_abs += std::abs(x);
    sum_sq += x * x;
    absolute.push_back(std::abs(x));
  }
  const double n = static_cast<double>(values.size());
  s.mean = sum / n;
  s.mean_abs = sum_abs / n;
  s.rms = std::sqrt(sum_sq / n);
  double var = 0;
  for (double x : values) var += (x - s.mean) * (x - s.mean);
  s.stddev = values.size() > 1 ? std::sqrt(var / (n - 1)) : 0;
  const auto [min, max] = std::minmax_element(values.begin(), values.end());
  s.min = *min;
  s.max = *max;
  s.median = percentile(values, 0.5);
  s.p90_abs = percentile(absolute, 0.9);
  return s;
}

FScore f_score(const std::vector<double>& reconstruction_to_truth,
               const std::vector<double>& truth_to_reconstruction, double tau) {
  auto share = [tau](const std::vector<double>& d) {
    if (d.empty()) return 0.0;
    std::size_t within = 0;
    for (double x : d) within += std::abs(x) < tau ? 1 : 0;
    return static_cast<double>(within) / static_cast<double>(d.size());
  };
  FScore f;
  f.tau = tau;
  f.precision = share(reconstruction_to_truth);
  f.recall = share(truth_to_reconstruction);
  f.fscore = f.precision + f.recall > 0 ? 2 * f.precision * f.recall / (f.precision + f.recall) : 0;
  return f;
}

std::array<std::uint8_t, 3> signed_distance_color(double d, double range) {
  if (!std::isfinite(d)) return {128, 128, 128};
  double x = range > 0 ? d / range : 0;  // -1 .. 1
  x = std::clamp(x, -1.0, 1.0);
  // Stops: -1 blue, -0.5 cyan, 0 green, 0.5 yellow, 1 red.
  double r, g, b;
  if (x < -0.5) {
    const double f = (x + 1) / 0.5;
    r = 0, g = f, b = 1;
  } else if (x < 0) {
    const double f = (x + 0.5) / 0.5;
    r = 0, g = 1, b = 1 - f;
  } else if (x < 0.5) {
    const double f = x / 0.5;
    r = f, g = 1, b = 0;
  } else {
    const double f = (x - 0.5) / 0.5;
    r = 1, g = 1 - f, b = 0;
  }
  auto byte = [](double v) { return static_cast<std::uint8_t>(std::lround(255 * v)); };
  return {byte(r), byte(g), byte(b)};
}

bool write_colored_ply(const fs::path& path, const std::vector<Vec3>& points,
                       const std::vector<double>& signed_distance_mm, double range_mm,
                       std::string* error) {
  std::string out = fmt::format(
      "ply\nformat binary_little_endian 1.0\ncomment RigC evaluation: signed distance to the "
      "ground truth in mm, colour range +-{:.3f} mm\nelement vertex {}\nproperty float x\n"
      "property float y\nproperty float z\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nproperty float scalar_signed_distance_mm\nend_header\n",
      range_mm, points.size());
  const std::size_t header = out.size();
  out.resize(header + points.size() * 19);
  char* p = out.data() + header;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const float xyz[3] = {static_cast<float>(points[i].x()), static_cast<float>(points[i].y()),
                          static_cast<float>(points[i].z())};
    const double d = i < signed_distance_mm.size() ? signed_distance_mm[i] : 0.0;
    const auto c = signed_distance_color(d, range_mm);
    const float df = static_cast<float>(d);
    std::memcpy(p, xyz, 12);
    std::memcpy(p + 12, c.data(), 3);
    std::memcpy(p + 15, &df, 4);
    p += 19;
  }
  return rigc::write_file_atomically(path, out, error);
}

bool write_histogram_png(const fs::path& path, const std::vector<double>& d_mm, double range_mm,
                         const DistanceStats& stats, std::string* error) {
  const int width = 900, height = 420;
  const int left = 60, right = 20, top = 40, bottom = 60;
  const int plot_w = width - left - right, plot_h = height - top - bottom;
  const int bins = 60;
  const double lo = -range_mm, hi = range_mm;
  std::vector<std::size_t> counts(bins, 0);
  for (double d : d_mm) {
    if (!std::isfinite(d)) continue;
    int b = static_cast<int>(std::floor((d - lo) / (hi - lo) * bins));
    counts[std::clamp(b, 0, bins - 1)]++;  // outside the range: in the end bins
  }
  const std::size_t peak =
      std::max<std::size_t>(1, *std::max_element(counts.begin(), counts.end()));
  Canvas canvas(width, height, {255, 255, 255});
  canvas.rect(left, top + plot_h, left + plot_w, top + plot_h + 1, {0, 0, 0});
  canvas.rect(left - 1, top, left, top + plot_h, {0, 0, 0});
  for (int b = 0; b < bins; ++b) {
    const int x0 = left + b * plot_w / bins;
    const int x1 = left + (b + 1) * plot_w / bins - 1;
    const int h = static_cast<int>(std::lround(static_cast<double>(counts[b]) / peak * plot_h));
    const double centre = lo + (b + 0.5) * (hi - lo) / bins;
    canvas.rect(x0, top + plot_h - h, x1, top + plot_h, signed_distance_color(centre, range_mm));
  }
  auto x_of = [&](double v) {
    return left + static_cast<int>(std::lround((v - lo) / (hi - lo) * plot_w));
  };
  std::vector<Label> labels;
  for (int k = -4; k <= 4; ++k) {
    const double v = range_mm * k / 4.0;
    const int x = x_of(v);
    canvas.rect(x, top + plot_h, x + 1, top + plot_h + 6, {0, 0, 0});
    labels.push_back({x, top + plot_h + 22, fmt::format("{:.2f}", v), 13,
                      OIIO::ImageBufAlgo::TextAlignX::Center});
  }
  if (stats.count > 0) {
    const int xm = x_of(std::clamp(stats.mean, lo, hi));
    canvas.rect(xm, top, xm + 2, top + plot_h, {0, 0, 0});
    for (double s : {stats.mean - stats.stddev, stats.mean + stats.stddev}) {
      const int xs = x_of(std::clamp(s, lo, hi));
      for (int y = top; y < top + plot_h; y += 8) canvas.rect(xs, y, xs + 1, y + 4, {0, 0, 0});
    }
  }
  labels.push_back({width / 2, height - 12, "signed distance to the ground truth (mm)", 15,
                    OIIO::ImageBufAlgo::TextAlignX::Center});
  labels.push_back(
      {left, 26,
       fmt::format("{} points   mean {:.3f} mm   std {:.3f} mm   median {:.3f} mm   "
                   "p90|d| {:.3f} mm   (peak {} points per bin)",
                   stats.count, stats.mean, stats.stddev, stats.median, stats.p90_abs, peak),
       14});
  return write_canvas(path, canvas, labels, 0.1f, error);
}

bool write_heatmap_png(const fs::path& path, const Surface& surface, const ViewCamera& camera,
                       const std::vector<Vec3>& points, const std::vector<double>& d_mm,
                       double range_mm, int max_width, std::string* error) {
  const double k = camera.width > max_width ? static_cast<double>(max_width) / camera.width : 1.0;
  const int w = std::max(1, static_cast<int>(std::lround(camera.width * k)));
  const int h = std::max(1, static_cast<int>(std::lround(camera.height * k)));
  const double fx = camera.fx * k, fy = camera.fy * k, cx = camera.cx * k, cy = camera.cy * k;
  const Eigen::Matrix3d r = camera.camera_from_world.topLeftCorner<3, 3>();
  const Vec3 t = camera.camera_from_world.topRightCorner<3, 1>();
  const Vec3 eye = camera.center();
  // Grey-shaded surface by ray casting (headlight), depth kept for the splats' depth test.
  std::vector<Vec3> origins(static_cast<std::size_t>(w) * h, eye), directions(origins.size());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Vec3 dc((x + 0.5 - cx) / fx, (y + 0.5 - cy) / fy, 1.0);
      directions[static_cast<std::size_t>(y) * w + x] = r.transpose() * dc;  // z_cam = t
    }
  }
  const RayHits hits = surface.cast_rays(origins, directions);
  Canvas canvas(w, h, {40, 40, 48});
  std::vector<float> depth(origins.size(), std::numeric_limits<float>::infinity());
  for (std::size_t i = 0; i < origins.size(); ++i) {
    if (!std::isfinite(hits.t[i])) continue;
    depth[i] = hits.t[i];
    const Vec3 n = hits.normals[i].cast<double>().normalized();
    const double shade = 0.25 + 0.6 * std::abs(n.dot(directions[i].normalized()));
    const auto g = static_cast<std::uint8_t>(std::lround(255 * shade));
    canvas.set(static_cast<int>(i % w), static_cast<int>(i / w), {g, g, g});
  }
  // Splats, far to near, hidden when well behind the surface. Points on one pixel have the same
  // disk, so only the nearest of them shows: one per pixel is sorted, not every point.
  const double tolerance = 0.01 * (surface.bounds().diagonal().norm());
  constexpr std::size_t kNoPoint = ~std::size_t{0};
  std::vector<std::size_t> nearest(origins.size(), kNoPoint);
  std::vector<double> nearest_z(origins.size(), std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Vec3 pc = r * points[i] + t;
    if (!(pc.z() > 0)) continue;
    const int u = static_cast<int>(std::floor(fx * pc.x() / pc.z() + cx));
    const int v = static_cast<int>(std::floor(fy * pc.y() / pc.z() + cy));
    if (u < 0 || v < 0 || u >= w || v >= h) continue;
    const std::size_t pixel = static_cast<std::size_t>(v) * w + u;
    if (pc.z() > depth[pixel] + tolerance || pc.z() >= nearest_z[pixel]) continue;
    nearest[pixel] = i;
    nearest_z[pixel] = pc.z();
  }
  std::vector<std::pair<double, std::size_t>> order;  // (depth, pixel)
  for (std::size_t pixel = 0; pixel < nearest.size(); ++pixel) {
    if (nearest[pixel] != kNoPoint) order.emplace_back(nearest_z[pixel], pixel);
  }
  std::sort(order.begin(), order.end(), [](auto& a, auto& b) { return a.first > b.first; });
  const int radius = std::max(1, static_cast<int>(std::lround(w / 400.0)));
  for (const auto& [z, pixel] : order) {
    const int u = static_cast<int>(pixel % w), v = static_cast<int>(pixel / w);
    const auto c = signed_distance_color(d_mm[nearest[pixel]], range_mm);
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx)
        if (dx * dx + dy * dy <= radius * radius) canvas.set(u + dx, v + dy, c);
  }
  // Colour bar.
  const int bar_w = std::max(100, w / 3), bar_h = std::max(8, h / 50);
  const int bx = w - bar_w - 20, by = h - bar_h - 30;
  for (int x = 0; x < bar_w; ++x) {
    const double v = range_mm * (2.0 * x / (bar_w - 1) - 1);
    canvas.rect(bx + x, by, bx + x + 1, by + bar_h, signed_distance_color(v, range_mm));
  }
  std::vector<Label> labels = {{bx, by - 6, fmt::format("-{:.2f} mm", range_mm), 13},
                               {bx + bar_w, by - 6, fmt::format("+{:.2f} mm", range_mm), 13,
                                OIIO::ImageBufAlgo::TextAlignX::Right}};
  return write_canvas(path, canvas, labels, 0.95f, error);
}

}  // namespace rigc::eval
