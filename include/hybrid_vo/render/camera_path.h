#pragma once

// The camera's motion through a render::Scene: a walk along the scene's route with rounded
// 90-degree turns, looking where it goes, with a walker's bob and sway; or, at the route's start,
// standing still, turning in place, or starting to walk from rest. Poses are camera-to-world.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/render/scene.h"

namespace hybrid_vo {
namespace render {

// A camera pose in the world: X_world = R_world_from_camera * X_camera + centre, with the camera
// frame optical (x right, y down, z forward).
struct CameraPose {
  Eigen::Matrix3d R_world_from_camera = Eigen::Matrix3d::Identity();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();

  Eigen::Vector3d to_camera(const Eigen::Vector3d& X_world) const {
    return R_world_from_camera.transpose() * (X_world - centre);
  }
  Eigen::Vector3d to_world(const Eigen::Vector3d& X_camera) const {
    return R_world_from_camera * X_camera + centre;
  }
};

// Columns: the optical frame's axes (x right, y down, z forward) in REP 103 body coordinates
// (x forward, y left, z up).
Eigen::Matrix3d base_from_optical();

// The right camera of a rectified stereo pair: same rotation, centre `baseline` metres along
// the left camera's x axis.
CameraPose stereo_right(const CameraPose& left, double baseline);

enum class Motion {
  kWalk,  // along the route at `speed`
  kRest,  // standing at the route's start, without sway: only the sensor noise changes
  kTurn,  // a wheeled robot turning in place at the route's start, about a vertical axis
  kRamp,  // at rest, then accelerating to `speed`, then the walk
  // A camera held in the hand of someone strolling along the route at `speed` (0.09 m/s from
  // the command line) and looking around: slow yaw, pitch and roll swings (the yaw 8 deg/s
  // typical, 15 at most), the hand's drift (10 cm sideways, 3 cm up and down) and its shake
  // (0.15 deg, 1.5 mm at 2-5 Hz). At 30 Hz it has a few pixels of parallax per second.
  kHandheld,
};

// Parses "walk", "rest", "turn", "ramp" or "handheld"; false for anything else.
bool parse_motion(const std::string& name, Motion* motion);
const char* to_string(Motion motion);

struct PathOptions {
  Motion motion = Motion::kWalk;
  int num_frames = 150;
  double rate_hz = 10.0;
  double speed = 1.5;  // metres per second along the route
  double start = 0.0;  // metres along the route at frame 0 (the route is a closed loop)
  double camera_height = 1.45;
  double pitch_down_deg = 4.0;
  bool sway = true;   // walking bob, sideways sway, small pitch, roll and yaw wobble
  uint64_t seed = 1;  // phases of the sway
  // kTurn: the axis is lever_arm metres behind the camera centre (level with it; 0: through the
  // centre), so the centre moves on a circle of that radius. The yaw rate (positive: to the
  // left) rises from 0 to turn_rate_deg over turn_ramp_seconds as a raised cosine and holds;
  // with turn_stop it falls back to 0 over the last turn_ramp_seconds.
  double lever_arm = 0.2;
  double turn_rate_deg = 30.0;
  double turn_ramp_seconds = 1.0;
  bool turn_stop = false;
  // kRamp: still for rest_seconds, then the speed rises to `speed` over ramp_seconds as a raised
  // cosine (no jolt), then the walk goes on. The sway grows with the speed, as a walker's would.
  double rest_seconds = 1.0;
  double ramp_seconds = 2.0;
};

struct Trajectory {
  std::vector<CameraPose> poses;  // per frame; the left camera for stereo
  std::vector<double> times;      // seconds since frame 0: i / rate
  double length = 0.0;            // metres travelled by the camera centre
  double total_turn_deg = 0.0;    // sum of |heading change| between frames (without the wobble)
  // The path between and beyond the frames: the pose at any time (seconds since frame 0), the
  // frames' own at theirs. Motion blur samples it within a frame's exposure.
  std::function<CameraPose(double time)> pose_at;
};

// Throws std::invalid_argument for invalid options, and for a turn whose circle leaves the
// scene's free space.
Trajectory make_trajectory(const Scene& scene, const PathOptions& options = {});

// Length of the scene's route (one lap), metres.
double route_length(const Scene& scene);

}  // namespace render
}  // namespace hybrid_vo
