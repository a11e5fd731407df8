// `rigc compile --target povray` and `rigc render --backend povray`: the scene as POV-Ray 3.7
// files (scene.inc with the meshes as mesh2, materials and lights; per shot a .pov with the
// camera and the turntable angle, a .ini for the image and a _mask.ini for the object mask),
// rendered by `povray` and developed by the shared DSLR model.
//
// Units: POV-Ray has none, so the files are written in Blender's radiometric units (the output
// is cd/m² / 683, like Cycles'). POV's diffuse is albedo·cos·light colour with no 1/π, and its
// inverse-square fade with fade_power 2 is 2/(1 + (d/D)²) ≈ 2D²/d² for D = 1 mm, so a light of
// intensity I (W/sr) gets the colour I/(π·2D²). Area lights are POV area arrays of spotlights
// with radius = falloff = 90° and tightness 1: a cos θ emission, one-sided, like a Lambertian
// panel. Ambient illuminance E is ambient_light E/(683π) with finish ambient = diffuse albedo.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "backends/external/external_backend.h"
#include "ir/ir.h"

namespace rigc::povray {

// POV-Ray's focal blur `aperture` per metre of pupil diameter f/N (2: checked with a render by
// ReferenceAgreement.DefocusBlurWidth).
extern const double kApertureMetersPerPupilDiameter;

class PovrayBackend : public external::ExternalBackend {
 public:
  std::string name() const override { return "povray"; }
  std::string executable() const override { return "povray"; }
  std::string package() const override { return "povray"; }
  // Emits shots that render the unlit albedo (every surface its own pigment at ambient 1, no
  // lights) instead of the lit image: for the albedo agreement test.
  bool albedo_only = false;
  std::string options_key() const override { return albedo_only ? "albedo_only" : ""; }
  // 2: the highlight's peak that of the preview's GGX lobe; 3: area lights light from their
  // whole panel; 4: the whole diffuse under the highlight.
  int output_version() const override { return 4; }
  // POV-Ray's sampling is deterministic (no seed to measure its noise by): kConvergedSamples is
  // refused until a converged setting is measured against it (docs/fidelity.md).
  bool converges() const override { return true; }
  bool check_settings(const run::RenderSettings& settings, std::string* error) const override;
  // Writes scene.inc, and shot_NNN.pov / .ini / _mask.ini for every shot, into `dir` (created if
  // missing), and the textures beside them as PNG. `samples` sets antialiasing and focal blur
  // samples (0: defaults).
  bool emit(const ir::Scene& scene, const scene::StudioScene& studio,
            const std::filesystem::path& dir, const run::RenderSettings& settings,
            std::string* error) override;
  // Runs povray for the shot's image (per motion-blur sub-frame, which it averages) and mask.
  bool render(const ir::Scene& scene, const scene::StudioScene& studio, const ir::Shot& shot,
              const run::RenderSettings& settings, const run::ShotFiles& files,
              run::RenderedShot* out, std::string* error) override;

 private:
  std::vector<int> subframes_;  // per shot index, from the last emit
};

}  // namespace rigc::povray
