#include "hybrid_vo/features/line_detection.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include "hybrid_vo/features/gray_image.h"

namespace hybrid_vo {
namespace {

// The given percentile of the gradient magnitude (3x3 Sobel / 8: grey levels per pixel) over
// `inside`, from a histogram of 0.25 grey-level bins over every other row and column: a global
// statistic. The Sobel responses are computed at those pixels only (a quarter of the work of
// filtering the whole image), from the image's own pixels around them, as cv::Sobel does inside
// an image; `inside` must leave a pixel of the image on each side.
double gradient_percentile(const cv::Mat& gray, const cv::Rect& inside, double percentile) {
  constexpr double kBin = 0.25;
  constexpr int kBins = 1024;
  std::vector<int> histogram(kBins, 0);
  int samples = 0;
  for (int y = inside.y; y < inside.y + inside.height; y += 2) {
    const uchar* above = gray.ptr<uchar>(y - 1);
    const uchar* row = gray.ptr<uchar>(y);
    const uchar* below = gray.ptr<uchar>(y + 1);
    for (int x = inside.x; x < inside.x + inside.width; x += 2) {
      const int gx = (above[x + 1] + 2 * row[x + 1] + below[x + 1]) -
                     (above[x - 1] + 2 * row[x - 1] + below[x - 1]);
      const int gy = (below[x - 1] + 2 * below[x] + below[x + 1]) -
                     (above[x - 1] + 2 * above[x] + above[x + 1]);
      const double magnitude = 0.125 * std::sqrt(static_cast<double>(gx * gx + gy * gy));
      ++histogram[std::min(kBins - 1, static_cast<int>(magnitude / kBin))];
      ++samples;
    }
  }
  const double wanted = std::clamp(percentile, 0.0, 100.0) / 100.0 * samples;
  double seen = 0.0;
  for (int b = 0; b < kBins; ++b) {
    seen += histogram[b];
    if (seen >= wanted) return (b + 1) * kBin;
  }
  return kBins * kBin;
}

// A merged segment: its fragments' endpoints, each weighted by half its fragment's length.
struct Chain {
  std::vector<Eigen::Vector2d> points;
  std::vector<double> weights;
  LineSegment segment;

  void add(const LineSegment& s) {
    points.push_back(s.p1);
    points.push_back(s.p2);
    weights.push_back(0.5 * s.length());
    weights.push_back(0.5 * s.length());
  }
  // The weighted total-least-squares line of the points, spanned by their extreme projections.
  void fit() {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    double total = 0.0;
    for (size_t k = 0; k < points.size(); ++k) {
      mean += weights[k] * points[k];
      total += weights[k];
    }
    mean /= total;
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (size_t k = 0; k < points.size(); ++k)
      scatter += weights[k] * (points[k] - mean) * (points[k] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
    Eigen::Vector2d u = eig.eigenvectors().col(1);
    // Keep the direction of the chain's first (longest) fragment.
    if (u.dot(points[1] - points[0]) < 0.0) u = -u;
    double lo = 0.0, hi = 0.0;
    for (size_t k = 0; k < points.size(); ++k) {
      const double t = u.dot(points[k] - mean);
      lo = k == 0 ? t : std::min(lo, t);
      hi = k == 0 ? t : std::max(hi, t);
    }
    segment = LineSegment(mean + lo * u, mean + hi * u);
  }
};

// Whether fragment t continues chain segment s: the same direction, on its line, and near it.
bool continues(const LineSegment& s, const LineSegment& t, double cos_angle, double offset,
               double gap) {
  const double ls = s.length(), lt = t.length();
  if (!(ls > 0.0) || !(lt > 0.0)) return false;
  const Eigen::Vector2d us = (s.p2 - s.p1) / ls, ut = (t.p2 - t.p1) / lt;
  if (std::abs(us.dot(ut)) < cos_angle) return false;
  const Eigen::Vector2d n(-us.y(), us.x());
  if (std::abs(n.dot(t.p1 - s.p1)) > offset || std::abs(n.dot(t.p2 - s.p1)) > offset) return false;
  const double a = us.dot(t.p1 - s.p1), b = us.dot(t.p2 - s.p1);
  const double separation = std::max({0.0, std::min(a, b) - ls, -std::max(a, b)});
  return separation <= gap;
}

double default_gradient(LineDetector detector) {
  return detector == LineDetector::kLsd ? kLsdDefaultGradient : kFldDefaultGradient;
}

}  // namespace

bool along_image_border(const LineSegment& s, int width, int height, double margin) {
  if (!(margin > 0.0)) return false;
  auto near = [margin](double a, double b, double side) {
    return std::abs(a - side) <= margin && std::abs(b - side) <= margin;
  };
  return near(s.p1.x(), s.p2.x(), 0.0) || near(s.p1.x(), s.p2.x(), width - 1.0) ||
         near(s.p1.y(), s.p2.y(), 0.0) || near(s.p1.y(), s.p2.y(), height - 1.0);
}

double line_gradient_threshold(const cv::Mat& gray, const LineDetectionOptions& options) {
  const double fixed = default_gradient(options.detector);
  if (!options.adapt_to_contrast || gray.empty()) return fixed;
  // Inside the border, whose artefacts (a dark last row) would otherwise set the contrast.
  const int margin = 2 + static_cast<int>(std::ceil(std::max(0.0, options.border_margin_px)));
  const cv::Rect inside(margin, margin, gray.cols - 2 * margin, gray.rows - 2 * margin);
  if (inside.width < 3 || inside.height < 3) return fixed;
  const double adapted =
      options.contrast_fraction * gradient_percentile(gray, inside, options.contrast_percentile);
  return std::clamp(adapted, std::min(options.min_gradient, fixed), fixed);
}

std::vector<LineSegment> merge_collinear_segments(std::vector<LineSegment> segments,
                                                  const LineDetectionOptions& options) {
  std::stable_sort(segments.begin(), segments.end(),
                   [](const LineSegment& a, const LineSegment& b) {
                     return a.length() > b.length();
                   });
  const double cos_angle = std::cos(options.merge_angle_deg * M_PI / 180.0);
  std::vector<char> used(segments.size(), 0);
  std::vector<LineSegment> merged;
  for (size_t i = 0; i < segments.size(); ++i) {
    if (used[i]) continue;
    used[i] = 1;
    Chain chain;
    chain.add(segments[i]);
    chain.segment = segments[i];
    // Joining a fragment moves the chain's line a little, which may bring others within reach.
    for (bool grown = true; grown;) {
      grown = false;
      for (size_t j = i + 1; j < segments.size(); ++j) {
        if (used[j] || !continues(chain.segment, segments[j], cos_angle, options.merge_offset_px,
                                  options.merge_gap_px))
          continue;
        used[j] = 1;
        chain.add(segments[j]);
        chain.fit();
        grown = true;
      }
    }
    merged.push_back(chain.segment);
  }
  return merged;
}

std::vector<LineSegment> detect_line_segments(const GrayImage& image,
                                              const LineDetectionOptions& options) {
  std::vector<LineSegment> segments;
  if (image.empty()) return segments;
  const cv::Mat& gray = image.mat();

  std::vector<cv::Vec4f> raw;
  const double gradient = line_gradient_threshold(gray, options);
  // Fragments are not taken shorter than the final minimum: on TUM fr3 structure_notexture,
  // half the minimum joined no more long edges, and FLD found 30 % more to check on KITTI.
  const double min_raw_length = options.min_length_px;
  const bool lowered = gradient < default_gradient(options.detector);
  if (options.detector == LineDetector::kLsd) {
    // LSD's gradient threshold is quant / sin(ang_th), ang_th 22.5 degrees; its default quant 2.
    const double quant = lowered ? gradient * std::sin(22.5 * M_PI / 180.0) : 2.0;
    cv::createLineSegmentDetector(cv::LSD_REFINE_STD, 0.8, 0.6, quant)->detect(gray, raw);
  } else {
    const int min_length = static_cast<int>(std::max(1.0, min_raw_length));
    const double canny = lowered ? 8.0 * gradient : 50.0;
    cv::ximgproc::createFastLineDetector(min_length, 1.414213562f, canny, canny)->detect(gray, raw);
  }
  for (const cv::Vec4f& r : raw) {
    LineSegment s({r[0], r[1]}, {r[2], r[3]});
    if (all_finite(s.p1) && all_finite(s.p2) && s.length() >= min_raw_length &&
        !along_image_border(s, gray.cols, gray.rows, options.border_margin_px))
      segments.push_back(s);
  }
  if (options.merge_collinear) segments = merge_collinear_segments(std::move(segments), options);
  if (options.max_segments > 0 && static_cast<int>(segments.size()) > options.max_segments) {
    std::partial_sort(segments.begin(), segments.begin() + options.max_segments, segments.end(),
                      [](const LineSegment& a, const LineSegment& b) {
                        return a.length() > b.length();
                      });
    segments.resize(options.max_segments);
  }
  return segments;
}

}  // namespace hybrid_vo
