#pragma once

// Whether reported covariances are honest: the normalised estimation error squared (NEES,
// e^T C^-1 e) of rotations, translation directions and orientations against the truth, and its
// summary. Under an honest covariance the NEES is chi-square with the error's degrees of freedom.
// Angles and truth noise are in radians here; the tools take degrees.

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {
namespace evaluation {

// Chi-square quantiles for 1 to 3 degrees of freedom (NaN otherwise): the 95 % one bounds the
// ellipsoid (3 dof: 7.8147, 2 dof: 5.9915); the median is what an honest covariance gives
// (3 dof: 2.366, 2 dof: 1.386).
double chi_square_95(int dof);
double chi_square_median(int dof);

// A covariance a NEES can use: square, finite, symmetric (to 1e-9 of its largest entry),
// positive semi-definite, with at least `rank` eigenvalues above 1e-12 of the largest (a zero
// matrix, the message's "unknown", has none).
bool usable_covariance(const Eigen::MatrixXd& covariance, int rank);

// The 3x3 block at (first, first) of a row-major 6x6 covariance (a message's float64[36]).
Eigen::Matrix3d covariance_block(const double* row_major_6x6, int first);

// NEES of a rotation (3 dof): w = log(R_est R_true^T), the left increment R_est = exp([w]x)
// R_true, under covariance + truth_sigma^2 I (truth_sigma: the truth's own noise per axis). NaN
// when the covariance is not usable with full rank; that is checked before the truth's noise is
// added, so a zero covariance stays missing.
double rotation_nees(const Eigen::Matrix3d& R_est, const Eigen::Matrix3d& R_true,
                     const Eigen::Matrix3d& covariance, double truth_sigma = 0.0);

// NEES of a translation direction (2 dof), in the tangent plane of the estimated direction:
// the error is the true direction's offset on the sphere from t_est/|t_est|, the covariance that
// of t (unit or metric) projected into the plane and divided by |t_est|^2 (what normalising t
// does to it to first order), plus truth_sigma^2 per axis of the plane. The 3x3 covariance may
// have rank 2 (unit t: nothing along t), its projection must have full rank. NaN when either
// vector is zero or the covariance is not usable; +infinity when the directions are opposite.
double direction_nees(const Eigen::Vector3d& t_est, const Eigen::Vector3d& t_true,
                      const Eigen::Matrix3d& covariance, double truth_sigma = 0.0);

// NEES of two observations of one world direction (2 dof), e.g. a VP seen in frames a and b, under
// the true rotation R_ba from a's camera into b's: a's direction carried into b against b's, with
// both covariances (unit directions, tangent plane, rad^2). A VP has either sign: a's is flipped
// to b's side. NaN when either direction is zero or their summed covariance is not usable.
double direction_pair_nees(const Eigen::Vector3d& d_a, const Eigen::Matrix3d& C_a,
                           const Eigen::Vector3d& d_b, const Eigen::Matrix3d& C_b,
                           const Eigen::Matrix3d& R_ba);

// The VP observations' NEES along a run: each sighting of a map direction (its id) against the
// last one it was compared with, at least `min_gap` frames before (nearby frames share tracked
// segments and their errors), under the true rotation between the two frames.
class DirectionSightings {
 public:
  explicit DirectionSightings(int min_gap = 5) : min_gap_(min_gap) {}
  // d, C: the observation in the camera frame (direction_pair_nees); R_true: the true
  // camera-to-world rotation of `frame`.
  void add(int frame, int id, const Eigen::Vector3d& d, const Eigen::Matrix3d& C,
           const Eigen::Matrix3d& R_true);
  const std::vector<double>& nees() const { return nees_; }

 private:
  struct Sighting {
    int frame;
    Eigen::Vector3d d;
    Eigen::Matrix3d C, R_true;
  };
  int min_gap_;
  std::map<int, Sighting> last_;
  std::vector<double> nees_;
};

// NEES of a metric translation (3 dof; stereo pairs): the error t_est - t_true under covariance
// + truth_sigma^2 I (metres). NaN when the covariance is not usable with full rank.
double translation_nees(const Eigen::Vector3d& t_est, const Eigen::Vector3d& t_true,
                        const Eigen::Matrix3d& covariance, double truth_sigma = 0.0);

// Camera k's orientation against the first camera's, as the trajectory tools compare it:
// error = log(R_est_rel R_true_rel^T) with R_rel = R_0^T R_k (camera-to-world rotations). Its
// covariance comes from `covariance_world`, that of a left increment of the estimated R_k about
// the odometry frame's axes (nav_msgs/Odometry's pose covariance, of any frame rigidly attached
// to the camera: the body's increment about fixed axes is the camera's), mapped into the first
// camera's frame: R_0_est^T C R_0_est. The first pose is taken as exact: the odometry starts there.
struct RelativeOrientation {
  Eigen::Vector3d error = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};
RelativeOrientation relative_orientation(const Eigen::Matrix3d& R0_est,
                                         const Eigen::Matrix3d& Rk_est,
                                         const Eigen::Matrix3d& R0_true,
                                         const Eigen::Matrix3d& Rk_true,
                                         const Eigen::Matrix3d& covariance_world);

// NEES of relative_orientation (3 dof) plus truth_sigma^2 I; NaN without a usable covariance.
double orientation_nees(const Eigen::Matrix3d& R0_est, const Eigen::Matrix3d& Rk_est,
                        const Eigen::Matrix3d& R0_true, const Eigen::Matrix3d& Rk_true,
                        const Eigen::Matrix3d& covariance_world, double truth_sigma = 0.0);

// NEES values of many estimates, a NaN for each without a usable covariance.
struct NeesSummary {
  int dof = 0;
  int count = 0;    // estimates
  int missing = 0;  // of them without a usable covariance
  double median = NAN, p90 = NAN;
  double inside95 = NAN;  // share (0..1) of those with a covariance inside the 95 % ellipsoid
};
NeesSummary summarize_nees(const std::vector<double>& nees, int dof);

// "NEES median 2.41 (honest 2.366), p90 6.02, 95.1 % inside the 95 % ellipsoid (7.815); 118 of
// 120 <what> with a covariance": the tools' `# consistency:` lines.
std::string describe_nees(const NeesSummary& summary, const std::string& what);

}  // namespace evaluation
}  // namespace hybrid_vo
