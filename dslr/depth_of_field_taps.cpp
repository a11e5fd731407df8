#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "dslr/depth_of_field_level.h"

namespace rigc::dslr::dof {
namespace {

constexpr double kDenseRadius = 4.5, kRingRatio = 1.3;

}  // namespace

const TapSet& tap_set() {
  static const TapSet set = [] {
    struct Tap {
      int dx, dy;
      float distance, area, inv_soft;
    };
    std::vector<Tap> taps;
    const int d = static_cast<int>(kDenseRadius);
    for (int dy = -d; dy <= d; ++dy) {
      for (int dx = -d; dx <= d; ++dx) {
        const double r = std::hypot(dx, dy);
        if (r <= kDenseRadius) taps.push_back({dx, dy, float(r), 1.0f, 1.0f});
      }
    }
    int ring = 0;
    for (double inner = kDenseRadius; inner < kMaxCocRadiusPx + 1; inner *= kRingRatio, ++ring) {
      const double outer = inner * kRingRatio, width = outer - inner, rho = 0.5 * (inner + outer);
      // As many taps as keep their spacing along the ring equal to the ring width.
      const int n = static_cast<int>(std::lround(2 * std::numbers::pi * rho / width));
      const double area = std::numbers::pi * (outer * outer - inner * inner) / n;
      const double phase = ring * 2.399963;  // golden angle: rings do not line up
      for (int k = 0; k < n; ++k) {
        const double a = phase + 2 * std::numbers::pi * k / n;
        const int dx = static_cast<int>(std::lround(rho * std::cos(a)));
        const int dy = static_cast<int>(std::lround(rho * std::sin(a)));
        taps.push_back({dx, dy, float(std::hypot(dx, dy)), float(area), float(1 / width)});
      }
    }
    std::stable_sort(taps.begin(), taps.end(),
                     [](const Tap& a, const Tap& b) { return a.distance < b.distance; });
    TapSet s;
    for (const Tap& t : taps) {
      s.dx.push_back(t.dx);
      s.dy.push_back(t.dy);
      s.distance.push_back(t.distance);
      s.area.push_back(t.area);
      s.inv_soft.push_back(t.inv_soft);
    }
    s.count_for_quarter.assign(4 * (kMaxCocRadiusPx + 1) + 1, 0);
    for (int q = 0; q < static_cast<int>(s.count_for_quarter.size()); ++q) {
      for (int t = 0; t < static_cast<int>(taps.size()); ++t) {
        if (taps[t].distance - 0.5f / taps[t].inv_soft < q / 4.0f) s.count_for_quarter[q] = t + 1;
      }
    }
    s.extent_of_count.assign(taps.size() + 1, 0);
    for (std::size_t t = 0; t < taps.size(); ++t) {
      s.extent_of_count[t + 1] =
          std::max({s.extent_of_count[t], std::abs(taps[t].dx), std::abs(taps[t].dy)});
    }
    return s;
  }();
  return set;
}

MatchedRadius::MatchedRadius() {
  const TapSet& set = tap_set();
  auto moment = [&set](double radius) {
    double weight = 0, weighted = 0;
    for (std::size_t t = 0; t < set.distance.size(); ++t) {
      const double d = set.distance[t];
      const double w = set.area[t] * std::clamp((radius - d) * set.inv_soft[t] + 0.5, 0.0, 1.0);
      weight += w;
      weighted += w * d * d;
    }
    return weighted / weight;
  };
  for (int k = 0; k <= kTableEnd * kPerPixel; ++k) {
    const double r = static_cast<double>(k) / kPerPixel;
    if (r < kSharpBelow) {
      table_.push_back(0.5f);
      continue;
    }
    double low = 0.5, high = r + 1;  // the moment grows with the radius from 0 at half a pixel
    for (int step = 0; step < 32; ++step) {
      const double mid = 0.5 * (low + high);
      (moment(mid) < 0.5 * r * r ? low : high) = mid;
    }
    table_.push_back(static_cast<float>(0.5 * (low + high)));
  }
  tail_sq_ = kTableEnd * kTableEnd - table_.back() * table_.back();
}

const MatchedRadius& matched_radius() {
  static const MatchedRadius matched;
  return matched;
}

}  // namespace rigc::dslr::dof
