#include "eval/silhouette.h"

#include <OpenImageIO/imagebuf.h>
#include <fmt/format.h>

namespace rigc::eval {

std::optional<Silhouette> read_silhouette(const std::filesystem::path& path, std::string* error) {
  OIIO::ImageBuf in(path.string());
  if (!in.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
    *error = fmt::format("cannot read the mask {}: {}", path.string(), in.geterror());
    return std::nullopt;
  }
  Silhouette s;
  s.width = in.spec().width;
  s.height = in.spec().height;
  s.coverage.resize(static_cast<std::size_t>(s.width) * s.height);
  in.get_pixels(OIIO::ROI(0, s.width, 0, s.height, 0, 1, 0, 1), OIIO::TypeDesc::FLOAT,
                s.coverage.data());
  return s;
}

double silhouette_iou(const Silhouette& a, const Silhouette& b) {
  std::size_t both = 0, either = 0;
  for (std::size_t i = 0; i < a.coverage.size() && i < b.coverage.size(); ++i) {
    const bool in_a = a.coverage[i] >= 0.5f, in_b = b.coverage[i] >= 0.5f;
    both += in_a && in_b;
    either += in_a || in_b;
  }
  return either ? static_cast<double>(both) / static_cast<double>(either) : 1.0;
}

}  // namespace rigc::eval
