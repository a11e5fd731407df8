// How finely a renderer without native motion blur must sample a turning turntable.
#pragma once

#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::scene {

// The number of sub-frames motion blur needs for a shot (1 when there is no motion): about one
// per pixel the fastest object point travels while the shutter is open, at most 48.
int motion_blur_subframes(const ir::Scene& scene, const StudioScene& studio, const ir::Shot& shot,
                          double scale);

}  // namespace rigc::scene
