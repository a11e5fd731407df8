// The DSLR model for the live view, with what an exposure or white balance change cannot alter
// kept: the frame after depth of field, diffraction and the warp to the sensor, at unit exposure.
// An ISO, shutter or white balance change then runs only the exposure gain, the sensor and the
// encoding. The stages and their order are dslr/pipeline.cpp's (develop_frame); a frame that is
// not clean radiance goes through develop_frame itself.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "dslr/frame.h"
#include "dslr/lens.h"
#include "ir/ir.h"
#include "run/backend.h"

namespace rigc::studio {

// How a live development went: whether the kept optics served, and each stage's time (added to
// what is there).
struct DevelopReport {
  bool reused_optics = false;
  std::map<std::string, double> stage_ms;
};

class LiveDevelop {
 public:
  // 8-bit sRGB codes of `rendered` (the renderer's linear frame of `shot` at settings.scale) as
  // the camera takes it, with settings.seed's noise. Empty with `error` set on failure.
  dslr::DevelopResult develop(const ir::Camera& camera,
                              std::shared_ptr<const run::RenderedShot> rendered,
                              const ir::Shot& shot, const run::RenderSettings& settings,
                              DevelopReport* report, std::string* error);

 private:
  // What the optics read besides the frame: the lens, the aperture, the focus, the sensor grid.
  struct OpticsKey {
    std::shared_ptr<const run::RenderedShot> rendered;  // held, so that its address stays unique
    ir::Camera camera;
    double focus_m = 0, scale = 0;
    bool same_as(const OpticsKey& other) const;
  };
  struct Optics {
    OpticsKey key;
    dslr::SensorImage image;  // unit exposure
  };
  bool develop_optics(const OpticsKey& key, std::string* error,
                      std::map<std::string, double>* stage_ms);

  std::optional<Optics> kept_;
};

}  // namespace rigc::studio
