#include "hybrid_vo/features/point_flow_field.h"

#include <algorithm>
#include <cmath>

#include "median.h"

namespace hybrid_vo {
namespace {

Eigen::Vector2d median_motion(const std::vector<Eigen::Vector2d>& motions) {
  std::vector<double> x, y;
  for (const Eigen::Vector2d& m : motions) {
    x.push_back(m.x());
    y.push_back(m.y());
  }
  return Eigen::Vector2d(median_of(x), median_of(y));
}

}  // namespace

PointFlowField::PointFlowField(const std::vector<PointMatch>& motions, double cell_px)
    : cell_(cell_px > 1.0 ? cell_px : 1.0) {
  for (const PointMatch& m : motions)
    if (all_finite(m.x1) && all_finite(m.x2)) motions_.push_back(m);
  if (motions_.empty()) return;
  double x1 = motions_[0].x1.x(), y1 = motions_[0].x1.y();
  x0_ = x1;
  y0_ = y1;
  for (const PointMatch& m : motions_) {
    x0_ = std::min(x0_, m.x1.x()), y0_ = std::min(y0_, m.x1.y());
    x1 = std::max(x1, m.x1.x()), y1 = std::max(y1, m.x1.y());
  }
  // Points far outside any image would make a huge grid: at most 256 buckets a side.
  cell_ = std::max(cell_, std::max(x1 - x0_, y1 - y0_) / 256.0);
  cols_ = static_cast<int>((x1 - x0_) / cell_) + 1;
  rows_ = static_cast<int>((y1 - y0_) / cell_) + 1;
  cells_.assign(static_cast<size_t>(cols_) * rows_, {});
  for (int i = 0; i < static_cast<int>(motions_.size()); ++i) {
    const int cx = static_cast<int>((motions_[i].x1.x() - x0_) / cell_);
    const int cy = static_cast<int>((motions_[i].x1.y() - y0_) / cell_);
    cells_[static_cast<size_t>(cy) * cols_ + cx].push_back(i);
  }
}

bool PointFlowField::predict(const LineSegment& s, double radius_px, int min_points,
                             LineSegment* predicted, double* spread_px) const {
  const double length = s.length();
  if (motions_.empty() || !(length > 0.0) || !all_finite(s.p1) || !all_finite(s.p2) ||
      !(radius_px > 0.0))
    return false;
  const Eigen::Vector2d u = (s.p2 - s.p1) / length, n(-u.y(), u.x());
  const auto bucket = [&](double v, double origin, int count) {
    return std::clamp(static_cast<int>(std::floor((v - origin) / cell_)), 0, count - 1);
  };
  const double lo_x = std::min(s.p1.x(), s.p2.x()) - radius_px;
  const double hi_x = std::max(s.p1.x(), s.p2.x()) + radius_px;
  const double lo_y = std::min(s.p1.y(), s.p2.y()) - radius_px;
  const double hi_y = std::max(s.p1.y(), s.p2.y()) + radius_px;
  if (hi_x < x0_ || hi_y < y0_ || lo_x > x0_ + cols_ * cell_ || lo_y > y0_ + rows_ * cell_)
    return false;
  // The points near the segment, by half, with where along it they lie (0 at p1, 1 at p2).
  std::vector<Eigen::Vector2d> first, second, all;
  std::vector<double> first_at, second_at, across, where;
  for (int cy = bucket(lo_y, y0_, rows_); cy <= bucket(hi_y, y0_, rows_); ++cy)
    for (int cx = bucket(lo_x, x0_, cols_); cx <= bucket(hi_x, x0_, cols_); ++cx)
      for (const int i : cells_[static_cast<size_t>(cy) * cols_ + cx]) {
        const Eigen::Vector2d d = motions_[i].x1 - s.p1;
        const double along = u.dot(d);
        if (std::abs(n.dot(d)) > radius_px || along < -radius_px || along > length + radius_px)
          continue;
        const Eigen::Vector2d motion = motions_[i].x2 - motions_[i].x1;
        const double t = along / length;
        (t < 0.5 ? first : second).push_back(motion);
        (t < 0.5 ? first_at : second_at).push_back(t);
        all.push_back(motion);
        across.push_back(n.dot(motion));
        where.push_back(t);
      }
  if (static_cast<int>(all.size()) < std::max(1, min_points)) return false;
  Eigen::Vector2d m1 = median_motion(all), m2 = m1;
  if (first.size() >= 2 && second.size() >= 2) {
    const double t1 = median_of(first_at), t2 = median_of(second_at);
    if (t2 - t1 > 0.2) {
      const Eigen::Vector2d a = median_motion(first), b = median_motion(second);
      m1 = a + (0.0 - t1) / (t2 - t1) * (b - a);
      m2 = a + (1.0 - t1) / (t2 - t1) * (b - a);
    }
  }
  // How far the points' motions across the segment stray from the prediction's there.
  std::vector<double> deviations;
  for (size_t k = 0; k < across.size(); ++k)
    deviations.push_back(std::abs(across[k] - n.dot(m1 + where[k] * (m2 - m1))));
  *spread_px = 1.4826 * median_of(deviations);
  *predicted = LineSegment(s.p1 + m1, s.p2 + m2);
  return true;
}

}  // namespace hybrid_vo
