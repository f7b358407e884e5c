#include "hybrid_vo/evaluation/opencv_baseline.h"

#include <opencv2/calib3d.hpp>

namespace hybrid_vo {
namespace evaluation {
namespace {

cv::Mat intrinsics(const PinholeCamera& c) {
  return (cv::Mat_<double>(3, 3) << c.fx, 0.0, c.cx, 0.0, c.fy, c.cy, 0.0, 0.0, 1.0);
}

}  // namespace

OpenCvPose opencv_usac_magsac(const std::vector<PointMatch>& matches, const PinholeCamera& camera1,
                              const PinholeCamera& camera2, double threshold_px, uint64_t seed) {
  OpenCvPose out;
  out.inliers.assign(matches.size(), 0);
  if (matches.size() < 5) return out;
  std::vector<cv::Point2d> px1, px2, n1, n2;
  for (const PointMatch& m : matches) {
    px1.emplace_back(m.x1.x(), m.x1.y());
    px2.emplace_back(m.x2.x(), m.x2.y());
    const Eigen::Vector2d a = camera1.normalize(m.x1), b = camera2.normalize(m.x2);
    n1.emplace_back(a.x(), a.y());
    n2.emplace_back(b.x(), b.y());
  }
  cv::UsacParams params;
  params.confidence = 0.999;
  params.maxIterations = 1000;
  params.score = cv::SCORE_METHOD_MAGSAC;
  params.loMethod = cv::LOCAL_OPTIM_SIGMA;
  params.loSampleSize = 50;
  params.loIterations = 10;
  params.sampler = cv::SAMPLING_UNIFORM;
  params.threshold = threshold_px;
  params.randomGeneratorState = static_cast<int>(seed & 0x7fffffff);
  cv::Mat mask;
  const cv::Mat E = cv::findEssentialMat(px1, px2, intrinsics(camera1), intrinsics(camera2),
                                         cv::noArray(), cv::noArray(), mask, params);
  if (E.rows != 3 || E.cols != 3) return out;
  const cv::Mat ransac_mask = mask.clone();
  // E relates normalised coordinates, so recoverPose takes them with K = I (two cameras may differ).
  cv::Mat R, t;
  if (cv::recoverPose(E, n1, n2, cv::Mat::eye(3, 3, CV_64F), R, t, mask) <= 0) return out;
  for (size_t i = 0; i < matches.size(); ++i)
    out.inliers[i] = ransac_mask.at<uchar>(static_cast<int>(i)) != 0;
  for (int r = 0; r < 3; ++r) {
    out.pose.t(r) = t.at<double>(r);
    for (int k = 0; k < 3; ++k) out.pose.R(r, k) = R.at<double>(r, k);
  }
  out.ok = true;
  return out;
}

}  // namespace evaluation
}  // namespace hybrid_vo
