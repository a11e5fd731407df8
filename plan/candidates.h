// The camera positions a plan chooses from: tripod stations beside the turntable (the turntable
// turns the object), rings around a static object, and the scene's own poses. Each candidate is
// written as scene text, so the compiler places it exactly as it will place the planned shot.
#pragma once

#include <string>
#include <vector>

#include "compiler/spec.h"
#include "compiler/units.h"
#include "ir/ir.h"

namespace rigc::plan {

enum class StationKind { kTurntable, kOrbit, kPose };

// Where a camera stands; the candidates turn around it (the turntable or the camera's azimuth).
struct Station {
  StationKind kind = StationKind::kTurntable;
  spec::TurntableCameraSpec turntable;  // kTurntable: as the language states it
  double turntable_speed_rad_s = 0;     // kTurntable: rotation during the exposure
  double orbit_distance_m = 0;          // kOrbit: from the aim
  double elevation_rad = 0;             // kTurntable and kOrbit: of the camera seen from the aim
  spec::Target aim;                     // kOrbit
  spec::PoseShotSpec pose;              // kPose
  bool from_scene = false;              // one of the scene's own stations
};

struct Candidate {
  int station = 0;
  double angle_deg = 0;  // kTurntable: the turntable's angle; kOrbit: the camera's azimuth
};

struct CandidateOptions {
  std::vector<double> ring_elevations_rad;  // extra stations; empty: kDefaultRingsDeg
  std::vector<double> distances_m;  // of the extra stations from the aim; empty: the scene's
  double azimuth_step_rad = 10 * kDegree;
  bool turntable_only = false;  // only the scene's own stations
};

inline constexpr double kDefaultRingsDeg[] = {0, 20, 40, 60, 80};
// Camera heights above the floor a tripod (with a centre column or a step) reaches.
inline constexpr double kLowestCameraM = 0.1, kHighestCameraM = 2.5;

struct CandidateSet {
  std::vector<Station> stations;
  std::vector<Candidate> candidates;  // grouped by station, angles ascending
};

// The scene's own stations (its turntable cameras, orbit rings and poses) and, unless
// `turntable_only`, rings at the given elevations and distances in the scene's style: tripod
// stations when it uses the turntable, orbits otherwise. Stations a camera cannot take (below the
// floor, beyond a tripod's reach, in the turntable or the object) are left out.
CandidateSet make_candidates(const spec::SceneSpec& spec, const ir::Scene& scene,
                             const CandidateOptions& options);

// 0, 1, ..., every candidate's index.
std::vector<int> all_candidates(const CandidateSet& set);

// The `shots:` section (from the key on) holding `chosen` candidates in that order. Consecutive
// turntable candidates of one station at equal steps share one entry when `merge_runs`.
std::string shots_yaml(const CandidateSet& set, const std::vector<int>& chosen, bool merge_runs);

// "tripod at 90cm, 15cm above the table" and the like, for reports.
std::string describe_station(const Station& station);

}  // namespace rigc::plan
