// The part of `rigc render --backend povray|cycles` both reference renderers share: for every
// selected shot, render it with the external program (a Renderer), pass its linear output
// through the same DSLR model as the preview, and write the common output layout (images,
// masks, sparse/, transforms.json, manifest.json). A rerun renders only the missing shots; a
// shot that fails is named with its log file and the others still render (exit code 2 at the end).
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::external {

struct ReferenceOptions {
  std::string output_dir;  // the run folder
  std::vector<int> shots;  // indices to render (all when empty)
  double scale = 1.0;      // multiplies the sensor resolution
  std::uint64_t seed = 1;  // sensor noise (and the renderer's sampling seed)
  int samples = 0;         // renderer samples per pixel; 0 = the backend's default
  bool progress_bar = false;
};

struct ShotTiming {
  double render_ms = 0;   // the external renderer(s), including their start-up
  double develop_ms = 0;  // the DSLR model
  double write_ms = 0;
  double total_ms = 0;
  int subframes = 1;     // motion-blur sub-frames the renderer averaged (1: none, or native)
  bool skipped = false;  // already in the manifest with the same inputs
  bool failed = false;
};

// A renderer's linear output for one shot, on the undistorted canvas of
// dslr::render_geometry_for(camera, scale).
struct RenderedShot {
  dslr::LinearFrame frame;  // rgb in cd/m², mask from the renderer's own coverage pass
  bool depth_of_field_rendered = false;  // the renderer did DOF: the DSLR model must not
  int subframes = 1;
};

class Renderer {
 public:
  virtual ~Renderer() = default;
  // "povray" or "cycles": the backend name in the manifest and the shot keys.
  virtual std::string name() const = 0;
  // The program it runs and the Debian package that installs it.
  virtual std::string executable() const = 0;
  virtual std::string package() const = 0;
  // Writes every file a user needs to render the scene by hand into `dir` (which exists).
  virtual bool emit(const ir::Scene& scene, const std::filesystem::path& dir, double scale,
                    int samples, std::string* error) = 0;
  // Renders one shot from the files emit() wrote into `dir`; the renderer's output goes to
  // `log_path`. False with a one-line `error` on failure.
  virtual bool render(const ir::Scene& scene, const std::filesystem::path& dir,
                      const ir::Shot& shot, double scale, int samples,
                      const std::filesystem::path& log_path, RenderedShot* out,
                      std::string* error) = 0;
};

// What every emit() checks first: a positive scale, that `dir` exists or can be made, and that
// every shot name can be a file name. False with a one-line `error`.
bool prepare_emit_folder(const ir::Scene& scene, const std::filesystem::path& dir, double scale,
                         std::string* error);

// Runs the whole backend; returns the exit code (0 ok, 1 user error, 2 renderer failure).
int run_reference(const ir::Scene& scene, const ReferenceOptions& options, Renderer& renderer,
                  std::ostream& log, std::vector<ShotTiming>* timings = nullptr);

// Where run_reference keeps the emitted scene files, the renderer's raw output and its logs.
std::filesystem::path render_folder(const std::filesystem::path& run_dir);

// A linear image (OpenEXR, Radiance HDR...) through OpenImageIO: RGB as floats, and alpha when
// the file has one (else empty). False with a one-line `error`.
struct LinearImage {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;
  std::vector<float> alpha;
};
bool read_linear_image(const std::filesystem::path& path, LinearImage* image, std::string* error);

// Writes a texture's pixels (8-bit, sRGB) as a PNG, atomically enough for emitting.
bool write_texture_png(const std::filesystem::path& path, const ir::Texture& texture,
                       std::string* error);

// The light a renderer's file holds per unit: both POV-Ray and Cycles write Blender's
// radiometric units, and 1 W/(m²·sr) of linear Y is 683 cd/m² (CAMERA.md).
inline constexpr double kCandelaPerBlenderUnit = 683.0;

}  // namespace rigc::external
