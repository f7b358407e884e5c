#include "hybrid_vo/render/imaging.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "painter.h"

namespace hybrid_vo {
namespace render {
namespace {

constexpr double kPi = 3.14159265358979323846;

void vignette(cv::Mat* radiance, double vignetting) {
  for (int y = 0; y < radiance->rows; ++y) {
    float* row = radiance->ptr<float>(y);
    for (int x = 0; x < radiance->cols; ++x)
      row[x] *= static_cast<float>(
          vignetting_factor(vignetting, x, y, radiance->cols, radiance->rows));
  }
}

// Poisson-Gaussian noise, the Poisson part by its Gaussian limit: a pixel receives thousands of
// electrons, so the shape of the distribution does not matter, its variance does.
void add_signal_dependent_noise(cv::Mat* radiance, double read_sigma, double shot_gain,
                                cv::RNG* rng) {
  cv::Mat noise(radiance->size(), CV_32FC1);
  rng->fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
  const double read_variance = read_sigma * read_sigma;
  for (int y = 0; y < radiance->rows; ++y) {
    float* signal = radiance->ptr<float>(y);
    const float* n = noise.ptr<float>(y);
    for (int x = 0; x < radiance->cols; ++x)
      signal[x] += static_cast<float>(
          n[x] * std::sqrt(read_variance + shot_gain * std::max(0.0f, signal[x])));
  }
}

cv::Mat jpeg_coded(const cv::Mat& image, int quality) {
  std::vector<uchar> bytes;
  cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return cv::imdecode(bytes, cv::IMREAD_GRAYSCALE);
}

// The step level of the auto exposure at `time`: each second, with chance 1/4, it jumps at a
// seeded instant to a new level in [-1, 1]; the last jump before `time` holds.
double exposure_step_level(uint64_t seed, double time) {
  const int64_t slot = static_cast<int64_t>(std::floor(time));
  for (int64_t k = slot; k > slot - 64; --k) {
    Rng rng(hash_mix(seed, static_cast<uint64_t>(k)));
    const bool jumps = rng.chance(0.25);
    const double at = k + rng.uniform(), level = rng.uniform(-1.0, 1.0);
    if (jumps && at <= time) return level;
  }
  return 0.0;
}

}  // namespace

ImagingOptions realistic_imaging() {
  ImagingOptions o;
  o.exposure_ms = 10.0;
  o.vignetting = 0.35;
  o.shot_noise_gain = 0.05;
  o.exposure_drift = 0.15;
  o.jpeg_quality = 85;
  return o;
}

std::string imaging_problem(const ImagingOptions& o) {
  if (!(std::isfinite(o.exposure_ms) && o.exposure_ms >= 0.0 && o.exposure_ms <= 1000.0))
    return "the exposure must be in [0, 1000] ms";
  if (o.max_exposure_samples < 1 || o.max_exposure_samples > 31 || o.max_exposure_samples % 2 == 0)
    return "the views per exposure must be odd, in [1, 31]";
  if (!(std::isfinite(o.vignetting) && o.vignetting >= 0.0 && o.vignetting < 1.0))
    return "the vignetting must be in [0, 1)";
  if (!(std::isfinite(o.shot_noise_gain) && o.shot_noise_gain >= 0.0 && o.shot_noise_gain <= 10.0))
    return "the shot noise gain must be in [0, 10]";
  if (!(std::isfinite(o.exposure_drift) && o.exposure_drift >= 0.0 && o.exposure_drift < 1.0))
    return "the exposure drift must be in [0, 1)";
  if (o.jpeg_quality < 0 || o.jpeg_quality > 100) return "the JPEG quality must be in [0, 100]";
  return "";
}

std::string describe(const ImagingOptions& o) {
  std::string text;
  auto add = [&text](const char* format, double value) {
    char part[64];
    std::snprintf(part, sizeof(part), format, value);
    text += (text.empty() ? "" : ", ") + std::string(part);
  };
  if (o.exposure_ms > 0.0) add("exposure %g ms", o.exposure_ms);
  if (o.vignetting > 0.0) add("vignetting %g", o.vignetting);
  if (o.shot_noise_gain > 0.0) add("shot noise gain %g", o.shot_noise_gain);
  if (o.exposure_drift > 0.0) add("exposure drift %g", o.exposure_drift);
  if (o.jpeg_quality > 0) add("JPEG %g", o.jpeg_quality);
  return text.empty() ? "clean" : text;
}

cv::Mat sensor_image(cv::Mat radiance, const RenderOptions& o) {
  if (o.blur_sigma > 0.0)
    cv::GaussianBlur(radiance, radiance, cv::Size(0, 0), o.blur_sigma, o.blur_sigma,
                     cv::BORDER_REFLECT);
  if (o.vignetting > 0.0) vignette(&radiance, o.vignetting);
  if (o.noise_sigma > 0.0 || o.shot_noise_gain > 0.0) {
    cv::RNG rng(o.noise_seed * 0x9E3779B97F4A7C15ull + 1);
    if (o.shot_noise_gain > 0.0) {
      add_signal_dependent_noise(&radiance, o.noise_sigma, o.shot_noise_gain, &rng);
    } else {
      cv::Mat noise(radiance.size(), CV_32FC1);
      rng.fill(noise, cv::RNG::NORMAL, 0.0, o.noise_sigma);
      radiance += noise;
    }
  }
  cv::Mat image;
  radiance.convertTo(image, CV_8U);
  if (o.jpeg_quality > 0) image = jpeg_coded(image, o.jpeg_quality);
  return image;
}

double vignetting_factor(double vignetting, double x, double y, int width, int height) {
  if (vignetting <= 0.0) return 1.0;
  const double dx = x - 0.5 * (width - 1), dy = y - 0.5 * (height - 1);
  const double half_diagonal_squared = 0.25 * ((width - 1.0) * (width - 1.0) +
                                               (height - 1.0) * (height - 1.0));
  const double r2 = half_diagonal_squared > 0.0 ? (dx * dx + dy * dy) / half_diagonal_squared : 0.0;
  const double k = 1.0 / std::sqrt(1.0 - vignetting) - 1.0;
  const double falloff = 1.0 + k * r2;
  return 1.0 / (falloff * falloff);
}

double exposure_gain(double drift, uint64_t seed, double time) {
  if (drift <= 0.0) return 1.0;
  const uint64_t s = hash_mix(seed, 0xE7905E);
  Rng rng(s);
  double wander = 0.0, weights = 0.0;
  for (int k = 0; k < 3; ++k) {
    const double weight = rng.uniform(0.5, 1.0), period = rng.uniform(2.0, 9.0);
    wander += weight * std::sin(2.0 * kPi * time / period + rng.uniform(0.0, 2.0 * kPi));
    weights += weight;
  }
  const double level = exposure_step_level(hash_mix(s, 1), time);
  return 1.0 + drift * (0.75 * wander / weights + 0.25 * level);
}

int exposure_samples(double motion_px, int max_samples) {
  const double needed = std::ceil(std::max(0.0, motion_px) - 1e-9);
  int n = needed >= max_samples ? max_samples : std::max(1, static_cast<int>(needed));
  if (n % 2 == 0) n = n + 1 <= max_samples ? n + 1 : n - 1;
  return std::max(1, n);
}

std::vector<double> exposure_offsets(double exposure_s, int samples) {
  std::vector<double> offsets;
  for (int k = 0; k < samples; ++k)
    offsets.push_back(2 * k + 1 == samples ? 0.0 : exposure_s * ((k + 0.5) / samples - 0.5));
  return offsets;
}

}  // namespace render
}  // namespace hybrid_vo
