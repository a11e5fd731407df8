// What the backends that render through another program (POV-Ray, Blender Cycles) share: the
// program check, the emitted scripts, reading the program's linear output, writing textures.
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"
#include "run/backend.h"
#include "scene/studio_scene.h"

namespace rigc::external {

// A backend that renders through another program (POV-Ray, Blender): it emits scripts into the
// run's render/ folder before the first shot, checks that the program is installed, and logs
// each shot's run of it there.
class ExternalBackend : public run::Backend {
 public:
  bool emits_scripts() const override { return true; }
  bool takes_samples() const override { return true; }
  // The program it runs and the Debian package that installs it.
  virtual std::string executable() const = 0;
  virtual std::string package() const = 0;
  // The program is in $PATH; else an error naming the package to install.
  bool available(std::string* error) const override;
  // Emits the scripts into files.work_dir.
  bool prepare(const ir::Scene& scene, const scene::StudioScene& studio,
               const run::RenderSettings& settings, const run::ShotFiles& files,
               std::string* error) override;
};

// What every emit() checks first: the settings (RenderSettings::check), that `dir` exists or can
// be made, and that every shot name can be a file name. False with a one-line `error`.
bool prepare_emit_folder(const ir::Scene& scene, const std::filesystem::path& dir,
                         const run::RenderSettings& settings, std::string* error);

// A linear image (OpenEXR, Radiance HDR...) through OpenImageIO: RGB as floats, and alpha when
// the file has one (else empty). False with a one-line `error`.
struct LinearImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;
  std::vector<float> alpha;
};
bool read_linear_image(const std::filesystem::path& path, LinearImage* image, std::string* error);

// The light a renderer's file holds per unit: both POV-Ray and Cycles write Blender's
// radiometric units, in which 1 W/(m²·sr) of linear Y is ir::kLumensPerWatt cd/m².
inline constexpr double kCandelaPerBlenderUnit = ir::kLumensPerWatt;

}  // namespace rigc::external
