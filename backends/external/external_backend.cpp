#include "backends/external/external_backend.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <ostream>

#include "backends/external/process.h"
#include "backends/external/script_text.h"
#include "dslr/image_io.h"
#include "io/output_paths.h"

namespace rigc::external {

namespace fs = std::filesystem;

bool read_linear_image(const fs::path& path, LinearImage* image, std::string* error) {
  auto input = OIIO::ImageInput::open(path.string());
  if (!input) {
    *error = fmt::format("cannot read '{}': {}", path.string(), OIIO::geterror());
    return false;
  }
  const OIIO::ImageSpec& spec = input->spec();
  const int channels = spec.nchannels;
  if (channels < 1 || spec.width <= 0 || spec.height <= 0) {
    *error = fmt::format("'{}' has no pixels", path.string());
    return false;
  }
  std::vector<float> pixels(static_cast<size_t>(spec.width) * spec.height * channels);
  if (!input->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, pixels.data())) {
    *error = fmt::format("cannot read '{}': {}", path.string(), input->geterror());
    return false;
  }
  image->width = spec.width;
  image->height = spec.height;
  const size_t count = static_cast<size_t>(spec.width) * spec.height;
  image->rgb.resize(count * 3);
  image->alpha.clear();
  const int alpha_channel = spec.alpha_channel >= 0 ? spec.alpha_channel : (channels == 4 ? 3 : -1);
  if (alpha_channel >= 0) image->alpha.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const float* p = &pixels[i * channels];
    for (int c = 0; c < 3; ++c) image->rgb[i * 3 + c] = p[std::min(c, channels - 1)];
    if (alpha_channel >= 0) image->alpha[i] = p[alpha_channel];
  }
  return true;
}

bool prepare_emit_folder(const ir::Scene& scene, const fs::path& dir,
                         const run::RenderSettings& settings, std::string* error) {
  if (!settings.check(error)) return false;
  if (!make_output_folder(dir, error)) return false;
  for (const auto& shot : scene.shots) {
    if (!is_plain_file_stem(shot.name)) {
      *error = fmt::format("shot name '{}' cannot be a file name", comment_text(shot.name));
      return false;
    }
  }
  return true;
}

bool ExternalBackend::available(std::string* error) const {
  if (find_executable(executable())) return true;
  *error = fmt::format(
      "the {} backend needs '{}', which is not installed (not found in PATH); install it with: "
      "sudo apt-get install {}",
      name(), executable(), package());
  return false;
}

bool ExternalBackend::prepare(const ir::Scene& scene, const scene::StudioScene& studio,
                              const run::RenderSettings& settings, const run::ShotFiles& files,
                              std::string* error) {
  return emit(scene, studio, files.work_dir, settings, error);
}

}  // namespace rigc::external
