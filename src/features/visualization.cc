#include "hybrid_vo/features/visualization.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

namespace hybrid_vo {
namespace {

cv::Mat to_bgr(const cv::Mat& image) {
  cv::Mat bgr;
  if (image.empty()) return bgr;
  if (image.channels() == 1)
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else if (image.channels() == 4)
    cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  else
    bgr = image.clone();
  if (bgr.depth() != CV_8U) bgr.convertTo(bgr, CV_8U);
  return bgr;
}

cv::Point2f pt(const Eigen::Vector2d& p) {
  return {static_cast<float>(p.x()), static_cast<float>(p.y())};
}

bool selected(const std::vector<char>& mask, size_t i) { return mask.empty() || (i < mask.size() && mask[i]); }

}  // namespace

cv::Scalar vp_colour(int k) {
  static const cv::Scalar palette[] = {{60, 60, 230}, {60, 200, 60}, {230, 120, 40},
                                       {0, 200, 230}, {200, 60, 200}, {230, 200, 0}};
  if (k < 0) return {150, 150, 150};
  return palette[k % 6];
}

cv::Mat draw_view(const cv::Mat& image, const std::vector<Eigen::Vector2d>& points,
                  const std::vector<LineSegment>& segments, const std::vector<int>& labels,
                  const std::vector<Eigen::Vector3d>& vp_directions, const PinholeCamera& camera) {
  cv::Mat out = to_bgr(image);
  if (out.empty()) return out;
  for (size_t i = 0; i < segments.size(); ++i) {
    const int label = i < labels.size() ? labels[i] : -1;
    cv::line(out, pt(segments[i].p1), pt(segments[i].p2), vp_colour(label), 2, cv::LINE_AA);
  }
  for (const Eigen::Vector2d& p : points)
    cv::circle(out, pt(p), 3, cv::Scalar(40, 220, 40), 1, cv::LINE_AA);
  for (size_t k = 0; k < vp_directions.size(); ++k) {
    const Eigen::Vector3d& d = vp_directions[k];
    if (!(std::abs(d.z()) > 1e-9)) continue;
    const Eigen::Vector2d v = camera.denormalize(d.head<2>() / d.z());
    if (std::abs(v.x() - 0.5 * out.cols) > out.cols || std::abs(v.y() - 0.5 * out.rows) > out.rows)
      continue;
    cv::drawMarker(out, pt(v), vp_colour(static_cast<int>(k)), cv::MARKER_CROSS, 24, 3);
  }
  return out;
}

cv::Mat draw_two_view(const cv::Mat& image1, const cv::Mat& image2, const TwoViewMatches& matches,
                      const std::vector<char>& point_mask, const std::vector<char>& line_mask,
                      const PinholeCamera& camera1, const PinholeCamera& camera2) {
  std::vector<Eigen::Vector2d> p1, p2;
  for (size_t i = 0; i < matches.points.size(); ++i) {
    if (!selected(point_mask, i)) continue;
    p1.push_back(matches.points[i].x1);
    p2.push_back(matches.points[i].x2);
  }
  std::vector<LineSegment> s1, s2;
  std::vector<int> labels;
  for (size_t i = 0; i < matches.lines.size(); ++i) {
    if (!selected(line_mask, i)) continue;
    s1.push_back(matches.lines[i].s1);
    s2.push_back(matches.lines[i].s2);
    labels.push_back(i < matches.line_vp.size() ? matches.line_vp[i] : -1);
  }
  std::vector<Eigen::Vector3d> d1, d2;
  for (const VpMatch& v : matches.vps) {
    d1.push_back(v.d1);
    d2.push_back(v.d2);
  }
  const cv::Mat a = draw_view(image1, p1, s1, labels, d1, camera1);
  const cv::Mat b = draw_view(image2, p2, s2, labels, d2, camera2);
  if (a.empty() || b.empty()) return cv::Mat();
  cv::Mat canvas(std::max(a.rows, b.rows), a.cols + b.cols, CV_8UC3, cv::Scalar(0, 0, 0));
  a.copyTo(canvas(cv::Rect(0, 0, a.cols, a.rows)));
  b.copyTo(canvas(cv::Rect(a.cols, 0, b.cols, b.rows)));
  const cv::Point2f shift(static_cast<float>(a.cols), 0.0f);
  // Every few matches only, so that the picture stays readable.
  const size_t step = std::max<size_t>(1, p1.size() / 150);
  for (size_t i = 0; i < p1.size(); i += step)
    cv::line(canvas, pt(p1[i]), pt(p2[i]) + shift, cv::Scalar(40, 220, 40), 1, cv::LINE_AA);
  return canvas;
}

}  // namespace hybrid_vo
