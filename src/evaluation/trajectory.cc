#include "hybrid_vo/evaluation/trajectory.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "hybrid_vo/evaluation/statistics.h"
#include "hybrid_vo/geometry/homogeneous.h"
#include "hybrid_vo/geometry/pose_error.h"

namespace hybrid_vo {
namespace evaluation {

bool pose_at(const Trajectory& trajectory, double stamp, double tolerance, StampedPose* pose) {
  if (trajectory.empty()) return false;
  const auto it = std::lower_bound(
      trajectory.begin(), trajectory.end(), stamp,
      [](const StampedPose& p, double s) { return p.stamp < s; });
  const StampedPose* best = nullptr;
  double best_gap = tolerance;
  for (auto c = it == trajectory.begin() ? it : it - 1; c != trajectory.end() && c <= it; ++c) {
    const double gap = std::abs(c->stamp - stamp);
    if (gap <= best_gap) best_gap = gap, best = &*c;
  }
  if (!best) return false;
  *pose = *best;
  return true;
}

bool umeyama(const std::vector<Eigen::Vector3d>& from, const std::vector<Eigen::Vector3d>& to,
             bool with_scale, Eigen::Matrix3d* R, Eigen::Vector3d* t, double* s) {
  const size_t n = std::min(from.size(), to.size());
  if (n < 3) return false;
  Eigen::Vector3d mf = Eigen::Vector3d::Zero(), mt = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) mf += from[i], mt += to[i];
  mf /= n;
  mt /= n;
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  double var = 0.0;
  for (size_t i = 0; i < n; ++i) {
    C += (to[i] - mt) * (from[i] - mf).transpose();
    var += (from[i] - mf).squaredNorm();
  }
  C /= n;
  var /= n;
  if (!(var > 0.0)) return false;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) D(2, 2) = -1.0;
  *R = svd.matrixU() * D * svd.matrixV().transpose();
  *s = with_scale ? (svd.singularValues().asDiagonal() * D).trace() / var : 1.0;
  *t = mt - *s * *R * mf;
  return std::isfinite(*s) && *s > 0.0;
}

namespace {

double angle_deg(const Eigen::Matrix3d& R) {
  return rotation_error(Eigen::Matrix3d::Identity(), R) * 180.0 / M_PI;
}

bool is_finite(const StampedPose& p) {
  return std::isfinite(p.stamp) && p.R.allFinite() && p.c.allFinite();
}

// The angle of (R_est_a^T R_est_b)^T (R_gt_a^T R_gt_b): how far the estimated rotation from
// pose a to pose b is from the true one.
double relative_rotation_error_deg(const PosePair& a, const PosePair& b) {
  const Eigen::Matrix3d dRe = a.estimate.R.transpose() * b.estimate.R;
  const Eigen::Matrix3d dRg = a.truth.R.transpose() * b.truth.R;
  return angle_deg(dRe.transpose() * dRg);
}

}  // namespace

std::vector<PosePair> match_poses(const Trajectory& estimate, const Trajectory& truth,
                                  double tolerance) {
  std::vector<PosePair> poses;
  for (const StampedPose& p : estimate) {
    PosePair pair;
    if (!is_finite(p) || !pose_at(truth, p.stamp, tolerance, &pair.truth) ||
        !is_finite(pair.truth))
      continue;
    pair.estimate = p;
    poses.push_back(pair);
  }
  std::stable_sort(poses.begin(), poses.end(), [](const PosePair& a, const PosePair& b) {
    return a.estimate.stamp < b.estimate.stamp;
  });
  return poses;
}

std::vector<double> window_rotation_errors_deg(const std::vector<PosePair>& poses,
                                               double window_s) {
  std::vector<double> errors;
  if (poses.size() < 2 || !std::isfinite(window_s) || !(window_s > 0.0)) return errors;
  std::vector<double> stamps;
  for (const PosePair& p : poses) stamps.push_back(p.estimate.stamp);
  // Not half a frame: the node's trajectory has poses at its estimated frames only, a few
  // frames apart, and a window of 0.9-1.1 s still measures the drift over about a second.
  const double tolerance = 0.1 * window_s;
  for (size_t i = 0; i + 1 < poses.size(); ++i) {
    const double target = stamps[i] + window_s;
    const auto after = std::lower_bound(stamps.begin() + i + 1, stamps.end(), target);
    size_t best = poses.size();
    double best_gap = tolerance;
    if (after != stamps.end() && *after - target <= best_gap)
      best = after - stamps.begin(), best_gap = *after - target;
    if (after - stamps.begin() > static_cast<std::ptrdiff_t>(i + 1) &&
        target - *(after - 1) <= best_gap)
      best = after - 1 - stamps.begin();
    if (best < poses.size()) errors.push_back(relative_rotation_error_deg(poses[i], poses[best]));
  }
  return errors;
}

std::vector<double> orientation_errors_deg(const std::vector<PosePair>& poses) {
  std::vector<double> errors;
  for (const PosePair& p : poses) errors.push_back(relative_rotation_error_deg(poses[0], p));
  return errors;
}

TrajectoryErrors compare_trajectories(const Trajectory& estimate, const Trajectory& truth,
                                      bool with_scale, double tolerance,
                                      std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>>*
                                          aligned,
                                      double window_s) {
  TrajectoryErrors e;
  e.window_s = window_s;
  const std::vector<PosePair> poses = match_poses(estimate, truth, tolerance);
  std::vector<StampedPose> est, gt;
  for (const PosePair& p : poses) {
    est.push_back(p.estimate);
    gt.push_back(p.truth);
  }
  if (est.size() < 2) return e;
  std::vector<Eigen::Vector3d> ce, cg;
  for (size_t i = 0; i < est.size(); ++i) {
    ce.push_back(est[i].c);
    cg.push_back(gt[i].c);
  }
  Eigen::Matrix3d Ra = Eigen::Matrix3d::Identity();
  Eigen::Vector3d ta = Eigen::Vector3d::Zero();
  double s = 1.0;
  if (!umeyama(ce, cg, with_scale, &Ra, &ta, &s)) {
    // Too few or collinear-free points: align the first pose only.
    Ra = gt[0].R * est[0].R.transpose();
    ta = gt[0].c - Ra * est[0].c;
    s = 1.0;
  }
  e.scale = s;
  double ate = 0.0;
  for (size_t i = 0; i < est.size(); ++i) {
    const Eigen::Vector3d a = s * Ra * est[i].c + ta;
    ate += (a - gt[i].c).squaredNorm();
    if (aligned) aligned->emplace_back(a, gt[i].c);
  }
  e.ate = std::sqrt(ate / est.size());

  double rpe_t = 0.0, rpe_r = 0.0;
  for (size_t i = 0; i + 1 < est.size(); ++i) {
    const Eigen::Matrix3d dRe = est[i].R.transpose() * est[i + 1].R;
    const Eigen::Matrix3d dRg = gt[i].R.transpose() * gt[i + 1].R;
    const Eigen::Vector3d dte = s * est[i].R.transpose() * (est[i + 1].c - est[i].c);
    const Eigen::Vector3d dtg = gt[i].R.transpose() * (gt[i + 1].c - gt[i].c);
    const double rot = angle_deg(dRe.transpose() * dRg);
    e.rot_err_deg.push_back(rot);
    e.dir_err_deg.push_back(translation_error(dte, dtg) * 180.0 / M_PI);
    rpe_t += (dte - dtg).squaredNorm();
    rpe_r += rot * rot;
    ++e.pairs;
  }
  e.rpe_trans = std::sqrt(rpe_t / e.pairs);
  e.rpe_rot_deg = std::sqrt(rpe_r / e.pairs);
  e.rot_pair_median_deg = median(e.rot_err_deg);
  e.dir_median_deg = median(e.dir_err_deg);
  e.rot_window_err_deg = window_rotation_errors_deg(poses, window_s);
  e.rot_window_median_deg = median(e.rot_window_err_deg);
  const std::vector<double> orientation = orientation_errors_deg(poses);
  e.orientation_last_deg = orientation.back();
  e.orientation_max_deg = *std::max_element(orientation.begin(), orientation.end());

  // Drift over sub-sequences (KITTI devkit style), with fractions of the path when it is short.
  std::vector<double> distance(gt.size(), 0.0);
  for (size_t i = 1; i < gt.size(); ++i) distance[i] = distance[i - 1] + (gt[i].c - gt[i - 1].c).norm();
  const double total = distance.back();
  std::vector<double> lengths;
  if (total >= 200.0) {
    for (double l = 100.0; l <= 800.0 && l < total; l += 100.0) lengths.push_back(l);
  } else if (total > 0.0) {
    for (double f : {0.25, 0.5, 0.75}) lengths.push_back(f * total);
  }
  double trans_sum = 0.0, rot_sum = 0.0;
  for (size_t first = 0; first < gt.size(); first += 5) {
    for (double length : lengths) {
      size_t last = first;
      while (last < gt.size() && distance[last] - distance[first] < length) ++last;
      if (last >= gt.size()) break;
      const Eigen::Matrix3d dRe = est[first].R.transpose() * est[last].R;
      const Eigen::Matrix3d dRg = gt[first].R.transpose() * gt[last].R;
      const Eigen::Vector3d dte = s * est[first].R.transpose() * (est[last].c - est[first].c);
      const Eigen::Vector3d dtg = gt[first].R.transpose() * (gt[last].c - gt[first].c);
      trans_sum += (dRg.transpose() * (dte - dtg)).norm() / length * 100.0;
      rot_sum += angle_deg(dRg.transpose() * dRe) / length * 100.0;
      ++e.drift_segments;
    }
  }
  if (e.drift_segments > 0) {
    e.drift_trans_percent = trans_sum / e.drift_segments;
    e.drift_rot_deg_per_100m = rot_sum / e.drift_segments;
  }
  return e;
}

Eigen::Matrix3d relative_rotation(const StampedPose& from, const StampedPose& to) {
  return to.R.transpose() * from.R;
}

Eigen::Vector3d rotation_difference_deg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(a * b.transpose()));
  return aa.angle() * aa.axis() * 180.0 / M_PI;
}

RotationOffsetFit fit_rotation_offset(const std::vector<Eigen::Matrix3d>& reference,
                                      const std::vector<Eigen::Matrix3d>& measured) {
  RotationOffsetFit fit;
  const size_t n = reference.size();
  if (n < 3 || measured.size() != n) return fit;
  // e = scale * theta - [theta]x tilt: three rows per pair, four unknowns.
  Eigen::MatrixXd A(3 * n, 4);
  Eigen::VectorXd e(3 * n);
  for (size_t i = 0; i < n; ++i) {
    if (!reference[i].allFinite() || !measured[i].allFinite()) return fit;
    const Eigen::AngleAxisd aa(reference[i]);
    const Eigen::Vector3d theta = aa.angle() * aa.axis();
    A.block<3, 1>(3 * i, 0) = theta;
    A.block<3, 3>(3 * i, 1) = -skew(theta);
    e.segment<3>(3 * i) = rotation_difference_deg(reference[i], measured[i]) * M_PI / 180.0;
  }
  // Least squares on the pairs in `keep`; false when the rotations cannot tell the four numbers
  // apart (rotations about one axis only leave the tilt about it unobservable).
  auto solve = [&](const std::vector<char>& keep, Eigen::Vector4d* x) {
    const int m = static_cast<int>(std::count(keep.begin(), keep.end(), 1));
    if (m < 3) return false;
    Eigen::MatrixXd As(3 * m, 4);
    Eigen::VectorXd es(3 * m);
    for (size_t i = 0, k = 0; i < n; ++i)
      if (keep[i]) {
        As.middleRows<3>(3 * k) = A.middleRows<3>(3 * i);
        es.segment<3>(3 * k++) = e.segment<3>(3 * i);
      }
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(As, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd& sv = svd.singularValues();
    if (!(sv(0) > 0.0) || !(sv(3) > 1e-3 * sv(0))) return false;
    *x = svd.solve(es);
    return x->allFinite();
  };
  // A measurement that failed is an outlier of the fit, not a frame offset. The pairs within 3
  // times the median of a residual are kept: first of the difference itself, then of the fit.
  auto keep_within_3_medians = [&](const Eigen::Vector4d& x, std::vector<char>* keep) {
    std::vector<double> residual(n);
    for (size_t i = 0; i < n; ++i)
      residual[i] = (e.segment<3>(3 * i) - A.middleRows<3>(3 * i) * x).norm();
    std::vector<double> sorted = residual;
    std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
    for (size_t i = 0; i < n; ++i) (*keep)[i] = residual[i] <= 3.0 * sorted[n / 2];
  };
  std::vector<char> keep(n, 1);
  Eigen::Vector4d x = Eigen::Vector4d::Zero();
  keep_within_3_medians(x, &keep);
  if (!solve(keep, &x)) return fit;
  keep_within_3_medians(x, &keep);
  if (!solve(keep, &x)) return fit;
  double before = 0.0, after = 0.0;
  int rows = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!keep[i]) continue;
    before += e.segment<3>(3 * i).squaredNorm();
    after += (e.segment<3>(3 * i) - A.middleRows<3>(3 * i) * x).squaredNorm();
    rows += 3;
  }
  const double to_deg = 180.0 / M_PI;
  fit.ok = true;
  fit.pairs = rows / 3;
  fit.scale = x(0);
  fit.tilt_deg = x.tail<3>() * to_deg;
  fit.rms_before_deg = std::sqrt(before / rows) * to_deg;
  fit.rms_after_deg = std::sqrt(after / rows) * to_deg;
  return fit;
}

bool read_tum_trajectory(const std::string& path, Trajectory* trajectory, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot open";
    return false;
  }
  trajectory->clear();
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double v[8];
    int n = 0;
    while (n < 8 && fields >> v[n]) ++n;
    std::string extra;
    if (n != 8 || (fields >> extra)) {
      *error = path + ":" + std::to_string(number) + ": expected 8 numbers";
      return false;
    }
    for (double x : v)
      if (!std::isfinite(x)) {
        *error = path + ":" + std::to_string(number) + ": non-finite number";
        return false;
      }
    Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (!(q.norm() > 0.5)) {
      *error = path + ":" + std::to_string(number) + ": not a unit quaternion";
      return false;
    }
    StampedPose p;
    p.stamp = v[0];
    p.c = Eigen::Vector3d(v[1], v[2], v[3]);
    p.R = q.normalized().toRotationMatrix();
    trajectory->push_back(p);
  }
  std::sort(trajectory->begin(), trajectory->end(),
            [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  if (trajectory->empty()) {
    *error = path + ": no poses";
    return false;
  }
  return true;
}

bool write_tum_trajectory(const std::string& path, const Trajectory& trajectory,
                          std::string* error) {
  std::ofstream out(path);
  if (!out) {
    *error = path + ": cannot write";
    return false;
  }
  out << "# timestamp tx ty tz qx qy qz qw (camera to world)\n";
  char line[256];
  for (size_t i = 0; i < trajectory.size(); ++i) {
    const StampedPose& p = trajectory[i];
    if (!std::isfinite(p.stamp) || !p.R.allFinite() || !p.c.allFinite()) {
      *error = path + ": pose " + std::to_string(i) + " is not finite";
      return false;
    }
    const Eigen::Quaterniond q(p.R);
    std::snprintf(line, sizeof(line), "%.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f\n", p.stamp,
                  p.c.x(), p.c.y(), p.c.z(), q.x(), q.y(), q.z(), q.w());
    out << line;
  }
  out.flush();
  if (!out) {
    *error = path + ": write failed";
    return false;
  }
  return true;
}

}  // namespace evaluation
}  // namespace hybrid_vo
