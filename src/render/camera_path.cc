#include "hybrid_vo/render/camera_path.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "painter.h"
#include "route.h"

namespace hybrid_vo {
namespace render {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("render path: " + what);
}

// 0 before t = 0, 1 after `duration`, a raised cosine between: no jump in the speed's slope.
double smooth_ramp(double t, double duration) {
  if (t <= 0.0) return 0.0;
  if (t >= duration) return 1.0;
  return 0.5 * (1.0 - std::cos(kPi * t / duration));
}

// Its integral from 0 to t: the distance (or angle) at unit final speed.
double smooth_ramp_integral(double t, double duration) {
  if (t <= 0.0) return 0.0;
  if (t >= duration) return t - 0.5 * duration;
  return 0.5 * t - duration / (2.0 * kPi) * std::sin(kPi * t / duration);
}

// The camera at `centre` whose body (x forward, y left, z up) has this yaw, pitch and roll;
// positive pitch tips the nose down.
CameraPose body_pose(const Eigen::Vector3d& centre, double yaw, double pitch, double roll) {
  const Eigen::Matrix3d R_world_from_base = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                             Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                             Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                                .toRotationMatrix();
  CameraPose pose;
  pose.R_world_from_camera = R_world_from_base * base_from_optical();
  pose.centre = centre;
  return pose;
}

// The camera's pose at any time since frame 0, for the frames and for the instants within an
// exposure (motion blur); it copies what it needs, so it outlives the scene and options.
class CameraPath {
 public:
  CameraPath(const Scene& scene, const PathOptions& o)
      : o_(o),
        pieces_(route_pieces(scene)),
        total_(route_length(pieces_)),
        look_left_(scene.route_look_left_deg * kDeg),
        duration_((o.num_frames - 1) / o.rate_hz) {
    Rng rng(hash_mix(o.seed, 0x9A7B));
    for (double& p : phase_) p = rng.uniform(0.0, 2.0 * kPi);
    start_ = walk_pose(o.start, 0.0, &start_heading_);
    // The turn's pivot: lever_arm behind the centre, level with it.
    Eigen::Vector3d forward = start_.R_world_from_camera.col(2);
    forward.z() = 0.0;
    pivot_ = start_.centre - o.lever_arm * forward.normalized();
  }

  // The pose at `time` and the heading (without the wobble).
  CameraPose at(double time, double* heading) const {
    const double full_sway = o_.sway ? 1.0 : 0.0;
    const double turn_rate = o_.turn_rate_deg * kDeg;
    *heading = start_heading_;
    CameraPose pose = start_;
    switch (o_.motion) {
      case Motion::kWalk:
        pose = walk_pose(o_.start + o_.speed * time, full_sway, heading);
        break;
      case Motion::kRest:
        break;
      case Motion::kTurn: {
        double angle = turn_rate * smooth_ramp_integral(time, o_.turn_ramp_seconds);
        if (o_.turn_stop)
          angle -= turn_rate * smooth_ramp_integral(time - (duration_ - o_.turn_ramp_seconds),
                                                    o_.turn_ramp_seconds);
        const Eigen::Matrix3d R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).matrix();
        pose.R_world_from_camera = R * start_.R_world_from_camera;
        pose.centre = pivot_ + R * (start_.centre - pivot_);
        *heading = start_heading_ + angle;
        break;
      }
      case Motion::kRamp: {
        const double moving = time - o_.rest_seconds;
        pose = walk_pose(o_.start + o_.speed * smooth_ramp_integral(moving, o_.ramp_seconds),
                         full_sway * smooth_ramp(moving, o_.ramp_seconds), heading);
        break;
      }
      case Motion::kHandheld:
        pose = handheld_pose(time, heading);
        break;
    }
    return pose;
  }

 private:
  static constexpr double kStride = 1.5;  // metres per gait cycle (two steps)

  // The walk's pose at arc length s, its sway scaled by `sway` (0: none), and its heading.
  CameraPose walk_pose(double s, double sway, double* heading) const {
    Eigen::Vector2d pos = Eigen::Vector2d::Zero(), tangent = Eigen::Vector2d::UnitX();
    point_on_route(pieces_, total_, s, &pos, &tangent);
    // Heading: the tangent averaged with triangular weights over +-2 m, so that the yaw rate
    // ramps up and down smoothly and a 90-degree turn takes about 4 m (peak 50 deg/s at 1.5 m/s).
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int k = -20; k <= 20; ++k) {
      Eigen::Vector2d p2 = Eigen::Vector2d::Zero(), t2 = Eigen::Vector2d::Zero();
      point_on_route(pieces_, total_, s + 0.1 * k, &p2, &t2);
      mean += (21 - std::abs(k)) * t2;
    }
    *heading = std::atan2(mean.y(), mean.x());
    const Eigen::Vector2d left(-tangent.y(), tangent.x());
    const double cycle = 2.0 * kPi * s / kStride;
    pos += sway * 0.025 * std::sin(cycle + phase_[0]) * left;
    const double z = o_.camera_height + sway * 0.015 * std::sin(2.0 * cycle + phase_[1]);
    const double yaw = *heading + look_left_ +
                       sway * 1.0 * kDeg * std::sin(2.0 * kPi * s / 2.9 + phase_[2]);
    const double pitch =
        o_.pitch_down_deg * kDeg + sway * 1.2 * kDeg * std::sin(2.0 * kPi * s / 3.7 + phase_[3]);
    const double roll = sway * 0.8 * kDeg * std::sin(cycle + phase_[4]);
    return body_pose(Eigen::Vector3d(pos.x(), pos.y(), z), yaw, pitch, roll);
  }

  // kHandheld: the route's point and heading at the stroll's arc length, the hand's slow swings
  // and drift (periods of 3-10 s, incommensurate, with the seed's phases) and its shake.
  CameraPose handheld_pose(double time, double* heading) const {
    Eigen::Vector2d pos = Eigen::Vector2d::Zero(), tangent = Eigen::Vector2d::UnitX();
    const double s = o_.start + o_.speed * time;
    point_on_route(pieces_, total_, s, &pos, &tangent);
    walk_pose(s, 0.0, heading);  // for its smoothed heading
    const auto wave = [&](double amplitude, double period, int k) {
      return amplitude * std::sin(2.0 * kPi * time / period + phase_[k % 6] + k);
    };
    const Eigen::Vector2d left(-tangent.y(), tangent.x());
    pos += (wave(0.10, 8.1, 0) + wave(0.0015, 1.0 / 1.7, 1)) * left;
    const double z = o_.camera_height + wave(0.03, 6.2, 2) + wave(0.0015, 1.0 / 2.3, 3);
    const double yaw = *heading + look_left_ + (wave(12.0, 9.0, 4) + wave(3.0, 3.1, 5) +
                                                wave(0.15, 1.0 / 2.1, 6)) * kDeg;
    const double pitch = (o_.pitch_down_deg + wave(4.0, 7.3, 7) + wave(0.15, 1.0 / 3.3, 8)) * kDeg;
    const double roll = (wave(1.5, 5.7, 9) + wave(0.15, 1.0 / 4.7, 10)) * kDeg;
    return body_pose(Eigen::Vector3d(pos.x(), pos.y(), z), yaw, pitch, roll);
  }

  PathOptions o_;
  std::vector<RoutePiece> pieces_;
  double total_ = 0.0, look_left_ = 0.0, duration_ = 0.0;
  double phase_[6] = {};
  CameraPose start_;
  double start_heading_ = 0.0;
  Eigen::Vector3d pivot_ = Eigen::Vector3d::Zero();
};

}  // namespace

Eigen::Matrix3d base_from_optical() {
  Eigen::Matrix3d R;
  // Columns: optical x = -base y, optical y = -base z, optical z = base x.
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return R;
}

CameraPose stereo_right(const CameraPose& left, double baseline) {
  CameraPose right = left;
  right.centre = left.centre + baseline * left.R_world_from_camera.col(0);
  return right;
}

double route_length(const Scene& scene) { return route_length(route_pieces(scene)); }

bool parse_motion(const std::string& name, Motion* motion) {
  for (Motion m : {Motion::kWalk, Motion::kRest, Motion::kTurn, Motion::kRamp, Motion::kHandheld})
    if (name == to_string(m)) {
      *motion = m;
      return true;
    }
  return false;
}

const char* to_string(Motion motion) {
  switch (motion) {
    case Motion::kWalk:
      return "walk";
    case Motion::kRest:
      return "rest";
    case Motion::kTurn:
      return "turn";
    case Motion::kRamp:
      return "ramp";
    case Motion::kHandheld:
      return "handheld";
  }
  return "?";
}

Trajectory make_trajectory(const Scene& scene, const PathOptions& o) {
  check(o.num_frames >= 1 && o.num_frames <= 1000000, "num_frames must be in [1, 1e6]");
  check(std::isfinite(o.rate_hz) && o.rate_hz > 0.0 && o.rate_hz <= 1000.0,
        "rate must be in (0, 1000] Hz");
  check(std::isfinite(o.speed) && o.speed > 0.0 && o.speed <= 5.0, "speed must be in (0, 5] m/s");
  check(std::isfinite(o.start), "start must be finite");
  check(std::isfinite(o.camera_height) && o.camera_height >= 0.4 &&
            o.camera_height <= scene.options.height - 0.4,
        "camera height must be at least 0.4 m from floor and ceiling");
  check(std::isfinite(o.pitch_down_deg) && std::abs(o.pitch_down_deg) <= 30.0,
        "pitch must be within +-30 degrees");
  check(std::isfinite(o.lever_arm) && o.lever_arm >= 0.0 && o.lever_arm <= 2.0,
        "the lever arm must be in [0, 2] m");
  check(std::isfinite(o.turn_rate_deg) && std::abs(o.turn_rate_deg) <= 360.0,
        "the turn rate must be within +-360 deg/s");
  check(std::isfinite(o.turn_ramp_seconds) && o.turn_ramp_seconds >= 0.0 &&
            o.turn_ramp_seconds <= 60.0,
        "the turn's ramp must be in [0, 60] s");
  check(std::isfinite(o.rest_seconds) && o.rest_seconds >= 0.0 && o.rest_seconds <= 3600.0,
        "the rest must be in [0, 3600] s");
  check(std::isfinite(o.ramp_seconds) && o.ramp_seconds >= 0.0 && o.ramp_seconds <= 600.0,
        "the ramp must be in [0, 600] s");
  const double duration = (o.num_frames - 1) / o.rate_hz;
  check(o.motion != Motion::kTurn || !o.turn_stop || duration >= 2.0 * o.turn_ramp_seconds,
        "a turn that stops needs frames for two ramps (" +
            std::to_string(2.0 * o.turn_ramp_seconds) + " s)");

  const CameraPath path(scene, o);
  Trajectory traj;
  double previous_heading = 0.0;
  for (int i = 0; i < o.num_frames; ++i) {
    const double time = i / o.rate_hz;
    double heading = 0.0;
    const CameraPose pose = path.at(time, &heading);
    if (o.motion == Motion::kTurn)
      check(scene.is_free(pose.centre, 0.3),
            "the turn's circle leaves the free space (shorten the lever arm)");
    if (i > 0) {
      traj.length += (pose.centre - traj.poses.back().centre).norm();
      traj.total_turn_deg += std::abs(std::remainder(heading - previous_heading, 2.0 * kPi)) / kDeg;
    }
    previous_heading = heading;
    traj.poses.push_back(pose);
    traj.times.push_back(time);
  }
  traj.pose_at = [path](double time) {
    double heading = 0.0;
    return path.at(time, &heading);
  };
  return traj;
}

}  // namespace render
}  // namespace hybrid_vo
