#include "plan/candidates.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace rigc::plan {
namespace {

using ir::Vec3;

// Scene text holds what is printed; rounding first keeps it short and the compiled poses exact.
double round_length(double meters) {
  return std::round(meters * 1e4) / 1e4;
}
double round_angle_deg(double degrees) {
  return std::round(degrees * 1e3) / 1e3;
}

std::string length_text(double meters) {
  return fmt::format("{}m", round_length(meters));
}
std::string angle_text(double degrees) {
  return fmt::format("{}deg", round_angle_deg(degrees));
}

std::string point_text(const Vec3& p) {
  return fmt::format("[{}, {}, {}]", length_text(p.x()), length_text(p.y()), length_text(p.z()));
}

std::string target_text(const spec::Target& target) {
  return target.object ? "object" : point_text(target.point);
}

// The object's centre in the world at turntable angle 0: what `aim: object` means.
Vec3 object_center_world(const ir::Scene& scene) {
  const Vec3 center = (scene.object.bounds_min_object + scene.object.bounds_max_object) / 2;
  return (ir::world_from_object(scene, 0) * center.homogeneous()).head<3>();
}

// Two stations from which the candidates are the same poses.
bool same_place(const Station& a, const Station& b) {
  if (a.kind != b.kind || a.kind == StationKind::kPose) return false;
  if (!a.turntable.aim.object || !b.turntable.aim.object || !a.aim.object || !b.aim.object) {
    return false;
  }
  if (a.kind == StationKind::kOrbit) {
    return round_length(a.orbit_distance_m) == round_length(b.orbit_distance_m) &&
           round_angle_deg(a.elevation_rad / kDegree) == round_angle_deg(b.elevation_rad / kDegree);
  }
  return round_length(a.turntable.distance_m) == round_length(b.turntable.distance_m) &&
         round_length(a.turntable.height_m) == round_length(b.turntable.height_m) &&
         round_angle_deg(a.turntable.azimuth_rad / kDegree) ==
             round_angle_deg(b.turntable.azimuth_rad / kDegree) &&
         a.turntable_speed_rad_s == b.turntable_speed_rad_s;
}

class CandidateMaker {
 public:
  CandidateMaker(const spec::SceneSpec& spec, const ir::Scene& scene,
                 const CandidateOptions& options)
      : spec_(spec), scene_(scene), options_(options), aim_(object_center_world(scene)) {}

  CandidateSet make() {
    add_scene_stations();
    if (!options_.turntable_only) add_rings();
    return std::move(set_);
  }

 private:
  void add_scene_stations();
  void add_rings();
  void add_station(Station station, double grid_start_deg);
  double table_top() const { return scene_.studio.turntable.height_m; }
  // The aim of a turntable camera aiming at the object: on the axis at the object's mid height.
  Vec3 turntable_aim(const spec::Target& aim) const {
    return aim.object ? Vec3(0, 0, aim_.z()) : aim.point;
  }
  Vec3 turntable_eye(const spec::TurntableCameraSpec& camera) const {
    return {camera.distance_m * std::cos(camera.azimuth_rad),
            camera.distance_m * std::sin(camera.azimuth_rad), table_top() + camera.height_m};
  }
  bool camera_can_stand(const Vec3& eye, const Vec3& aim) const;
  std::vector<double> ring_distances() const;

  const spec::SceneSpec& spec_;
  const ir::Scene& scene_;
  const CandidateOptions& options_;
  const Vec3 aim_;
  CandidateSet set_;
  std::vector<double> scene_distances_m_;  // of the scene's stations from their aims
  double first_azimuth_rad_ = -std::numbers::pi / 2;
  double first_start_deg_ = 0;
  bool uses_turntable_ = false;
};

void CandidateMaker::add_scene_stations() {
  bool first_turntable = true;
  for (const spec::ShotGroupSpec& group : spec_.shots) {
    Station station;
    station.from_scene = true;
    switch (group.kind) {
      case ir::ShotKind::kTurntable: {
        station.kind = StationKind::kTurntable;
        station.turntable = group.turntable.camera;
        station.turntable_speed_rad_s = group.turntable.speed_rad_s;
        const Vec3 offset = turntable_eye(station.turntable) - turntable_aim(station.turntable.aim);
        station.elevation_rad = std::atan2(offset.z(), offset.head<2>().norm());
        scene_distances_m_.push_back(offset.norm());
        if (first_turntable) {
          first_azimuth_rad_ = station.turntable.azimuth_rad;
          first_start_deg_ = group.turntable.start_rad / kDegree;
          first_turntable = false;
        }
        uses_turntable_ = true;
        add_station(station, group.turntable.start_rad / kDegree);
        break;
      }
      case ir::ShotKind::kOrbit:
        for (const spec::RingSpec& ring : group.orbit.rings) {
          station.kind = StationKind::kOrbit;
          station.orbit_distance_m = group.orbit.distance_m;
          station.elevation_rad = ring.elevation_rad;
          station.aim = group.orbit.aim;
          scene_distances_m_.push_back(group.orbit.distance_m);
          add_station(station, ring.start_rad / kDegree);
        }
        break;
      case ir::ShotKind::kPose:
        station.kind = StationKind::kPose;
        station.pose = group.pose;
        scene_distances_m_.push_back(
            (group.pose.position - (group.pose.look_at.object ? aim_ : group.pose.look_at.point))
                .norm());
        add_station(station, group.pose.turntable_rad / kDegree);
        break;
    }
  }
}

std::vector<double> CandidateMaker::ring_distances() const {
  std::vector<double> distances =
      options_.distances_m.empty() ? scene_distances_m_ : options_.distances_m;
  for (double& d : distances) d = round_length(d);
  std::sort(distances.begin(), distances.end());
  distances.erase(std::unique(distances.begin(), distances.end()), distances.end());
  return distances;
}

// Extra rings in the scene's style, at every elevation and distance asked for.
void CandidateMaker::add_rings() {
  std::vector<double> elevations = options_.ring_elevations_rad;
  if (elevations.empty()) {
    for (double degrees : kDefaultRingsDeg) elevations.push_back(degrees * kDegree);
  }
  for (double distance : ring_distances()) {
    for (double elevation : elevations) {
      Station station;
      station.elevation_rad = elevation;
      if (uses_turntable_) {
        station.kind = StationKind::kTurntable;
        station.turntable.distance_m = round_length(distance * std::cos(elevation));
        station.turntable.height_m =
            round_length(aim_.z() - table_top() + distance * std::sin(elevation));
        station.turntable.azimuth_rad = first_azimuth_rad_;
        const Vec3 eye = turntable_eye(station.turntable);
        if (!camera_can_stand(eye, turntable_aim(station.turntable.aim))) continue;
        add_station(station, first_start_deg_);
      } else {
        station.kind = StationKind::kOrbit;
        station.orbit_distance_m = distance;
        const Vec3 eye = aim_ + distance * Vec3(std::cos(elevation), 0, std::sin(elevation));
        if (!camera_can_stand(eye, aim_)) continue;
        add_station(station, 0);
      }
    }
  }
}

// A tripod's reach, out of the turntable's disc and the object's box, and not straight above or
// below the aim (a camera there has no up direction).
bool CandidateMaker::camera_can_stand(const Vec3& eye, const Vec3& aim) const {
  if (eye.z() < kLowestCameraM || eye.z() > kHighestCameraM) return false;
  const ir::Turntable& table = scene_.studio.turntable;
  const double horizontal = eye.head<2>().norm();
  if (horizontal < table.diameter_m / 2 + 0.05 && eye.z() < table.height_m + 0.05 &&
      eye.z() > table.height_m - table.thickness_m - 0.05) {
    return false;
  }
  const Vec3 half = (scene_.object.bounds_max_object - scene_.object.bounds_min_object) / 2;
  if ((eye - aim_).norm() < half.norm() * 1.2) return false;
  const Vec3 view = aim - eye;
  return view.head<2>().norm() > 0.05 * view.norm();
}

void CandidateMaker::add_station(Station station, double grid_start_deg) {
  for (const Station& known : set_.stations) {
    if (same_place(known, station)) return;
  }
  const int index = static_cast<int>(set_.stations.size());
  set_.stations.push_back(station);
  if (station.kind == StationKind::kPose) {
    set_.candidates.push_back({index, round_angle_deg(grid_start_deg)});
    return;
  }
  const double step_deg = options_.azimuth_step_rad / kDegree;
  const int count = std::max(1, static_cast<int>(std::lround(360 / step_deg)));
  std::vector<double> angles;
  for (int k = 0; k < count; ++k) {
    const double angle = std::fmod(grid_start_deg + k * 360.0 / count, 360);
    angles.push_back(round_angle_deg(angle < 0 ? angle + 360 : angle));
  }
  std::sort(angles.begin(), angles.end());
  for (double angle : angles) set_.candidates.push_back({index, angle});
}

std::string turntable_entry(const Station& station, int steps, double step_deg, double start_deg) {
  std::string text = fmt::format("  - turntable: {{steps: {}, ", steps);
  if (steps > 1) text += fmt::format("step: {}, ", angle_text(step_deg));
  text += fmt::format("start: {}, ", angle_text(start_deg));
  if (station.turntable_speed_rad_s != 0) {
    text += fmt::format("speed: {}deg/s, ", station.turntable_speed_rad_s / kDegree);
  }
  const spec::TurntableCameraSpec& camera = station.turntable;
  text +=
      fmt::format("camera: {{distance: {}, height: {}, azimuth: {}", length_text(camera.distance_m),
                  length_text(camera.height_m), angle_text(camera.azimuth_rad / kDegree));
  if (!camera.aim.object) text += ", aim: " + point_text(camera.aim.point);
  return text + "}}\n";
}

std::string orbit_ring(const Station& station, double azimuth_deg) {
  return fmt::format("{{elevation: {}, count: 1, start: {}}}",
                     angle_text(station.elevation_rad / kDegree), angle_text(azimuth_deg));
}

// A rotation-given pose keeps its position and rotation to the last digit: it reproduces a real
// camera.
std::string rotation_pose_entry(const spec::PoseShotSpec& pose) {
  const Eigen::Matrix3d& r = *pose.camera_from_world;
  std::string rows;
  for (int i = 0; i < 3; ++i) {
    rows += fmt::format("{}[{}, {}, {}]", i ? ", " : "", r(i, 0), r(i, 1), r(i, 2));
  }
  const Vec3& c = pose.position;
  return fmt::format("  - pose: {{position: [{}m, {}m, {}m], rotation: [{}], turntable: {}}}\n",
                     c.x(), c.y(), c.z(), rows, angle_text(pose.turntable_rad / kDegree));
}

std::string pose_entry(const spec::PoseShotSpec& pose) {
  if (pose.camera_from_world) return rotation_pose_entry(pose);
  return fmt::format("  - pose: {{position: {}, look_at: {}, up: [{}, {}, {}], turntable: {}}}\n",
                     point_text(pose.position), target_text(pose.look_at), pose.up.x(), pose.up.y(),
                     pose.up.z(), angle_text(pose.turntable_rad / kDegree));
}

// How many chosen candidates from `first` on are turntable shots of one station at equal steps.
int equal_step_run(const CandidateSet& set, const std::vector<int>& chosen, size_t first) {
  const Candidate& head = set.candidates[chosen[first]];
  size_t end = first + 1;
  double step = 0;
  while (end < chosen.size()) {
    const Candidate& next = set.candidates[chosen[end]];
    const double gap = next.angle_deg - set.candidates[chosen[end - 1]].angle_deg;
    if (next.station != head.station || gap <= 0) break;
    if (end == first + 1) step = gap;
    if (std::abs(gap - step) > 1e-6) break;
    ++end;
  }
  return static_cast<int>(end - first);
}

}  // namespace

CandidateSet make_candidates(const spec::SceneSpec& spec, const ir::Scene& scene,
                             const CandidateOptions& options) {
  return CandidateMaker(spec, scene, options).make();
}

std::vector<int> all_candidates(const CandidateSet& set) {
  std::vector<int> all(set.candidates.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = static_cast<int>(i);
  return all;
}

std::string shots_yaml(const CandidateSet& set, const std::vector<int>& chosen, bool merge_runs) {
  std::string text = "shots:\n";
  for (size_t i = 0; i < chosen.size();) {
    const Candidate& candidate = set.candidates[chosen[i]];
    const Station& station = set.stations[candidate.station];
    if (station.kind == StationKind::kPose) {
      text += pose_entry(station.pose);
      ++i;
    } else if (station.kind == StationKind::kTurntable) {
      const int run = merge_runs ? equal_step_run(set, chosen, i) : 1;
      const double step =
          run > 1 ? set.candidates[chosen[i + 1]].angle_deg - candidate.angle_deg : 0;
      text += turntable_entry(station, run, step, candidate.angle_deg);
      i += run;
    } else {
      text += fmt::format("  - orbit: {{distance: {}, ", length_text(station.orbit_distance_m));
      if (!station.aim.object) text += "aim: " + point_text(station.aim.point) + ", ";
      text += "rings: [" + orbit_ring(station, candidate.angle_deg);
      for (++i; i < chosen.size() && set.candidates[chosen[i]].station == candidate.station; ++i) {
        text += ", " + orbit_ring(station, set.candidates[chosen[i]].angle_deg);
      }
      text += "]}\n";
    }
  }
  return text;
}

std::string describe_station(const Station& station) {
  const double elevation_deg = station.elevation_rad / kDegree;
  switch (station.kind) {
    case StationKind::kTurntable:
      return fmt::format("tripod {:.0f} cm out, {:.0f} cm above the table ({:.0f}°)",
                         station.turntable.distance_m * 100, station.turntable.height_m * 100,
                         elevation_deg);
    case StationKind::kOrbit:
      return fmt::format("orbit {:.0f} cm at {:.0f}°", station.orbit_distance_m * 100,
                         elevation_deg);
    case StationKind::kPose:
      return "the scene's pose";
  }
  return "";
}

}  // namespace rigc::plan
