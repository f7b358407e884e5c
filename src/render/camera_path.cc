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

  const std::vector<RoutePiece> pieces = route_pieces(scene);
  const double total = route_length(pieces);
  Rng rng(hash_mix(o.seed, 0x9A7B));
  double phase[6];
  for (double& p : phase) p = rng.uniform(0.0, 2.0 * kPi);
  const double sway = o.sway ? 1.0 : 0.0;
  const double stride = 1.5;  // metres per gait cycle (two steps)

  Trajectory traj;
  double previous_heading = 0.0;
  for (int i = 0; i < o.num_frames; ++i) {
    const double time = i / o.rate_hz;
    const double s = o.start + o.speed * time;
    Eigen::Vector2d pos = Eigen::Vector2d::Zero(), tangent = Eigen::Vector2d::UnitX();
    point_on_route(pieces, total, s, &pos, &tangent);
    // Heading: the tangent averaged with triangular weights over +-2 m, so that the yaw rate
    // ramps up and down smoothly and a 90-degree turn takes about 4 m (peak 50 deg/s at 1.5 m/s).
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (int k = -20; k <= 20; ++k) {
      Eigen::Vector2d p2 = Eigen::Vector2d::Zero(), t2 = Eigen::Vector2d::Zero();
      point_on_route(pieces, total, s + 0.1 * k, &p2, &t2);
      mean += (21 - std::abs(k)) * t2;
    }
    const double heading = std::atan2(mean.y(), mean.x());
    const Eigen::Vector2d left(-tangent.y(), tangent.x());
    const double cycle = 2.0 * kPi * s / stride;
    pos += sway * 0.025 * std::sin(cycle + phase[0]) * left;
    const double z = o.camera_height + sway * 0.015 * std::sin(2.0 * cycle + phase[1]);
    const double yaw = heading + scene.route_look_left_deg * kDeg +
                       sway * 1.0 * kDeg * std::sin(2.0 * kPi * s / 2.9 + phase[2]);
    const double pitch =
        o.pitch_down_deg * kDeg + sway * 1.2 * kDeg * std::sin(2.0 * kPi * s / 3.7 + phase[3]);
    const double roll = sway * 0.8 * kDeg * std::sin(cycle + phase[4]);
    // Body frame x forward, y left, z up; positive pitch tips the nose down.
    const Eigen::Matrix3d R_world_from_base = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                                               Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                                               Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
                                                  .toRotationMatrix();
    CameraPose pose;
    pose.R_world_from_camera = R_world_from_base * base_from_optical();
    pose.centre = Eigen::Vector3d(pos.x(), pos.y(), z);
    if (i > 0) {
      traj.length += (pose.centre - traj.poses.back().centre).norm();
      traj.total_turn_deg += std::abs(std::remainder(heading - previous_heading, 2.0 * kPi)) / kDeg;
    }
    previous_heading = heading;
    traj.poses.push_back(pose);
    traj.times.push_back(time);
  }
  return traj;
}

}  // namespace render
}  // namespace hybrid_vo
