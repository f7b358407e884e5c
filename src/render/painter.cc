#include "painter.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace hybrid_vo {
namespace render {
namespace {

constexpr int kMipAlign = 64;  // level 0 padding: six exact halvings
constexpr int kShift = 4;      // fixed-point bits of antialiased drawing
constexpr double kOne = 1 << kShift;

cv::Scalar grey(double albedo) { return cv::Scalar(std::clamp(albedo, 0.0, 1.0) * 255.0); }

int round_up(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

}  // namespace

uint64_t hash_mix(uint64_t a, uint64_t b) {
  Rng rng(a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull + (a << 6) + (a >> 2)));
  rng.next();
  return rng.next();
}

Canvas::Canvas(double size_u, double size_v, double texels_per_metre, double albedo)
    : size_u_(size_u), size_v_(size_v), tpm_(texels_per_metre) {
  cols_ = std::max(1, static_cast<int>(std::ceil(size_u * tpm_ - 1e-9)));
  rows_ = std::max(1, static_cast<int>(std::ceil(size_v * tpm_ - 1e-9)));
  mat_ = cv::Mat(round_up(rows_, kMipAlign), round_up(cols_, kMipAlign), CV_8UC1, grey(albedo));
  clear_clip();
}

void Canvas::set_clip(double u0, double v0, double u1, double v1) {
  clip_ = texel_rect(u0, v0, u1, v1);
  if (clip_.area() == 0) clip_ = cv::Rect(0, 0, 1, 1);
}

void Canvas::clear_clip() { clip_ = cv::Rect(0, 0, cols_, rows_); }

cv::Rect Canvas::texel_rect(double u0, double v0, double u1, double v1) const {
  const int c0 = std::clamp(static_cast<int>(std::lround(std::min(u0, u1) * tpm_)), 0, cols_);
  const int c1 = std::clamp(static_cast<int>(std::lround(std::max(u0, u1) * tpm_)), 0, cols_);
  const int r0 = std::clamp(static_cast<int>(std::lround(std::min(v0, v1) * tpm_)), 0, rows_);
  const int r1 = std::clamp(static_cast<int>(std::lround(std::max(v0, v1) * tpm_)), 0, rows_);
  return cv::Rect(c0, r0, c1 - c0, r1 - r0);
}

void Canvas::rect(double u0, double v0, double u1, double v1, double albedo) {
  const cv::Rect r = texel_rect(u0, v0, u1, v1) & clip_;
  if (r.area() > 0) mat_(r).setTo(grey(albedo));
}

void Canvas::frame(double u0, double v0, double u1, double v1, double width, double albedo) {
  rect(u0, v0, u1, v0 + width, albedo);
  rect(u0, v1 - width, u1, v1, albedo);
  rect(u0, v0, u0 + width, v1, albedo);
  rect(u1 - width, v0, u1, v1, albedo);
}

// OpenCV draws with texel centres at integer coordinates; ours are at c + 0.5.
void Canvas::circle(double u, double v, double radius, double albedo) {
  const cv::Point centre(static_cast<int>(std::lround((u * tpm_ - 0.5 - clip_.x) * kOne)),
                         static_cast<int>(std::lround((v * tpm_ - 0.5 - clip_.y) * kOne)));
  const int r = std::max(1, static_cast<int>(std::lround(radius * tpm_ * kOne)));
  cv::Mat m = target();
  cv::circle(m, centre, r, grey(albedo), cv::FILLED, cv::LINE_AA, kShift);
}

void Canvas::polygon(const std::vector<Eigen::Vector2d>& points, double albedo) {
  std::vector<cv::Point> pts;
  for (const Eigen::Vector2d& p : points)
    pts.emplace_back(static_cast<int>(std::lround((p.x() * tpm_ - 0.5 - clip_.x) * kOne)),
                     static_cast<int>(std::lround((p.y() * tpm_ - 0.5 - clip_.y) * kOne)));
  cv::Mat m = target();
  cv::fillConvexPoly(m, pts, grey(albedo), cv::LINE_AA, kShift);
}

double Canvas::font_scale(double height, bool bold) const {
  const int font = bold ? cv::FONT_HERSHEY_DUPLEX : cv::FONT_HERSHEY_SIMPLEX;
  int baseline = 0;
  const cv::Size size = cv::getTextSize("H", font, 1.0, 1, &baseline);
  return height * tpm_ / size.height;
}

void Canvas::text(const std::string& s, double u, double v, double height, double albedo,
                  bool bold) {
  const int font = bold ? cv::FONT_HERSHEY_DUPLEX : cv::FONT_HERSHEY_SIMPLEX;
  const double scale = font_scale(height, bold);
  const int thickness = std::max(1, static_cast<int>(std::lround(scale * (bold ? 2.2 : 1.3))));
  cv::Mat m = target();
  cv::putText(m, s,
              cv::Point(static_cast<int>(u * tpm_) - clip_.x, static_cast<int>(v * tpm_) - clip_.y),
              font, scale, grey(albedo), thickness, cv::LINE_AA);
}

double Canvas::text_width(const std::string& s, double height, bool bold) const {
  const int font = bold ? cv::FONT_HERSHEY_DUPLEX : cv::FONT_HERSHEY_SIMPLEX;
  const double scale = font_scale(height, bold);
  const int thickness = std::max(1, static_cast<int>(std::lround(scale * (bold ? 2.2 : 1.3))));
  int baseline = 0;
  return cv::getTextSize(s, font, scale, thickness, &baseline).width / tpm_;
}

void Canvas::scale(double u0, double v0, double u1, double v1, double factor) {
  const cv::Rect r = texel_rect(u0, v0, u1, v1);
  if (r.area() > 0) mat_(r).convertTo(mat_(r), CV_8U, factor);
}

void Canvas::grain(double u0, double v0, double u1, double v1, double sigma, uint64_t seed) {
  const cv::Rect r = texel_rect(u0, v0, u1, v1);
  if (r.area() == 0) return;
  cv::Mat noise(r.size(), CV_16SC1);
  cv::RNG rng(seed | 1);  // cv::RNG is deterministic for a given state
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma * 255.0);
  cv::Mat region;
  mat_(r).convertTo(region, CV_16S);
  region += noise;
  region.convertTo(mat_(r), CV_8U);
}

void Canvas::mottle(double u0, double v0, double u1, double v1, double amplitude, double cell_m,
                    uint64_t seed, double stretch_u, double stretch_v) {
  const cv::Rect r = texel_rect(u0, v0, u1, v1);
  if (r.area() == 0) return;
  const double cell = std::max(1.0, cell_m * tpm_);
  const int small_cols = std::max(2, static_cast<int>(r.width / (cell * stretch_u)) + 2);
  const int small_rows = std::max(2, static_cast<int>(r.height / (cell * stretch_v)) + 2);
  cv::Mat small(small_rows, small_cols, CV_32FC1);
  cv::RNG rng(seed | 1);
  rng.fill(small, cv::RNG::UNIFORM, -amplitude, amplitude);
  cv::Mat field;
  cv::resize(small, field, r.size(), 0, 0, cv::INTER_CUBIC);
  field += 1.0f;
  cv::Mat region;
  mat_(r).convertTo(region, CV_32F);
  region = region.mul(field);
  region.convertTo(mat_(r), CV_8U);
}

Texture Canvas::finish() const {
  Texture texture;
  texture.texels_per_metre = tpm_;
  cv::Mat level0 = mat_.clone();
  // The padding repeats the last painted row and column, so filtering never pulls in junk.
  if (cols_ < level0.cols) {
    cv::Mat last = level0(cv::Rect(cols_ - 1, 0, 1, level0.rows));
    for (int c = cols_; c < level0.cols; ++c) last.copyTo(level0(cv::Rect(c, 0, 1, level0.rows)));
  }
  if (rows_ < level0.rows) {
    cv::Mat last = level0(cv::Rect(0, rows_ - 1, level0.cols, 1));
    for (int r = rows_; r < level0.rows; ++r) last.copyTo(level0(cv::Rect(0, r, level0.cols, 1)));
  }
  texture.levels.push_back(level0);
  while (texture.levels.back().cols % 2 == 0 && texture.levels.back().rows % 2 == 0 &&
         texture.levels.size() < 12) {
    const cv::Mat& prev = texture.levels.back();
    cv::Mat next;
    cv::resize(prev, next, cv::Size(prev.cols / 2, prev.rows / 2), 0, 0, cv::INTER_AREA);
    texture.levels.push_back(next);
  }
  return texture;
}

std::string random_word(Rng& rng, int min_len, int max_len, bool upper) {
  static const char kLetters[] = "etaoinshrdlucmfwypvbgkqjxz";
  const int len = rng.uniform_int(min_len, max_len);
  std::string word;
  for (int i = 0; i < len; ++i) {
    // Frequent letters first, so words look like words.
    const int k = std::min(25, static_cast<int>(26.0 * std::pow(rng.uniform(), 1.8)));
    word += static_cast<char>(upper ? kLetters[k] - 'a' + 'A' : kLetters[k]);
  }
  return word;
}

}  // namespace render
}  // namespace hybrid_vo
