// LBD description of line segments: each segment oriented by its gradient and described by
// cv::line_descriptor (Zhang & Koch 2013) at the configured pyramid levels.
#include "hybrid_vo/features/line_matching.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>
#include <opencv2/line_descriptor.hpp>

#include "lbd.h"

namespace hybrid_vo {
namespace {

using cv::line_descriptor::KeyLine;

// Bilinear intensity with the border replicated (images of at least 2 x 2 pixels).
double sample(const cv::Mat& gray, double x, double y) {
  x = std::min(std::max(x, 0.0), gray.cols - 1.0);
  y = std::min(std::max(y, 0.0), gray.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), gray.cols - 2);
  const int y0 = std::min(static_cast<int>(y), gray.rows - 2);
  const double ax = x - x0, ay = y - y0;
  const uchar* r0 = gray.ptr<uchar>(y0);
  const uchar* r1 = gray.ptr<uchar>(y0 + 1);
  return (1 - ay) * ((1 - ax) * r0[x0] + ax * r0[x0 + 1]) +
         ay * ((1 - ax) * r1[x0] + ax * r1[x0 + 1]);
}

// Orients `s` like EDLines/LBD do (Zhang & Koch 2013; EDLineDetector::LineValidation_ in
// opencv_contrib): the mean gradient across the segment, dark to bright, points along (-dy, dx)
// of p1->p2. The contrast is the intensity difference 1.5 px either side of the
// segment, averaged along it; false (no edge to describe) below 1 grey level.
bool orient_by_gradient(const cv::Mat& gray, LineSegment* s) {
  const Eigen::Vector2d d = s->p2 - s->p1;
  const double length = d.norm();
  const Eigen::Vector2d u = d / length, n(-u.y(), u.x());
  const int steps = std::max(2, static_cast<int>(length));
  double contrast = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const Eigen::Vector2d p = s->p1 + (length * k / steps) * u;
    const Eigen::Vector2d a = p + 1.5 * n, b = p - 1.5 * n;
    contrast += sample(gray, a.x(), a.y()) - sample(gray, b.x(), b.y());
  }
  if (std::abs(contrast) < steps + 1.0) return false;
  if (contrast < 0.0) std::swap(s->p1, s->p2);
  return true;
}

// One KeyLine per octave of segment `s` (oriented, with midpoint `mid`), all with class_id `id`:
// BinaryDescriptor::compute describes each in the octave-th level of its pyrDown pyramid (factor
// 2), along the KeyLine's angle and over numOfPixels samples (computeLBD), so the angle carries
// the gradient orientation. `base_scale` is the descriptors' image's (first_octave), `image_size`
// the larger side of the image.
void add_keylines(const LineSegment& s, const Eigen::Vector2d& mid, int id, int octaves,
                  double base_scale, int image_size, std::vector<KeyLine>* keylines) {
  for (int o = 0; o < octaves; ++o) {
    const double scale = base_scale / (1 << o);
    auto in_octave = [&](double v) { return static_cast<float>((v + 0.5) * scale - 0.5); };
    KeyLine kl;
    kl.class_id = id;
    kl.octave = o;
    kl.angle = static_cast<float>(direction_angle(s));
    kl.startPointX = static_cast<float>(s.p1.x());
    kl.startPointY = static_cast<float>(s.p1.y());
    kl.endPointX = static_cast<float>(s.p2.x());
    kl.endPointY = static_cast<float>(s.p2.y());
    kl.sPointInOctaveX = in_octave(s.p1.x());
    kl.sPointInOctaveY = in_octave(s.p1.y());
    kl.ePointInOctaveX = in_octave(s.p2.x());
    kl.ePointInOctaveY = in_octave(s.p2.y());
    kl.pt = cv::Point2f(static_cast<float>(mid.x()), static_cast<float>(mid.y()));
    kl.lineLength = static_cast<float>(s.length() * scale);
    kl.numOfPixels = std::max(1, static_cast<int>(std::lround(s.length() * scale)));
    kl.response = static_cast<float>(s.length() / image_size);
    kl.size = static_cast<float>(std::abs((s.p2.x() - s.p1.x()) * (s.p2.y() - s.p1.y())));
    keylines->push_back(kl);
  }
}

// The LBD rows of `segments` from their `keylines` in `base` (the descriptors' image), one per
// segment; those without a finite descriptor are dropped. `kept` receives, per row, the entry
// of `indices` (the segment's index in the caller's list).
LineFeatures describe_keylines(const cv::Mat& base, std::vector<KeyLine>& keylines,
                               const std::vector<LineSegment>& segments,
                               const std::vector<int>& indices, int octaves,
                               const LineDescriptionOptions& options, std::vector<int>* kept) {
  cv::line_descriptor::BinaryDescriptor::Params params;
  params.widthOfBand_ = std::max(1, options.band_width);
  params.numOfOctave_ = octaves;
  params.reductionRatio = 2;
  cv::Ptr<cv::line_descriptor::BinaryDescriptor> lbd =
      cv::line_descriptor::BinaryDescriptor::createBinaryDescriptor(params);
  cv::Mat descriptors;
  lbd->compute(base, keylines, descriptors, options.float_descriptor);
  if (descriptors.rows != static_cast<int>(keylines.size()) ||
      descriptors.cols != (options.float_descriptor ? kLbdFloats : kLbdBytes))
    return LineFeatures();
  // Rows are ordered segment by segment, octave by octave: one row per segment.
  descriptors = descriptors.reshape(1, static_cast<int>(segments.size()));
  // LBD normalises by the gradient energy: a segment without any yields NaN; drop it.
  LineFeatures valid;
  std::vector<int> valid_indices;
  for (int r = 0; r < descriptors.rows; ++r) {
    if (!cv::checkRange(descriptors.row(r))) continue;
    valid.segments.push_back(segments[r]);
    valid.descriptors.push_back(descriptors.row(r));
    valid_indices.push_back(indices[r]);
  }
  if (kept) *kept = valid_indices;
  return valid;
}

}  // namespace

LineFeatures describe_line_segments(const GrayImage& image,
                                    const std::vector<LineSegment>& segments,
                                    std::vector<int>* kept, const LineDescriptionOptions& options) {
  LineFeatures features;
  if (kept) kept->clear();
  const cv::Mat& gray = image.mat();
  if (gray.empty() || segments.empty() || gray.cols < 2 || gray.rows < 2) return features;
  const int octaves = std::max(1, std::min(options.octaves, 5));
  // The descriptors' image: the first_octave-th level of a pyrDown pyramid. A pyrDown level maps
  // x to (x + 0.5) / 2 - 0.5.
  cv::Mat base = gray;
  double base_scale = 1.0;
  for (int f = 0; f < std::min(options.first_octave, 3) && base.cols >= 4 && base.rows >= 4; ++f) {
    cv::pyrDown(base, base);
    base_scale *= 0.5;
  }

  std::vector<int> indices;
  std::vector<KeyLine> keylines;
  for (size_t i = 0; i < segments.size(); ++i) {
    const LineSegment& input = segments[i];
    if (!all_finite(input.p1) || !all_finite(input.p2)) continue;
    if (input.length() < std::max(1.0, options.min_length_px)) continue;
    const Eigen::Vector2d mid = input.midpoint();
    if (mid.x() < 0 || mid.y() < 0 || mid.x() > gray.cols - 1 || mid.y() > gray.rows - 1) continue;
    LineSegment s = input;
    if (!orient_by_gradient(gray, &s)) continue;
    const int id = static_cast<int>(indices.size());
    indices.push_back(static_cast<int>(i));
    features.segments.push_back(s);
    add_keylines(s, mid, id, octaves, base_scale, std::max(gray.cols, gray.rows), &keylines);
  }
  if (keylines.empty()) return LineFeatures();
  if (!options.describe) {
    if (kept) *kept = indices;
    return features;
  }
  return describe_keylines(base, keylines, features.segments, indices, octaves, options, kept);
}

LineFeatures detect_line_features(const GrayImage& image, const LineMatchingOptions& options) {
  if (image.empty()) return LineFeatures();
  return describe_line_segments(image, detect_line_segments(image, options.detection), nullptr,
                                options.description);
}

}  // namespace hybrid_vo
