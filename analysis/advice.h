// Capture advice: compiler-style warnings at the scene line responsible, each with a fix.
#pragma once

#include "analysis/coverage.h"
#include "compiler/diagnostics.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::analysis {

// Warns about depth of field, motion blur, exposure, diffraction, unseen faces, overlap between
// consecutive shots and an object too small in the frame.
void report_capture_advice(const ir::Scene& scene, const scene::StudioScene& studio,
                           const CoverageResult& coverage, DiagnosticEngine& diag);

// The next standard third-stop f-number at or above `f_number`.
double next_standard_f_number(double f_number);

}  // namespace rigc::analysis
