#include "eval/photo_diagnosis.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>
#include <sstream>

namespace rigc::eval {

ImageStatistics image_statistics(const KeyImage& image, const std::vector<std::uint8_t>& mask) {
  const int w = image.width, h = image.height;
  std::vector<float> luma(image.pixels());
  for (std::size_t i = 0; i < luma.size(); ++i) {
    luma[i] = 0.2126f * image.srgb[3 * i] + 0.7152f * image.srgb[3 * i + 1] +
              0.0722f * image.srgb[3 * i + 2];
  }
  auto inside = [&](std::size_t i) { return mask.empty() || mask[i] != 0; };
  double sum = 0, lap_sum = 0, lap_sum2 = 0;
  std::size_t n = 0, n_lap = 0;
  std::vector<float> kept;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      if (!inside(i)) continue;
      sum += luma[i];
      kept.push_back(luma[i]);
      ++n;
      if (x == 0 || y == 0 || x == w - 1 || y == h - 1) continue;
      const double lap = luma[i - 1] + luma[i + 1] + luma[i - w] + luma[i + w] - 4.0 * luma[i];
      lap_sum += lap;
      lap_sum2 += lap * lap;
      ++n_lap;
    }
  }
  ImageStatistics s;
  if (n == 0) return s;
  s.mean_luma = sum / n / 255;
  const std::size_t p99 = std::min(kept.size() - 1, kept.size() * 99 / 100);
  std::nth_element(kept.begin(), kept.begin() + p99, kept.end());
  s.p99_luma = kept[p99] / 255;
  if (n_lap > 0) {
    const double mean = lap_sum / n_lap;
    s.sharpness = lap_sum2 / n_lap - mean * mean;
  }
  return s;
}

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The causes the image statistics show, against the set's medians.
std::vector<std::string> image_causes(const std::string& name, const DiagnosisInputs& in,
                                      double median_sharpness, double median_luma,
                                      double median_features) {
  std::vector<std::string> causes;
  const auto s = in.stats.find(name);
  if (s != in.stats.end()) {
    const ImageStatistics& st = s->second;
    const bool dark = st.p99_luma < 0.25 || st.mean_luma < 0.5 * median_luma;
    if (dark) {
      causes.push_back(fmt::format(
          "under-exposed (mean luma {:.2f} against the set's median {:.2f}, brightest 1 % "
          "below {:.2f})",
          st.mean_luma, median_luma, st.p99_luma));
    }
    // A dark image has little contrast to sharpen: blur is only told in a lit one.
    if (!dark && st.sharpness < 0.4 * median_sharpness) {
      causes.push_back(fmt::format("blurred (sharpness {:.0f} against the set's median {:.0f})",
                                   st.sharpness, median_sharpness));
    }
  }
  const auto f = in.features.find(name);
  if (f != in.features.end() && f->second < 0.3 * median_features) {
    causes.push_back(fmt::format("few features ({:.0f} against the set's median {:.0f})", f->second,
                                 median_features));
  }
  return causes;
}

}  // namespace

std::map<std::string, std::vector<std::string>> diagnose_unregistered(const DiagnosisInputs& in) {
  std::vector<double> sharpness, luma, features;
  for (const auto& [name, s] : in.stats) {
    sharpness.push_back(s.sharpness);
    luma.push_back(s.mean_luma);
  }
  for (const auto& [name, f] : in.features) features.push_back(f);
  const double median_sharpness = median(sharpness), median_luma = median(luma);
  const double median_features = median(features);
  std::map<std::string, std::vector<std::string>> result;
  const std::size_t n = in.order.size();
  for (std::size_t k = 0; k < n; ++k) {
    const std::string& name = in.order[k];
    if (in.registered.count(name)) continue;
    auto causes = image_causes(name, in, median_sharpness, median_luma, median_features);
    if (!in.masked && in.still_fraction > 0.3) {
      causes.push_back(fmt::format(
          "no masks and a static background ({:.0f} % of the pixels stay still from photo to "
          "photo: the object turns, the background does not; a chroma key or --masks helps)",
          100 * in.still_fraction));
    }
    const std::string& before = in.order[(k + n - 1) % n];
    const std::string& after = in.order[(k + 1) % n];
    if (causes.empty() || (!in.registered.count(before) && !in.registered.count(after))) {
      causes.push_back(fmt::format(
          "too little overlap with its neighbours in capture order ({}, {}{})", before, after,
          in.registered.count(before) || in.registered.count(after) ? "" : ", unregistered too"));
    }
    result[name] = std::move(causes);
  }
  return result;
}

std::map<std::string, double> features_by_image(const std::string& log_text) {
  static const std::regex name_re(R"(^\s*Name:\s*(\S.*?)\s*$)");
  static const std::regex features_re(R"(^\s*Features:\s*(\d+))");
  std::map<std::string, double> features;
  std::istringstream lines(log_text);
  std::string line, name;
  std::smatch m;
  while (std::getline(lines, line)) {
    if (std::regex_search(line, m, name_re)) {
      name = m[1];
    } else if (!name.empty() && std::regex_search(line, m, features_re)) {
      features[name] = std::stod(m[1]);
      name.clear();
    }
  }
  return features;
}

}  // namespace rigc::eval
