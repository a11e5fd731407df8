// Coverage analysis: for every shot, which faces of the object it sees and whether SfM can use the
// view (resolution on the surface, viewing angle, focus, exposure); per face, the views and
// whether some pair of usable views triangulates it. Area-weighted throughout.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "analysis/visibility_cache.h"
#include "ir/ir.h"
#include "scene/studio_scene.h"

namespace rigc::analysis {

struct ShotCoverage {
  int shot = 0;
  double visible_area_m2 = 0;
  double new_area_m2 = 0;            // first seen in this shot
  double overlap_with_previous = 0;  // share of this shot's visible area the previous shot saw
  // Cumulative shares of the surface area after this shot.
  double seen_1 = 0, seen_2 = 0, seen_3 = 0, reconstructable = 0;
  // Shares of this shot's visible area.
  double out_of_focus = 0, clipped = 0, too_dark = 0, too_oblique = 0, too_coarse = 0;
  double frame_fill = 0;  // object's share of the image area
  double nearest_depth_m = 0;
  // Visible area by signal, in steps of kSignalBinStops from kSignalLowestStops below the
  // clipping level (max_signal) up; the ends hold everything beyond. How many stops less (or
  // more) light would bring the clipped (or dark) share under a limit follows from it.
  static constexpr int kSignalBins = 320;
  static constexpr double kSignalBinStops = 0.125, kSignalLowestStops = -20;
  std::vector<double> signal_histogram;
};

// What one shot sees, kept for planning (CoverageOptions::keep_sights).
struct ShotSight {
  Eigen::Vector3d eye = Eigen::Vector3d::Zero();  // camera centre, object frame
  std::vector<std::uint32_t> seen;                // faces the shot sees
  std::vector<std::uint32_t> usable;              // of those, faces SfM can use
};

struct CoverageResult {
  std::vector<double> face_area_m2;         // object frame
  std::vector<std::uint16_t> views;         // shots that see each face
  std::vector<std::uint16_t> usable_views;  // of those, views SfM can use
  std::vector<std::uint8_t> reconstructable;
  std::vector<std::uint8_t> resting;  // faces lying on the turntable: no camera can see them
  // The shots in which each face was seen the first and second time (kNever if not).
  static constexpr std::uint16_t kNever = 0xFFFF;
  std::vector<std::uint16_t> first_seen, second_seen;
  std::vector<ShotCoverage> shots;
  double total_area_m2 = 0;
  // Blur needed to keep 95 % of the seen surface sharp, as a multiple of max_blur_px at the
  // current aperture (> 1: stop down by that factor).
  double blur_ratio_95 = 0;
  // With keep_sights: every shot's sight, and each face's centre and unit normal (object frame).
  std::vector<ShotSight> sights;
  std::vector<Eigen::Vector3d> face_center, face_normal;
};

struct CoverageOptions {
  // Scale of the visibility buffers relative to the sensor; footprints are always computed at
  // full resolution. 0 picks about 1400 px across; otherwise 0.01..1 (smaller buffers are too
  // coarse to tell which faces are hidden).
  double visibility_scale = 0;
  bool keep_sights = false;  // fill CoverageResult::sights, face_center and face_normal
  // Where shots' visibility is looked up before it is rendered, and kept after (may be shared by
  // analyses on several threads).
  std::shared_ptr<VisibilityCache> visibility_cache;

  // Whether every field holds a value the analysis takes; if not, says why in `error` (when
  // given). analyse_coverage throws std::invalid_argument on options that fail it.
  bool check(std::string* error = nullptr) const;
};

CoverageResult analyse_coverage(const ir::Scene& scene, const scene::StudioScene& studio,
                                const CoverageOptions& options = {});

// Each face's mean albedo luminance, as the exposure check sees it: the material's colour (or
// the mean of the face's vertex colours) times its texture's and pattern's averages.
std::vector<float> face_albedo(const ir::Scene& scene, const scene::StudioScene& studio);

class CoverageAnalysis;

// The analysis kept open, so that shots can be added one at a time (the studio's captures): after
// add_shot of shots s0..sn, result() is analyse_coverage's on a scene with those shots (and the
// scene's object, studio and camera). The last shots added can be taken back.
class IncrementalCoverage {
 public:
  IncrementalCoverage(std::shared_ptr<const ir::Scene> scene,
                      std::shared_ptr<const scene::StudioScene> studio,
                      const CoverageOptions& options = {});
  ~IncrementalCoverage();

  void add_shot(const ir::Shot& shot);
  // Takes the last shot back; false when it is not kept (more than kUndoDepth shots back).
  bool remove_last_shot();
  // Drops the kept states, so that remove_last_shot() returns false until shots are added again:
  // an analysis kept for a scene that may come back need not keep its undo too.
  void forget_undo();
  int shot_count() const;
  const std::vector<ir::Shot>& shots() const { return shots_; }
  CoverageResult result() const;

  static constexpr size_t kUndoDepth = 16;

 private:
  std::shared_ptr<const ir::Scene> scene_;
  std::shared_ptr<const scene::StudioScene> studio_;
  std::unique_ptr<CoverageAnalysis> analysis_;
  std::deque<std::unique_ptr<CoverageAnalysis>> before_;  // before each of the last shots added
  std::vector<ir::Shot> shots_;
};

}  // namespace rigc::analysis
