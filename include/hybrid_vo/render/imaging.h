#pragma once

// How a real camera makes its images, beyond the clean renders' slight blur and constant noise:
// motion blur over the exposure, vignetting, noise that grows with the signal (Poisson-Gaussian),
// an auto exposure that hunts, and JPEG artefacts. The renderers' tools switch it on with
// `--imaging realistic`; every effect is off by default, so the clean renders stay as they were.
// The per-view parts (vignetting, noise, JPEG) are RenderOptions' and sensor_image applies them;
// the exposure's length and the auto exposure are per sequence, and the tools turn them into the
// poses a view integrates over and its exposure gain.

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/render/renderer.h"

namespace hybrid_vo {
namespace render {

struct ImagingOptions {
  // Motion blur: the exposure's length; the frame's pose and stamp are its middle. 0: an instant.
  double exposure_ms = 0.0;
  // The most views averaged over one exposure (odd; fewer when the image moves less).
  int max_exposure_samples = 7;
  double vignetting = 0.0;       // how much darker the image corners are (fraction)
  double shot_noise_gain = 0.0;  // noise variance per grey level of signal (grey levels)
  double exposure_drift = 0.0;   // the auto exposure's gain wanders within 1 +- this
  int jpeg_quality = 0;          // 1..100: every image JPEG-coded at this quality; 0: none
};

// `--imaging realistic`: a 10 ms exposure, corners 35 % darker, shot noise of 0.05 grey levels of
// variance per grey level (2.5 grey levels at mid-grey, a full well of about 5000 electrons), a
// gain drifting within +-15 %, JPEG at quality 85. Its read noise, 1.5 grey levels, is the
// tools' --noise.
ImagingOptions realistic_imaging();
constexpr double kRealisticReadNoise = 1.5;

// Why the options are invalid, or an empty string.
std::string imaging_problem(const ImagingOptions& options);

// The effects switched on, for the tools' summaries ("exposure 10 ms, vignetting 0.35, ..."), or
// "clean".
std::string describe(const ImagingOptions& options);

// The sensor: a CV_32FC1 radiance image in grey levels (RenderOptions::exposure applied) to
// the 8-bit image. The optics' blur (blur_sigma) and vignetting, then noise of variance
// noise_sigma^2 + shot_noise_gain * signal (seeded by noise_seed), clipping and rounding to
// 8 bits, and JPEG coding at jpeg_quality. With the clean options (no vignetting, shot noise or
// JPEG) it is the renderer's sensor as it always was.
cv::Mat sensor_image(cv::Mat radiance, const RenderOptions& options);

// The vignetting's brightness factor at (x, y) of a width x height image: the cos^4 law's
// shape, 1 / (1 + k r^2)^2 with r the distance from the image centre over the half diagonal,
// k such that the corners get 1 - vignetting.
double vignetting_factor(double vignetting, double x, double y, int width, int height);

// The auto exposure's gain at `time` (seconds): 1 + drift s(t), |s| <= 1, s a smooth wander
// (three seeded sinusoids of periods 2 to 9 s) plus a level that jumps to a new value about every
// 4 s (a hunting auto exposure's steps). The same for every camera of a rig at one time; exactly
// 1 with drift 0.
double exposure_gain(double drift, uint64_t seed, double time);

// The fewest views (odd, so that the middle one is the frame's own pose; at most max_samples)
// that keep consecutive views of an exposure within a pixel, when the image moves by motion_px
// over the exposure.
int exposure_samples(double motion_px, int max_samples);

// The times of `samples` views spread evenly over an exposure of exposure_s seconds, relative to
// its middle (each stands for 1/samples of it); the middle one is exactly 0.
std::vector<double> exposure_offsets(double exposure_s, int samples);

}  // namespace render
}  // namespace hybrid_vo
