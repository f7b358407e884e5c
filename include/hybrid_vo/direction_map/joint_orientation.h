#pragma once

// The joint Gaussian behind the orientation and the map of world directions: the error of the
// camera's orientation (3, a left increment in the odometry frame) and the error of each map
// direction (2, in its tangent plane), with every cross-covariance. The cross-covariances are what keep the map honest: a direction placed under
// a drifted orientation carries that drift, and a correction by it cannot remove it; a correction
// must agree with the pairs' rotation since the direction was last seen, not with a covariance
// that forgot they were correlated (EKF-SLAM's consistency, Castellanos et al. 2004).
//
// Directions are not exactly fixed (segments are not straight, a road bends): each one's error
// may also drift a little with every frame (direction_drift).

#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {

class JointOrientation {
 public:
  static constexpr int kOrientation = 0;  // first row of the orientation block
  static constexpr int kDirections = 3;   // first row of direction 0

  // Orientation covariance P (rad^2), no directions.
  explicit JointOrientation(const Eigen::Matrix3d& P = Eigen::Matrix3d::Zero());

  int directions() const { return (static_cast<int>(covariance_.rows()) - kDirections) / 2; }
  const Eigen::MatrixXd& covariance() const { return covariance_; }
  Eigen::Matrix3d orientation() const { return covariance_.topLeftCorner<3, 3>(); }
  Eigen::Matrix2d direction(int j) const {
    return covariance_.block<2, 2>(kDirections + 2 * j, kDirections + 2 * j);
  }

  // A pair moved the camera: the orientation error grows by Q (odometry frame), each direction's
  // by `direction_drift` (rad^2, per tangent axis).
  void predict(const Eigen::Matrix3d& Q, double direction_drift = 0.0);
  // The orientation's uncertainty widened by `extra` (rad^2): a prediction not trusted as it is.
  void widen_orientation(const Eigen::Matrix3d& extra);
  // The orientation's covariance set to P: widened when P holds the old one, else replaced with
  // the cross-covariances shrunk so that the whole stays a covariance.
  void set_orientation(const Eigen::Matrix3d& P);

  // A new direction whose error is J times the orientation error plus noise N (2x2): a direction
  // observed from the camera inherits the camera's orientation error.
  void add_direction(const Eigen::Matrix<double, 2, 3>& J, const Eigen::Matrix2d& N);
  void remove_direction(int j);
  // Direction j's tangent coordinates changed basis: new = T old.
  void change_basis(int j, const Eigen::Matrix2d& T);

  // The Kalman gain for residuals r ~ H x + noise (covariance N), x the joint error: the
  // correction is K (r at x = 0). Only the states marked in `estimated` (one flag per state)
  // take a correction; the others are considered (Schmidt: their mean stays zero, their
  // covariances stay right). An iterated update relinearises and calls gain again; apply()
  // then takes the last gain into the covariance.
  struct Gain {
    bool valid = false;  // false: the innovation covariance H P H^T + N is singular
    Eigen::MatrixXd K;
    Eigen::MatrixXd S_inverse;
  };
  Gain gain(const Eigen::MatrixXd& H, const Eigen::MatrixXd& N,
            const std::vector<char>& estimated) const;
  // Joseph form, which stays right for a gain that is not the optimal one (Schmidt).
  void apply(const Gain& gain, const Eigen::MatrixXd& H, const Eigen::MatrixXd& N);

 private:
  Eigen::MatrixXd covariance_;
};

}  // namespace hybrid_vo
