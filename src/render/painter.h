#pragma once

// Painting helpers for the renderer's albedo textures: a portable random generator and a canvas
// addressed in metres.

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "hybrid_vo/render/scene.h"

namespace hybrid_vo {
namespace render {

// splitmix64: the same sequence on every platform and standard library.
class Rng {
 public:
  explicit Rng(uint64_t seed) : state_(seed) {}
  uint64_t next() {
    uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  int uniform_int(int lo, int hi) {  // inclusive
    return lo + static_cast<int>(next() % static_cast<uint64_t>(hi - lo + 1));
  }
  bool chance(double p) { return uniform() < p; }

 private:
  uint64_t state_;
};

// A well-mixed hash of two values (seeds per tile, per wall, per frame).
uint64_t hash_mix(uint64_t a, uint64_t b);

// An 8-bit albedo texture addressed in metres: u to the right, v down, texel (c, r) covering
// [c, c + 1) / tpm x [r, r + 1) / tpm. Axis-aligned rectangles snap to texel boundaries, so
// their corners sit exactly at snap(u), snap(v); other shapes are antialiased.
class Canvas {
 public:
  Canvas(double size_u, double size_v, double texels_per_metre, double albedo);

  double tpm() const { return tpm_; }
  double size_u() const { return size_u_; }
  double size_v() const { return size_v_; }
  cv::Mat& mat() { return mat_; }
  double snap(double metres) const { return std::round(metres * tpm_) / tpm_; }

  void rect(double u0, double v0, double u1, double v1, double albedo);
  // A border of the given width inside [u0, u1] x [v0, v1].
  void frame(double u0, double v0, double u1, double v1, double width, double albedo);
  void circle(double u, double v, double radius, double albedo);
  void polygon(const std::vector<Eigen::Vector2d>& points, double albedo);
  // Text with its baseline at v, starting at u; `height` is the capital height in metres.
  void text(const std::string& s, double u, double v, double height, double albedo,
            bool bold = false);
  // Width in metres of text drawn with text().
  double text_width(const std::string& s, double height, bool bold = false) const;
  // Multiplies a region by a factor (shadows, highlights).
  void scale(double u0, double v0, double u1, double v1, double factor);
  // Fine per-texel Gaussian grain (sigma in albedo units) over a region.
  void grain(double u0, double v0, double u1, double v1, double sigma, uint64_t seed);
  // Smooth multiplicative variation 1 +- amplitude with features of about cell_m metres;
  // stretch factors > 1 elongate them along u or v (wood grain).
  void mottle(double u0, double v0, double u1, double v1, double amplitude, double cell_m,
              uint64_t seed, double stretch_u = 1.0, double stretch_v = 1.0);

  // Restricts circle(), polygon() and text() to a region (pictures must not spill over).
  void set_clip(double u0, double v0, double u1, double v1);
  void clear_clip();

  // Replicates the painted area into the padding and builds the mip chain.
  Texture finish() const;

 private:
  cv::Rect texel_rect(double u0, double v0, double u1, double v1) const;
  double font_scale(double height, bool bold) const;
  // The matrix to draw antialiased shapes into and its offset in texels (the clip region).
  cv::Mat target() { return mat_(clip_); }

  double size_u_, size_v_, tpm_;
  int cols_, rows_;  // painted area; mat_ is padded beyond it
  cv::Mat mat_;
  cv::Rect clip_;
};

// Random text for posters and signs.
std::string random_word(Rng& rng, int min_len, int max_len, bool upper);

}  // namespace render
}  // namespace hybrid_vo
