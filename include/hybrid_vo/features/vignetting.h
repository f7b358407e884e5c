#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace hybrid_vo {

// A lens darkens its image towards the corners (vignetting; TartanAir's renders and KITTI: 16-17 %
// at the corners). The shading stays in the image while the scene moves, and Lucas-Kanade, which
// assumes that a point keeps its brightness, holds every track back against it: TartanAir's
// orientation drifts 3.0 deg over 188 frames with it and 0.4 without (doc/real_data.md).
//
// The shading is measured from the tracks themselves, as a photometric calibration does (Goldman
// 2010; Engel et al. 2016): a tracked point seen at radius r0 and then r1 changes its brightness by
// V(r1) / V(r0) times the frame's exposure change. With V(r) = exp(a rho + b rho^2), rho = r^2 / R^2
// (R: half the image diagonal, about the image centre), log(I1 / I0) is linear in (a, b) once each
// pair's own exposure offset is taken out; the pairs' normal equations accumulate over frames.
struct VignettingOptions {
  // Corrected only once the corners are estimated this much darker than the centre: a weaker
  // shading moves the tracks less than its estimate's noise does (TUM fr1's Kinect: 5 %).
  double min_corner_darkening = 0.08;
  // Pairs of frames before an estimate counts: over fewer, a scene's own lighting poses as
  // vignetting (TUM fr1's Kinect: 0.89-0.93 at the corners over the plant's 18 frames, 0.975 over
  // rpy's 458).
  int min_pairs = 30;
  // And the information the radius changes carry about the shading's leading term, sum (d rho)^2
  // over the tracks, centred per pair and forgotten as below: a camera that barely moves (the TUM
  // panels: 0.4 after 120 frames; TartanAir: 2 after 45, KITTI: 17 after one) leaves the fit to the
  // scene's lighting.
  double min_information = 2.0;
  // Each frame's weight relative to the next one's: the estimate follows a camera whose aperture
  // changes, over about 1 / (1 - forgetting) frames.
  double forgetting = 0.995;
};

class VignettingEstimator {
 public:
  explicit VignettingEstimator(const VignettingOptions& options = {}) : options_(options) {}
  // One pair of consecutive raw (uncorrected) images and the tracks between them (pixels).
  void add_pair(const cv::Mat& from_image, const cv::Mat& to_image,
                const std::vector<cv::Point2f>& from, const std::vector<cv::Point2f>& to);
  // Whether the estimate is sure and strong enough to correct the images (VignettingOptions).
  bool active() const { return active_; }
  // The estimated V at the corners (1: no shading; 0.83: 17 % darker).
  double corner_gain() const;
  double a() const { return a_; }
  double b() const { return b_; }
  int pairs() const { return pairs_; }
  double information() const { return n11_; }  // see min_information
  void reset();

 private:
  VignettingOptions options_;
  double n11_ = 0, n12_ = 0, n22_ = 0, r1_ = 0, r2_ = 0;  // normal equations (a, b)
  int pairs_ = 0;
  double a_ = 0, b_ = 0;
  bool active_ = false;
};

// 1 / V at every pixel of an image of `size` (CV_32F), for flat_field.
cv::Mat vignetting_gain_map(cv::Size size, double a, double b);
// The image with its shading taken out (CV_8U, saturated); the image itself when `gain` is empty
// or of another size.
cv::Mat flat_field(const cv::Mat& image, const cv::Mat& gain);

}  // namespace hybrid_vo
