#include "hybrid_vo/render/pan_motion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

#include "painter.h"

namespace hybrid_vo {
namespace render {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180.0;

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("render pan: " + what);
}

// One axis: two sinusoids, their periods in units of the pan's time scale.
struct Wave {
  double period[2], phase[2], weight[2];
  double at(double u) const {
    return weight[0] * std::sin(2.0 * kPi * u / period[0] + phase[0]) +
           weight[1] * std::sin(2.0 * kPi * u / period[1] + phase[1]);
  }
};

// The yaw swings at the time scale with a faster wobble; pitch and roll are slower, so that
// where the yaw reverses little else moves.
std::array<Wave, 3> seeded_waves(uint64_t seed) {
  Rng rng(hash_mix(seed, 0x9A11));
  std::array<Wave, 3> waves;
  for (int axis = 0; axis < 3; ++axis) {
    Wave& w = waves[axis];
    w.period[0] = axis == 0 ? 1.0 : rng.uniform(1.5, 2.5);
    w.period[1] = axis == 0 ? rng.uniform(0.4, 0.55) : rng.uniform(0.8, 1.2);
    w.weight[0] = 1.0;
    w.weight[1] = 0.3;
    for (double& phase : w.phase) phase = rng.uniform(0.0, 2.0 * kPi);
  }
  return waves;
}

// Yaw, pitch and roll (degrees) at any time at time scale tau (seconds per unit period), each
// axis scaled so that its largest magnitude over the sequence's time is its amplitude. That peak
// is taken between the frames too, so that it changes with tau without jumps, and so does the
// fastest step: the time scale can be found by bisection.
class PanAngles {
 public:
  PanAngles(const std::array<Wave, 3>& waves, const Eigen::Vector3d& amplitude, int frames,
            double rate, double tau)
      : waves_(waves), amplitude_(amplitude), tau_(tau) {
    constexpr int kBetween = 8;  // samples per frame interval for the peak
    for (int axis = 0; axis < 3; ++axis) {
      peak_[axis] = 0.0;
      for (int k = 0; k <= (frames - 1) * kBetween; ++k)
        peak_[axis] = std::max(peak_[axis], std::abs(waves[axis].at(k / (kBetween * rate) / tau)));
    }
  }

  Eigen::Vector3d at(double time) const {
    Eigen::Vector3d angles = Eigen::Vector3d::Zero();
    for (int axis = 0; axis < 3; ++axis)
      if (peak_[axis] > 0.0)
        angles[axis] = amplitude_[axis] * waves_[axis].at(time / tau_) / peak_[axis];
    return angles;
  }

 private:
  std::array<Wave, 3> waves_;
  Eigen::Vector3d amplitude_;
  double tau_ = 1.0, peak_[3] = {};
};

// The angles of every frame.
std::vector<Eigen::Vector3d> pan_angles(const std::array<Wave, 3>& waves,
                                        const Eigen::Vector3d& amplitude, int frames, double rate,
                                        double tau) {
  const PanAngles angles_at(waves, amplitude, frames, rate, tau);
  std::vector<Eigen::Vector3d> angles;
  for (int i = 0; i < frames; ++i) angles.push_back(angles_at.at(i / rate));
  return angles;
}

double fastest_step(const std::vector<Eigen::Vector3d>& angles) {
  double fastest = 0.0;
  for (size_t i = 1; i < angles.size(); ++i)
    fastest = std::max(
        fastest,
        rotation_step_deg(pan_rotation(angles[i - 1].x(), angles[i - 1].y(), angles[i - 1].z()),
                          pan_rotation(angles[i].x(), angles[i].y(), angles[i].z())));
  return fastest;
}

}  // namespace

Eigen::Matrix3d pan_rotation(double yaw_deg, double pitch_deg, double roll_deg) {
  return (Eigen::AngleAxisd(yaw_deg * kDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(pitch_deg * kDeg, Eigen::Vector3d::UnitX()) *
          Eigen::AngleAxisd(roll_deg * kDeg, Eigen::Vector3d::UnitZ()))
      .toRotationMatrix();
}

Eigen::Matrix3d PanMotion::R_neutral_from_camera_at(double time) const {
  const Eigen::Vector3d a = yaw_pitch_roll_deg_at(time);
  return pan_rotation(a.x(), a.y(), a.z());
}

double rotation_step_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return Eigen::AngleAxisd(a.transpose() * b).angle() / kDeg;
}

bool is_dropped(int frame, int drop_every) {
  return drop_every > 0 && frame % drop_every == drop_every - 1;
}

PanMotion make_pan_motion(const PanMotionOptions& o) {
  check(o.frames >= 2 && o.frames <= 1000000, "frames must be in [2, 1e6]");
  check(std::isfinite(o.rate) && o.rate > 0.0 && o.rate <= 1000.0, "rate must be in (0, 1000] Hz");
  const Eigen::Vector3d amplitude(o.yaw_deg, o.pitch_deg, o.roll_deg);
  check(amplitude.allFinite() && amplitude.minCoeff() >= 0.0 && amplitude.maxCoeff() <= 45.0,
        "amplitudes must be in [0, 45] degrees");
  check(amplitude.maxCoeff() > 0.0, "a pan needs an amplitude above 0");
  check(std::isfinite(o.max_step_deg) && o.max_step_deg > 0.0 && o.max_step_deg <= 45.0,
        "the largest step must be in (0, 45] degrees");

  const std::array<Wave, 3> waves = seeded_waves(o.seed);
  auto fastest_at = [&](double tau) {
    return fastest_step(pan_angles(waves, amplitude, o.frames, o.rate, tau));
  };
  // The slower the pan (the larger tau), the smaller its steps, down to a sweep over the
  // amplitudes in the sequence's time. The fastest allowed swing of the yaw takes 0.5 s: with
  // amplitudes too small to reach the limit even then, the pan stays below it.
  constexpr double kShortestTau = 0.5;
  double slow = 1.0;
  for (int k = 0; fastest_at(slow) > o.max_step_deg; ++k) {
    check(k < 60, "no time scale keeps the steps below the limit");  // not met in practice
    slow *= 2.0;
  }
  double fast = slow;
  while (fast > kShortestTau && fastest_at(fast) <= o.max_step_deg)
    fast = std::max(kShortestTau, 0.5 * fast);
  if (fastest_at(fast) <= o.max_step_deg) slow = fast;
  for (int k = 0; k < 60 && slow != fast; ++k) {
    const double middle = std::sqrt(slow * fast);
    (fastest_at(middle) > o.max_step_deg ? fast : slow) = middle;
  }
  const std::vector<Eigen::Vector3d> angles = pan_angles(waves, amplitude, o.frames, o.rate, slow);
  const double fastest = fastest_step(angles);

  PanMotion pan;
  pan.yaw_pitch_roll_deg = angles;
  pan.min_step_deg = 360.0;
  for (int i = 0; i < o.frames; ++i) {
    const Eigen::Vector3d& a = angles[i];
    pan.R_neutral_from_camera.push_back(pan_rotation(a.x(), a.y(), a.z()));
    pan.times.push_back(i / o.rate);
    if (i > 0)
      pan.min_step_deg = std::min(
          pan.min_step_deg,
          rotation_step_deg(pan.R_neutral_from_camera[i - 1], pan.R_neutral_from_camera[i]));
  }
  pan.max_step_deg = fastest;
  const PanAngles angles_at(waves, amplitude, o.frames, o.rate, slow);
  pan.yaw_pitch_roll_deg_at = [angles_at](double time) { return angles_at.at(time); };
  return pan;
}

}  // namespace render
}  // namespace hybrid_vo
