// The last stage of `rigc eval`: eval.json, the coloured cloud, the histogram and the heat map,
// and the summary lines on the log. eval.json is written at every exit after the output folder
// exists, failures included.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "eval/align.h"
#include "eval/colmap.h"
#include "eval/eval.h"
#include "eval/inputs.h"
#include "eval/measure.h"
#include "eval/photos.h"

namespace rigc::eval {

// Where the wall time went (seconds).
struct EvalTimes {
  double setup = 0;    // inputs and ground truth, before COLMAP
  double metrics = 0;  // reading the model, alignment and metrics
  double rigc = 0;     // metrics and files
  double total = 0;    // this call's wall time (with --reuse-colmap it holds no COLMAP time)
};

class EvalReport {
 public:
  // The report starts with the inputs.
  EvalReport(const EvalInputs& inputs, std::ostream& log, EvalSummary& summary);

  nlohmann::json& sections() { return report_; }  // eval.json's sections, by name

  // Writes eval.json (atomically) and hands the report to the summary; false, logged, when it
  // cannot.
  bool write();
  // A failed stage: `section`'s status and reason, the summary's failure, eval.json, the log.
  // Returns exit_code.
  int fail(const std::string& section, const std::string& reason, int exit_code);

  void add_colmap(const ColmapRun& colmap);
  // The "photos" section: masks, cameras, capture order.
  void add_photos(const PhotoSetup& photos);
  // The "reconstruction" section, and its line on the log.
  // `model` holds the points measured: those of the `points_in_model` COLMAP made that are seen
  // in at least options.sfm.min_track_length images.
  void add_reconstruction(const SparseModel& model, const ColmapRun& colmap,
                          std::size_t points_in_model, const EvalOptions& options);
  // cloud_signed_distance.ply, histogram.png and heatmap.png (seen by the first camera): the
  // "files" section. A file that cannot be written is a warning.
  void write_pictures(const EvalOptions& options, const Surface& surface,
                      const Alignment& alignment, const Measurements& m);
  void add_timing(const ColmapRun& colmap, const EvalTimes& times);
  // The result and the time split, on the log.
  void print_summary(const EvalOptions& options, const ColmapRun& colmap, const Measurements& m,
                     const EvalTimes& times) const;
  // The result line alone (signed distance and F-score).
  void print_measurements(const EvalOptions& options, const Measurements& m) const;
  void print_written() const;

 private:
  std::filesystem::path out_;
  std::size_t image_count_;
  std::ostream& log_;
  EvalSummary& summary_;
  nlohmann::json report_;
};

}  // namespace rigc::eval
