// The scene the studio's tests open: a small statue, one shot from the side, and comments that a
// save must keep.
#pragma once

#include <string>

namespace rigc::studio {

inline const std::string kStudioTestScene =
    R"(# The studio's test scene: a statue, lit from the front.
rigc: 1
name: studio-test
object:
  primitive: {shape: statue, detail: 4, seed: 3}
  fit: {height: 25cm}
  surface: {pattern: speckle, scale: 2mm, contrast: 0.7, color: [0.55, 0.52, 0.48]}
studio:
  turntable: {diameter: 40cm, height: 75cm, color: [0.05, 0.05, 0.05]}
  backdrop: {green_screen: {color: [0.0, 0.69, 0.25]}}
  lights:
    # the key light, left of the camera
    - {type: area, position: [0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 80W, temperature: 5500K}
    - {type: area, position: [-0.7m, -1.3m, 1.3m], size: [50cm, 50cm], power: 80W}
  ambient: 20lx
camera:
  body: canon-6d
  lens: {focal_length: 50mm}
  exposure: {aperture: f/11, shutter: 1/125, iso: 200}  # daylight
  focus: auto
  white_balance: 5500K
shots:
  # one view from the right
  - pose: {position: [0.8m, 0, 0.9m], look_at: object}
)";

// The line of `exposure:` above.
inline constexpr int kStudioTestSceneExposureLine = 19;

}  // namespace rigc::studio
