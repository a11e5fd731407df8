// The sweep's plots: each measure against each varied parameter, drawn with OpenImageIO.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "dslr/image_io.h"
#include "sweep/results.h"

namespace rigc::sweep {
namespace {

namespace fs = std::filesystem;
namespace IBA = OIIO::ImageBufAlgo;

constexpr int kWidth = 720, kHeight = 440;
constexpr int kLeft = 90, kRight = 30, kTop = 50, kBottom = 70;

struct Point {
  int x_index;
  double y;
};

void text(OIIO::ImageBuf& image, int x, int y, const std::string& s, int size,
          IBA::TextAlignX align = IBA::TextAlignX::Center) {
  const float black[3] = {0.1f, 0.1f, 0.1f};
  IBA::render_text(image, x, y, s, size, "DejaVuSans", black, align);
}

void dot(OIIO::ImageBuf& image, int x, int y, const float* colour) {
  IBA::render_box(image, x - 3, y - 3, x + 3, y + 3, OIIO::cspan<float>(colour, 3), true);
}

// One plot: points for every variant at its value of the axis, a line through the means.
bool draw_plot(const fs::path& path, const std::string& title, const Axis& axis,
               const std::vector<Point>& points, std::string* error) {
  OIIO::ImageBuf image(OIIO::ImageSpec(kWidth, kHeight, 3, OIIO::TypeDesc::UINT8));
  const float white[3] = {1, 1, 1}, grey[3] = {0.85f, 0.85f, 0.85f}, ink[3] = {0.1f, 0.1f, 0.1f};
  const float blue[3] = {0.2f, 0.4f, 0.8f}, red[3] = {0.85f, 0.2f, 0.15f};
  IBA::fill(image, white);
  double lo = points[0].y, hi = points[0].y;
  for (const Point& p : points) lo = std::min(lo, p.y), hi = std::max(hi, p.y);
  const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(1e-3, std::abs(hi) * 0.05);
  const AxisTicks ticks = nice_ticks(lo - pad, hi + pad);
  lo = ticks.values.front();
  hi = ticks.values.back();
  const int plot_w = kWidth - kLeft - kRight, plot_h = kHeight - kTop - kBottom;
  const int n = static_cast<int>(axis.values.size());
  auto px = [&](int i) { return kLeft + static_cast<int>((i + 0.5) * plot_w / n); };
  auto py = [&](double y) { return kTop + static_cast<int>((hi - y) / (hi - lo) * plot_h); };
  for (const double y : ticks.values) {
    IBA::render_line(image, kLeft, py(y), kWidth - kRight, py(y), grey);
    text(image, kLeft - 8, py(y) + 5, fmt::format("{:.{}f}", y, ticks.decimals), 14,
         IBA::TextAlignX::Right);
  }
  IBA::render_box(image, kLeft, kTop, kWidth - kRight, kTop + plot_h, ink, false);
  std::vector<double> sum(n, 0);
  std::vector<int> count(n, 0);
  for (const Point& p : points) {
    sum[p.x_index] += p.y;
    ++count[p.x_index];
  }
  int previous = -1;
  for (int i = 0; i < n; ++i) {
    text(image, px(i), kTop + plot_h + 22, axis.values[i].text, 14);
    if (!count[i]) continue;
    if (previous >= 0) {
      IBA::render_line(image, px(previous), py(sum[previous] / count[previous]), px(i),
                       py(sum[i] / count[i]), red);
    }
    previous = i;
  }
  for (const Point& p : points) dot(image, px(p.x_index), py(p.y), blue);
  text(image, kWidth / 2, 30, title, 18);
  text(image, kLeft + plot_w / 2, kHeight - 18, axis.path + "   (dots: variants, line: mean)", 14);
  return dslr::write_image_buffer(path, image, error);
}

}  // namespace

AxisTicks nice_ticks(double lo, double hi, int count) {
  const double raw = std::max(hi - lo, 1e-12) / std::max(count, 1);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = 10 * magnitude;
  for (const double m : {1.0, 2.0, 5.0}) {
    if (m * magnitude >= raw) {
      step = m * magnitude;
      break;
    }
  }
  AxisTicks ticks;
  ticks.decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  const long first = static_cast<long>(std::floor(lo / step + 1e-9));
  const long last = static_cast<long>(std::ceil(hi / step - 1e-9));
  for (long k = first; k <= std::max(last, first + 1); ++k) {
    // Rounded to the printed decimals: 3 x 0.2 is 0.6, not 0.6000000000000001.
    const double scale = std::pow(10.0, ticks.decimals);
    ticks.values.push_back(std::round(k * step * scale) / scale);
  }
  return ticks;
}

std::vector<std::string> write_plots(const fs::path& sweep_dir, const SweepSpec& spec,
                                     const std::vector<ResultRow>& rows, std::string* error) {
  std::vector<std::string> written;
  std::error_code ec;
  fs::create_directories(sweep_dir / "plots", ec);
  for (std::size_t a = 0; a < spec.axes.size(); ++a) {
    if (spec.axes[a].values.size() < 2) continue;
    for (std::size_t m = 0; m < measures().size(); ++m) {
      std::vector<Point> points;
      for (const ResultRow& r : rows) {
        if (r.ok && r.numbers[m]) points.push_back({r.variant->value_index[a], *r.numbers[m]});
      }
      if (points.empty()) continue;
      const std::string name =
          fmt::format("plots/{}_vs_{}.png", measures()[m].key, folder_name(spec.axes[a].path, 60));
      const std::string title = fmt::format("{} by {}", measures()[m].title, spec.axes[a].path);
      if (!draw_plot(sweep_dir / name, title, spec.axes[a], points, error)) return written;
      written.push_back(name);
    }
  }
  return written;
}

}  // namespace rigc::sweep
