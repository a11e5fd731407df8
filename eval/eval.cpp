#include "eval/eval.h"

#include <chrono>
#include <ostream>

#include "eval/align.h"
#include "eval/colmap.h"
#include "eval/geometry.h"
#include "eval/inputs.h"
#include "eval/measure.h"
#include "eval/report.h"

namespace rigc::eval {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

}  // namespace

int evaluate(const EvalOptions& o, std::ostream& log, EvalSummary* summary) {
  const auto t_start = Clock::now();
  EvalSummary local;
  EvalSummary& sum = summary ? *summary : local;
  const auto in = gather_inputs(o, log, sum);
  if (!in) return 1;
  EvalReport report(*in, log, sum);

  EvalTimes times;
  times.setup = seconds_since(t_start);
  const ColmapRun colmap = run_colmap(o, *in, log);
  report.add_colmap(colmap);
  if (!colmap.ok) {
    return report.fail("reconstruction", colmap.failure, colmap.exit_code ? colmap.exit_code : 2);
  }
  const auto t_rigc = Clock::now();
  std::string error;
  const auto model = read_sparse_model(colmap.model_txt, &error);
  if (!model) return report.fail("reconstruction", error, 2);
  report.add_reconstruction(*model, colmap, o.quiet);
  if (model->points.size() < 3) {
    return report.fail("reconstruction", "the reconstruction has fewer than 3 points", 2);
  }

  const Surface surface(in->truth.positions, in->truth.triangles);
  const Alignment alignment = align_to_ground_truth(o, *model, in->truth, surface);
  if (!alignment.ok) return report.fail("alignment", alignment.failure, 2);
  report.sections()["alignment"] = alignment.report;
  const Measurements m =
      measure(o, *model, in->truth, surface, alignment, in->out, report.sections());
  sum.mean_mm = m.stats.mean;
  sum.std_mm = m.stats.stddev;
  sum.fscore = m.f.fscore;
  times.metrics = seconds_since(t_rigc);

  report.write_pictures(o, surface, alignment, m);
  sum.rigc_s = times.rigc = seconds_since(t_rigc);
  times.total = seconds_since(t_start);
  report.add_timing(colmap, times);
  if (!report.write()) return 2;
  if (!o.quiet) report.print_summary(o, colmap, m, times);
  return 0;
}

}  // namespace rigc::eval
