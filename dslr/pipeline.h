// The DSLR model in one call: what the preview rasterizer and the post-processing of POV-Ray and
// Cycles renders both run, so every renderer is judged by the same camera.
#pragma once

#include "dslr/frame.h"
#include "ir/ir.h"

namespace rigc::dslr {

// Bits per channel of the encoded image for the camera's file format (8 for JPEG, else 16).
int output_bits(const ir::Camera& camera);

// Runs the stages in order, each switchable by camera.effects:
//   1. exposure (always): cd/m² -> normalised signal;
//   2. depth of field (needs frame.depth_m), 3. diffraction: on the undistorted canvas;
//   5. distortion and vignetting: warp to the sensor grid (width_px·scale x height_px·scale);
//   6. sensor noise, clipping and the ADC; 7. white balance, sRGB encoding.
// (4, motion blur, is the renderer's: it averages sub-frames.) The frame may have any size and
// intrinsics; render_geometry_for() gives the one that covers the sensor after distortion.
// On a malformed frame (buffer sizes that do not match) the result is empty and `error` says why.
DevelopResult develop_frame(const ir::Camera& camera, const LinearFrame& frame,
                            const ShotParams& shot, double scale, std::string* error = nullptr);
// The same, taking the frame's buffers as working memory (no copy of a full-size frame).
DevelopResult develop_frame(const ir::Camera& camera, LinearFrame&& frame, const ShotParams& shot,
                            double scale, std::string* error = nullptr);

}  // namespace rigc::dslr
