#pragma once

// A smooth random pan of a camera turning about its own centre, as a hand or a pan-tilt head
// moves it: yaw, pitch and roll each a sum of two sinusoids with seeded periods and phases,
// scaled to their amplitudes, with the time scale set so that the fastest frame-to-frame turn is
// the given maximum. The yaw reverses every second or two; there the turn is slow, elsewhere
// near the maximum. Rotations are of the camera's optical frame (x right, y down, z forward).

#include <cstdint>
#include <functional>
#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {
namespace render {

struct PanMotionOptions {
  int frames = 300;
  double rate = 30.0;  // Hz
  // The pan stays within +- these (degrees), and reaches each that is not 0 (the frames to a
  // few hundredths of a degree: the peak may fall between two).
  double yaw_deg = 8.0, pitch_deg = 3.0, roll_deg = 2.0;
  // The largest rotation between consecutive frames (degrees); the pan reaches it unless the
  // amplitudes are too small for it even when the yaw's period is 0.5 s.
  double max_step_deg = 1.3;
  uint64_t seed = 1;
};

struct PanMotion {
  // Per frame: the camera's rotation relative to its neutral orientation (camera to neutral).
  std::vector<Eigen::Matrix3d> R_neutral_from_camera;
  std::vector<Eigen::Vector3d> yaw_pitch_roll_deg;
  std::vector<double> times;                      // seconds: i / rate
  double min_step_deg = 0.0, max_step_deg = 0.0;  // between consecutive frames
  // The pan between and beyond the frames: the angles at any time (seconds since frame 0), the
  // frames' own at theirs. Motion blur samples it within a frame's exposure.
  std::function<Eigen::Vector3d(double time)> yaw_pitch_roll_deg_at;

  // Frame i's orientation in the first frame's camera, the ground truth's world (camera to
  // first); the centre stays at its origin.
  Eigen::Matrix3d R_first_from_camera(int frame) const {
    return R_neutral_from_camera.front().transpose() * R_neutral_from_camera.at(frame);
  }
  Eigen::Matrix3d R_neutral_from_camera_at(double time) const;
};

// Throws std::invalid_argument for fewer than 2 frames, a rate, amplitude or step that is not
// finite and positive (amplitudes may be 0, not all), or amplitudes above 45 degrees.
PanMotion make_pan_motion(const PanMotionOptions& options);

// Yaw about the camera's y axis (positive: to the right), then pitch about its x axis
// (positive: up), then roll about its z axis (positive: clockwise as seen from behind).
Eigen::Matrix3d pan_rotation(double yaw_deg, double pitch_deg, double roll_deg);

// The angle of the rotation from a to b, degrees.
double rotation_step_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

// Whether a busy machine that drops every drop_every-th frame (frames drop_every - 1,
// 2 drop_every - 1, ...) drops this one; drop_every 0 drops none.
bool is_dropped(int frame, int drop_every);

}  // namespace render
}  // namespace hybrid_vo
