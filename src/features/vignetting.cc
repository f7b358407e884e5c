#include "hybrid_vo/features/vignetting.h"

#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "median.h"

namespace hybrid_vo {
namespace {

// The mean brightness of a 5 x 5 window: a single pixel's noise (TUM's Kinect: 2-3 grey levels)
// would swamp a radius change's few percent. Negative where unusable: outside, or near black or
// white, where the sensor's response is not linear.
double window_brightness(const cv::Mat& image, const cv::Point2f& p) {
  constexpr int kHalf = 2;
  const int x = cvRound(p.x), y = cvRound(p.y);
  if (!(std::isfinite(p.x) && std::isfinite(p.y)) || x < kHalf || y < kHalf ||
      x + kHalf >= image.cols || y + kHalf >= image.rows)
    return -1.0;
  int sum = 0;
  for (int dy = -kHalf; dy <= kHalf; ++dy) {
    const uchar* row = image.ptr<uchar>(y + dy) + x;
    for (int dx = -kHalf; dx <= kHalf; ++dx) sum += row[dx];
  }
  const double mean = sum / 25.0;
  return mean < 16.0 || mean > 239.0 ? -1.0 : mean;
}

}  // namespace

void VignettingEstimator::reset() {
  n11_ = n12_ = n22_ = r1_ = r2_ = 0.0;
  pairs_ = 0;
  a_ = b_ = 0.0;
  active_ = false;
}

double VignettingEstimator::corner_gain() const { return std::exp(a_ + b_); }

void VignettingEstimator::add_pair(const cv::Mat& from_image, const cv::Mat& to_image,
                                   const std::vector<cv::Point2f>& from,
                                   const std::vector<cv::Point2f>& to) {
  if (from_image.type() != CV_8UC1 || to_image.type() != CV_8UC1 ||
      from_image.size() != to_image.size() || from.size() != to.size())
    return;
  const double cx = 0.5 * (to_image.cols - 1), cy = 0.5 * (to_image.rows - 1);
  const double inv_r2 = 1.0 / (cx * cx + cy * cy);
  const auto rho = [&](const cv::Point2f& p) {
    return ((p.x - cx) * (p.x - cx) + (p.y - cy) * (p.y - cy)) * inv_r2;
  };
  std::vector<double> y, x1, x2;
  for (size_t i = 0; i < from.size(); ++i) {
    const double i0 = window_brightness(from_image, from[i]);
    const double i1 = window_brightness(to_image, to[i]);
    if (i0 < 0.0 || i1 < 0.0) continue;
    const double r0 = rho(from[i]), r1 = rho(to[i]);
    y.push_back(std::log(i1 / i0));
    x1.push_back(r1 - r0);
    x2.push_back(r1 * r1 - r0 * r0);
  }
  if (y.size() < 10) return;

  // The pair's exposure change is the median of what the current V leaves; outliers (occlusions,
  // specular highlights) are down-weighted by their distance from it (Huber, then cut at 5 sigma).
  std::vector<double> e(y.size());
  for (size_t i = 0; i < y.size(); ++i) e[i] = y[i] - a_ * x1[i] - b_ * x2[i];
  const double offset = median_of(e);
  std::vector<double> dev(e.size());
  for (size_t i = 0; i < e.size(); ++i) dev[i] = std::abs(e[i] - offset);
  const double sigma = std::max(0.005, 1.4826 * median_of(dev));
  std::vector<double> w(y.size());
  double sw = 0, m1 = 0, m2 = 0, my = 0;
  for (size_t i = 0; i < y.size(); ++i) {
    w[i] = dev[i] > 5.0 * sigma ? 0.0 : dev[i] > 2.0 * sigma ? 2.0 * sigma / dev[i] : 1.0;
    sw += w[i];
    m1 += w[i] * x1[i];
    m2 += w[i] * x2[i];
    my += w[i] * y[i];
  }
  if (sw <= 0.0) return;
  m1 /= sw;
  m2 /= sw;
  my /= sw;
  const double f = options_.forgetting;
  n11_ *= f, n12_ *= f, n22_ *= f, r1_ *= f, r2_ *= f;
  for (size_t i = 0; i < y.size(); ++i) {
    // Centred within the pair: its exposure change, unknown, drops out.
    const double u = x1[i] - m1, v = x2[i] - m2, t = y[i] - my;
    n11_ += w[i] * u * u;
    n12_ += w[i] * u * v;
    n22_ += w[i] * v * v;
    r1_ += w[i] * u * t;
    r2_ += w[i] * v * t;
  }
  ++pairs_;

  // A lens only darkens outwards: V non-increasing on [0, 1] (a <= 0, a + 2 b <= 0); else, or
  // where the radii do not separate the two terms, the one-term model.
  const double det = n11_ * n22_ - n12_ * n12_;
  double a = 0.0, b = 0.0;
  if (det > 1e-9 * std::max(1.0, n11_ * n22_)) {
    a = (n22_ * r1_ - n12_ * r2_) / det;
    b = (n11_ * r2_ - n12_ * r1_) / det;
  }
  if (!(a <= 0.0 && a + 2.0 * b <= 0.0 && std::isfinite(a) && std::isfinite(b))) {
    a = n11_ > 0.0 ? std::min(0.0, r1_ / n11_) : 0.0;
    b = 0.0;
  }
  a_ = a;
  b_ = b;
  // Hysteresis, so that a shading near the threshold does not switch the correction every frame.
  const double darkening = 1.0 - corner_gain();
  const double needed = options_.min_corner_darkening * (active_ ? 0.75 : 1.0);
  active_ = pairs_ >= options_.min_pairs && n11_ >= options_.min_information && darkening >= needed;
}

cv::Mat vignetting_gain_map(cv::Size size, double a, double b) {
  cv::Mat exponent(size, CV_32F);
  const double cx = 0.5 * (size.width - 1), cy = 0.5 * (size.height - 1);
  const double inv_r2 = 1.0 / (cx * cx + cy * cy);
  for (int y = 0; y < size.height; ++y) {
    float* row = exponent.ptr<float>(y);
    const double dy2 = (y - cy) * (y - cy);
    for (int x = 0; x < size.width; ++x) {
      const double rho = ((x - cx) * (x - cx) + dy2) * inv_r2;
      row[x] = static_cast<float>(-(a * rho + b * rho * rho));
    }
  }
  cv::Mat gain;
  cv::exp(exponent, gain);
  return gain;
}

cv::Mat flat_field(const cv::Mat& image, const cv::Mat& gain) {
  if (gain.empty() || gain.size() != image.size() || image.type() != CV_8UC1) return image;
  cv::Mat scaled, out;
  image.convertTo(scaled, CV_32F);
  cv::multiply(scaled, gain, scaled);
  scaled.convertTo(out, CV_8U);
  return out;
}

}  // namespace hybrid_vo
