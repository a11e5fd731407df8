// Capture advice: compiler-style warnings at the scene line responsible, each with a fix.
#pragma once

#include <string>
#include <vector>

#include "analysis/coverage.h"
#include "compiler/diagnostics.h"
#include "ir/ir.h"
#include "ir/source_location.h"
#include "scene/studio_scene.h"

namespace rigc::analysis {

// A camera or studio setting an advice suggests changing.
enum class Setting { kShutter, kFNumber, kIso, kLight };

// One suggested change: the setting's value up (+1: a longer shutter, a larger f-number, a
// higher ISO, more light) or down (-1), and the value the advice works out for it where it
// works one out (0 otherwise): the shutter in seconds, the f-number, the ISO, or the factor the
// light is multiplied by. An advice that offers alternatives lists each.
struct SettingChange {
  Setting setting;
  int direction;
  double value = 0;
  // The same change, whatever value each names.
  bool operator==(const SettingChange& other) const {
    return setting == other.setting && direction == other.direction;
  }
};

// "shutter", "f-number", "iso" or "light".
const char* setting_name(Setting setting);

// One warning: where, what it says, and the changes it suggests. No advice for a scene suggests
// a change another one reverses (capture_advice holds to it).
struct Advice {
  SourceLoc loc;
  std::string message;
  std::vector<SettingChange> changes;
};

// Depth of field, motion blur, exposure (or a brightness range no exposure fits), diffraction,
// unseen faces, overlap between consecutive shots and an object too small in the frame.
std::vector<Advice> capture_advice(const ir::Scene& scene, const scene::StudioScene& studio,
                                   const CoverageResult& coverage);

// The resolution the advice's coverage analysis runs at: about 700 px across, the visibility
// scale for `camera` (check, the studio and `rigc new` give the same advice).
double advice_visibility_scale(const ir::Camera& camera);

// The advice `rigc check` gives for `scene`: its studio prepared and its coverage analysed at
// advice_visibility_scale.
std::vector<Advice> check_advice(const ir::Scene& scene);

// capture_advice as warnings.
void report_capture_advice(const ir::Scene& scene, const scene::StudioScene& studio,
                           const CoverageResult& coverage, DiagnosticEngine& diag);

// The slowest of cameras' third-stop shutter speeds (1/8000 s to 1 s) at or faster than
// `seconds`; 1/8000 s where none is.
double next_faster_standard_shutter(double seconds);

// The next standard third-stop f-number at or above `f_number`.
double next_standard_f_number(double f_number);

}  // namespace rigc::analysis
