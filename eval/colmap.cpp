#include "eval/colmap.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>

#include "io/child_processes.h"
#include "io/files.h"

namespace rigc::eval {

namespace fs = std::filesystem;

int run_logged(const std::vector<std::string>& argv, const fs::path& log, std::string* error,
               double* cpu_seconds) {
  if (argv.empty()) {
    *error = "no program to run";
    return -1;
  }
  {
    std::ofstream header(log, std::ios::app);
    if (!header) {
      *error = fmt::format("cannot write the log {}", log.string());
      return -1;
    }
    header << "$";
    for (const auto& a : argv) header << " " << a;
    header << "\n";
  }
  // COLMAP's Qt needs no display to extract and match.
  const rigc::ChildResult child = rigc::run_child({argv, log, {}, {"QT_QPA_PLATFORM=offscreen"}});
  if (!child.started || child.exit_code < 0) {
    *error = child.error;
    return -1;
  }
  if (cpu_seconds) *cpu_seconds = child.cpu_seconds;
  return child.exit_code;
}

namespace {

std::string read_all(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

std::optional<ColmapFlags> probe_colmap(const std::string& executable, const fs::path& log_dir,
                                        std::string* error) {
  ColmapFlags flags;
  const fs::path log = log_dir / "colmap_probe.log";
  std::error_code ec;
  fs::remove(log, ec);
  std::string why;
  int rc = run_logged({executable, "feature_extractor", "-h"}, log, &why);
  if (rc < 0) {
    *error = fmt::format(
        "COLMAP is not available ({}); install Debian's colmap package "
        "(scripts/setup.sh) or pass --colmap PATH",
        why);
    return std::nullopt;
  }
  std::string text = read_all(log);
  if (text.find("SiftExtraction.use_gpu") != std::string::npos) {
    flags.extraction_gpu = "--SiftExtraction.use_gpu";
  } else if (text.find("FeatureExtraction.use_gpu") != std::string::npos) {
    flags.extraction_gpu = "--FeatureExtraction.use_gpu";
  } else if (text.find("ImageReader") == std::string::npos) {
    *error = fmt::format("`{} feature_extractor -h` does not look like COLMAP (exit {}); see {}",
                         executable, rc, log.string());
    return std::nullopt;
  }
  fs::remove(log, ec);
  rc = run_logged({executable, "exhaustive_matcher", "-h"}, log, &why);
  text = read_all(log);
  if (text.find("SiftMatching.use_gpu") != std::string::npos) {
    flags.matching_gpu = "--SiftMatching.use_gpu";
  } else if (text.find("FeatureMatching.use_gpu") != std::string::npos) {
    flags.matching_gpu = "--FeatureMatching.use_gpu";
  }
  fs::remove(log, ec);
  run_logged({executable, "matches_importer", "-h"}, log, &why);
  text = read_all(log);
  flags.imports_pair_lists = text.find("match_list_path") != std::string::npos &&
                             text.find("match_type") != std::string::npos;
  fs::remove(log, ec);
  run_logged({executable, "-h"}, log, &why);
  std::istringstream lines(read_all(log));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind("COLMAP", 0) == 0) {
      flags.version = line;
      break;
    }
  }
  return flags;
}

std::vector<std::pair<int, int>> neighbour_pairs(const std::vector<ir::Vec3>& optical_axes,
                                                 const NeighbourPairOptions& options) {
  const int n = static_cast<int>(optical_axes.size());
  // A thousandth of a degree of slack: 3 x 15 deg read back from text is not exactly 45.
  const double max_angle = (options.max_angle_deg + 1e-3) * M_PI / 180;
  std::vector<std::pair<int, int>> pairs;
  std::vector<double> angle(n);
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) {
    const ir::Vec3 a = optical_axes[i].normalized();
    for (int j = 0; j < n; ++j) {
      const ir::Vec3 b = optical_axes[j].normalized();
      angle[j] = std::atan2(a.cross(b).norm(), a.dot(b));  // accurate for small angles too
    }
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int x, int y) { return angle[x] < angle[y]; });
    int taken = 0;
    for (int j : order) {
      if (j == i) continue;
      const bool near = angle[j] <= max_angle && taken < options.max_per_image;
      if (!near && taken >= options.min_per_image) break;
      pairs.emplace_back(std::min(i, j), std::max(i, j));
      ++taken;
    }
  }
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  return pairs;
}

bool write_pair_list(const fs::path& path, const std::vector<std::string>& names,
                     const std::vector<std::pair<int, int>>& pairs, std::string* error) {
  std::string text;
  for (const auto& [i, j] : pairs) text += names.at(i) + " " + names.at(j) + "\n";
  return rigc::write_file_atomically(path, text, error);
}

double SparseModel::mean_track_length() const {
  if (points.empty()) return 0;
  double sum = 0;
  for (const auto& p : points) sum += static_cast<double>(p.track_images.size());
  return sum / static_cast<double>(points.size());
}

double SparseModel::mean_reprojection_error() const {
  double sum = 0, weight = 0;
  for (const auto& p : points) {
    const double w = static_cast<double>(p.track_images.size());
    sum += p.error * w;
    weight += w;
  }
  return weight > 0 ? sum / weight : 0;
}

std::optional<std::vector<Point3D>> read_colmap_points(const fs::path& path, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = fmt::format("{}: cannot read", path.string());
    return std::nullopt;
  }
  std::vector<Point3D> points;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream s(line);
    Point3D p;
    if (!(s >> p.id >> p.position.x() >> p.position.y() >> p.position.z() >> p.rgb[0] >> p.rgb[1] >>
          p.rgb[2] >> p.error)) {
      *error = fmt::format("{}:{}: malformed point line", path.string(), number);
      return std::nullopt;
    }
    int image = 0, index = 0;
    while (s >> image >> index) p.track_images.push_back(image);
    points.push_back(std::move(p));
  }
  return points;
}

std::optional<SparseModel> read_sparse_model(const fs::path& dir, std::string* error) {
  SparseModel model;
  auto cameras = run::read_colmap_cameras(dir / "cameras.txt", error);
  if (!cameras) return std::nullopt;
  auto images = run::read_colmap_images(dir / "images.txt", error);
  if (!images) return std::nullopt;
  auto points = read_colmap_points(dir / "points3D.txt", error);
  if (!points) return std::nullopt;
  model.cameras = std::move(*cameras);
  model.images = std::move(*images);
  model.points = std::move(*points);
  return model;
}

}  // namespace rigc::eval
