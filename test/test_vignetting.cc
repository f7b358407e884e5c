// The vignetting measured from tracks (features/vignetting.h) and the KLT tracker's correction.
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "hybrid_vo/features/klt_tracker.h"
#include "hybrid_vo/features/vignetting.h"
#include "image_test_utils.h"

namespace hybrid_vo {
namespace {

constexpr int kRows = 480, kCols = 640;

// A camera panning over a flat texture in a circle (so that points cross the image in every
// direction), its image darkened by V(rho) = exp(a rho + b rho^2) and scaled by an exposure that
// changes every frame, plus sensor noise.
struct Pan {
  cv::Mat texture;
  double a = 0.0, b = 0.0, step_px = 6.0;
  std::vector<double> exposure;

  Pan(double a_, double b_, double step, int frames, unsigned seed) : a(a_), b(b_), step_px(step) {
    cv::setRNGSeed(static_cast<int>(seed));
    // Low contrast on a bright mean: the windows where a shading moves a track the most.
    const cv::Mat noise = testing::blurred_noise(kRows + 400, kCols + 400, 2.5);
    noise.convertTo(texture, CV_32F, 0.5, 70.0);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> gain(0.92, 1.08);
    for (int k = 0; k < frames; ++k) exposure.push_back(gain(rng));
  }
  cv::Point2d offset(int k) const {  // where frame k's corner lies on the texture
    const double angle = 0.05 * k;
    const double radius = step_px / 0.05;
    return {200.0 + radius * std::cos(angle), 200.0 + radius * std::sin(angle)};
  }
  // Whole-pixel offsets keep the truth exact.
  cv::Point offset_px(int k) const {
    const cv::Point2d o = offset(k);
    return {static_cast<int>(std::lround(o.x)), static_cast<int>(std::lround(o.y))};
  }
  cv::Mat frame(int k) const {
    const cv::Point o = offset_px(k);
    cv::Mat f = texture(cv::Rect(o.x, o.y, kCols, kRows)).clone();
    const cv::Mat shading = vignetting_gain_map(f.size(), a, b);  // 1 / V
    cv::divide(f, shading, f);
    f *= exposure[k];
    cv::Mat noise(f.size(), CV_32F);
    cv::randn(noise, 0.0, 1.0);
    f += noise;
    cv::Mat out;
    f.convertTo(out, CV_8U);
    return out;
  }
  // Points of frame k on a grid, and where they are in frame k + 1.
  void tracks(int k, std::vector<cv::Point2f>* from, std::vector<cv::Point2f>* to) const {
    const cv::Point d = offset_px(k) - offset_px(k + 1);
    from->clear();
    to->clear();
    for (int y = 20; y < kRows - 20; y += 24)
      for (int x = 20; x < kCols - 20; x += 24) {
        const cv::Point2f p(x, y), q(x + d.x, y + d.y);
        if (q.x < 10 || q.y < 10 || q.x > kCols - 10 || q.y > kRows - 10) continue;
        from->push_back(p);
        to->push_back(q);
      }
  }
};

VignettingEstimator estimate(const Pan& pan, int frames) {
  VignettingEstimator v;
  std::vector<cv::Point2f> from, to;
  cv::Mat previous = pan.frame(0);
  for (int k = 0; k + 1 < frames; ++k) {
    const cv::Mat next = pan.frame(k + 1);
    pan.tracks(k, &from, &to);
    v.add_pair(previous, next, from, to);
    previous = next;
  }
  return v;
}

TEST(Vignetting, RecoversTheShadingOfAPanningCamera) {
  for (const auto& [a, b] : {std::pair{-0.35, -0.05}, std::pair{-0.2, 0.0}, std::pair{-0.5, 0.1}}) {
    const Pan pan(a, b, 6.0, 60, 3);
    const VignettingEstimator v = estimate(pan, 60);
    const double truth = std::exp(a + b);
    EXPECT_NEAR(v.corner_gain(), truth, 0.03) << a << " " << b;
    // Halfway out too, where most tracks are.
    EXPECT_NEAR(v.a() * 0.25 + v.b() * 0.0625, a * 0.25 + b * 0.0625, 0.02) << a << " " << b;
    EXPECT_TRUE(v.active());
    EXPECT_EQ(v.pairs(), 59);
  }
}

TEST(Vignetting, StaysOffWithoutAShading) {
  const VignettingEstimator v = estimate(Pan(0.0, 0.0, 6.0, 60, 4), 60);
  EXPECT_GT(v.corner_gain(), 0.96);
  EXPECT_FALSE(v.active());
}

TEST(Vignetting, WaitsForEnoughPairsAndMotion) {
  // A strong shading, but too few pairs: not yet.
  EXPECT_FALSE(estimate(Pan(-0.4, 0.0, 6.0, 20, 5), 20).active());
  // Enough pairs, but a camera that barely moves: the radius changes say too little.
  EXPECT_FALSE(estimate(Pan(-0.4, 0.0, 0.3, 60, 5), 60).active());
}

TEST(Vignetting, IgnoresBadInput) {
  VignettingEstimator v;
  const cv::Mat image(kRows, kCols, CV_8UC1, cv::Scalar(128));
  const std::vector<cv::Point2f> one(50, cv::Point2f(100, 100));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  v.add_pair(cv::Mat(), image, one, one);                                    // empty
  v.add_pair(image, image(cv::Rect(0, 0, 320, 240)).clone(), one, one);     // sizes differ
  v.add_pair(image, image, one, std::vector<cv::Point2f>(49));              // counts differ
  v.add_pair(cv::Mat(kRows, kCols, CV_32F), image, one, one);                // not 8-bit grey
  v.add_pair(image, image, std::vector<cv::Point2f>(50, {nan, 5.0f}), one);  // NaN
  v.add_pair(image, image, std::vector<cv::Point2f>(50, {-40, 900}), one);   // outside
  const cv::Mat black(kRows, kCols, CV_8UC1, cv::Scalar(0));
  v.add_pair(black, black, one, one);  // no usable brightness
  EXPECT_EQ(v.pairs(), 0);
  EXPECT_EQ(v.corner_gain(), 1.0);
  EXPECT_FALSE(v.active());
}

TEST(Vignetting, FlatFieldUndoesTheShading) {
  cv::setRNGSeed(7);
  const cv::Mat scene = testing::blurred_noise(kRows, kCols, 2.0);
  cv::Mat scene_f, shaded_f, shaded;
  scene.convertTo(scene_f, CV_32F, 0.6, 40.0);
  const cv::Mat gain = vignetting_gain_map(scene.size(), -0.35, -0.05);
  EXPECT_NEAR(gain.at<float>(kRows / 2, kCols / 2), 1.0, 1e-3);
  EXPECT_NEAR(gain.at<float>(0, 0), std::exp(0.4), 0.01);
  cv::divide(scene_f, gain, shaded_f);
  shaded_f.convertTo(shaded, CV_8U);
  const cv::Mat flat = flat_field(shaded, gain);
  cv::Mat expected, diff;
  scene_f.convertTo(expected, CV_8U);
  cv::absdiff(flat, expected, diff);
  double worst = 0.0;
  cv::minMaxLoc(diff, nullptr, &worst);
  EXPECT_LE(worst, 2.0);  // rounding twice, times 1 / V <= 1.5
  // Without a map, or with one of another size: the image itself.
  EXPECT_EQ(flat_field(shaded, cv::Mat()).data, shaded.data);
  EXPECT_EQ(flat_field(shaded, vignetting_gain_map({320, 240}, -0.3, 0.0)).data, shaded.data);
}

// Through the tracker: on a shaded pan its tracks lag behind the truth; once it has measured the
// shading and tracks on the flat image, they lag less, and it can be switched off.
double mean_lag(bool correct, bool* active) {
  KltTrackerOptions options;
  options.correct_vignetting = correct;
  KltTracker klt(options, 400);
  const Pan pan(-0.45, 0.0, 6.0, 90, 9);
  double lag = 0.0;
  int n = 0;
  for (int k = 0; k < 90; ++k) {
    const std::vector<PointMatch> matches = klt.track(pan.frame(k));
    if (k < 60) continue;
    const cv::Point d = pan.offset_px(k - 1) - pan.offset_px(k);
    const Eigen::Vector2d truth(d.x, d.y);
    for (const PointMatch& m : matches) {
      // Along the motion: a shading that stays in the image holds the track back.
      lag += (m.x2 - m.x1 - truth).dot(truth.normalized());
      ++n;
    }
  }
  *active = klt.vignetting().active() && !klt.flat_field_gain().empty();
  return n > 0 ? lag / n : 0.0;
}

TEST(KltTrackerVignetting, TracksOnTheFlatImageLagLess) {
  bool active_on = false, active_off = true;
  const double on = mean_lag(true, &active_on);
  const double off = mean_lag(false, &active_off);
  std::printf("mean lag along the motion: corrected %+.4f px, as it is %+.4f px\n", on, off);
  EXPECT_TRUE(active_on);
  EXPECT_FALSE(active_off);
  EXPECT_LT(std::abs(on), std::abs(off) / 2.0);
}

}  // namespace
}  // namespace hybrid_vo
