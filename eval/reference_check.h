// `rigc eval --photos DIR --reference-cameras FILE`: the reconstruction's cameras against
// calibrated ones (eval/pose_accuracy.h), and when SfM registered fewer than half of the photos,
// the points it would have had at the reference poses (eval/known_poses.h). Both go into
// eval.json ("cameras", "known_poses") and onto the log.
#pragma once

#include <ostream>

#include "eval/colmap.h"
#include "eval/eval.h"
#include "eval/inputs.h"
#include "eval/report.h"

namespace rigc::eval {

// `model` is SfM's (null when it reconstructed nothing). Does nothing without reference cameras.
void check_against_reference(const EvalOptions& options, const EvalInputs& inputs,
                             const ColmapRun& colmap, const SparseModel* model, EvalReport& report,
                             std::ostream& log);

}  // namespace rigc::eval
