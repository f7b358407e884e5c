// Line matching by LBD: tentative matches (mutual nearest neighbours that pass the ratio test,
// and candidates) and the geometric filter's choice among them (line_geometric_filter.cc).
#include "hybrid_vo/features/line_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "lbd.h"
#include "line_geometric_filter.h"

namespace hybrid_vo {
namespace {

// Distances between every row of `a` and `b` (LBD octaves side by side): Hamming for binary, L2
// for float descriptors, scaled to 0..256; the distance of two segments is the smallest over all
// pairs of their octaves.
cv::Mat segment_distances(const cv::Mat& a, const cv::Mat& b) {
  const bool binary = a.depth() == CV_8U;
  const int width = binary ? kLbdBytes : kLbdFloats;
  const int octaves_a = a.cols / width, octaves_b = b.cols / width;
  cv::Mat best(a.rows, b.rows, CV_32F, cv::Scalar(std::numeric_limits<float>::max()));
  cv::Mat distances;
  for (int oa = 0; oa < octaves_a; ++oa) {
    for (int ob = 0; ob < octaves_b; ++ob) {
      // batchDistance computes Hamming distances into CV_32S only.
      cv::batchDistance(a.colRange(oa * width, (oa + 1) * width),
                        b.colRange(ob * width, (ob + 1) * width), distances,
                        binary ? CV_32S : CV_32F, cv::noArray(),
                        binary ? cv::NORM_HAMMING : cv::NORM_L2);
      if (binary) distances.convertTo(distances, CV_32F);
      best = cv::min(best, distances);
    }
  }
  if (!binary) best *= 128.0;  // unit vectors: L2 in [0, 2]
  return best;
}

// True when segment `t` lies on the infinite line of `s` (same direction within ~6 degrees, both
// endpoints within 3 px) and not far beyond its ends: typically a fragment of the same edge.
bool collinear(const LineSegment& s, const LineSegment& t) {
  const Eigen::Vector3d l = line_through(s.p1, s.p2);
  if (l.isZero() || t.length() <= 0.0) return false;
  const Eigen::Vector2d us = (s.p2 - s.p1).normalized(), ut = (t.p2 - t.p1).normalized();
  if (us.dot(ut) < std::cos(0.1)) return false;
  if (std::abs(l.dot(homogeneous(t.p1))) > 3.0 || std::abs(l.dot(homogeneous(t.p2))) > 3.0)
    return false;
  // Gap between the two along the line: at most half the longer one, plus a few pixels.
  const double t1 = us.dot(t.p1 - s.p1), t2 = us.dot(t.p2 - s.p1);
  const double gap = std::max({0.0, std::min(t1, t2) - s.length(), -std::max(t1, t2)});
  return gap <= 0.5 * std::max(s.length(), t.length()) + 5.0;
}

// Tentative matches between segments `a` (image 1) and `b` (image 2), each pair once.
class TentativeMatches {
 public:
  TentativeMatches(const std::vector<LineSegment>& a, const std::vector<LineSegment>& b)
      : a_(a), b_(b) {}
  void add(int i, int j, bool anchor) {
    if (!seen_.insert({i, j}).second) return;
    Tentative t;
    t.i = i;
    t.j = j;
    t.anchor = anchor;
    t.rotation = wrap_angle(direction_angle(b_[j]) - direction_angle(a_[i]));
    list_.push_back(t);
  }
  const std::vector<Tentative>& list() const { return list_; }

 private:
  const std::vector<LineSegment>& a_;
  const std::vector<LineSegment>& b_;
  std::vector<Tentative> list_;
  std::set<std::pair<int, int>> seen_;
};

// Anchors: mutual nearest neighbours (rows of `distances`: image 1) that pass the ratio test.
void add_anchors(const cv::Mat& distances, double max_distance,
                 const std::vector<LineSegment>& b, const LineMatchingOptions& options,
                 TentativeMatches* tentative) {
  const int n1 = distances.rows, n2 = distances.cols;
  // Best match in image 1 of every image-2 segment, for the mutual check.
  std::vector<int> backward(n2, -1);
  std::vector<float> backward_distance(n2, std::numeric_limits<float>::max());
  for (int i = 0; i < n1; ++i) {
    const float* row = distances.ptr<float>(i);
    for (int j = 0; j < n2; ++j) {
      if (row[j] < backward_distance[j]) {
        backward_distance[j] = row[j];
        backward[j] = i;
      }
    }
  }
  for (int i = 0; i < n1; ++i) {
    const float* row = distances.ptr<float>(i);
    const int best = static_cast<int>(std::min_element(row, row + n2) - row);
    if (row[best] > max_distance) continue;
    if (options.mutual && backward[best] != i) continue;
    if (options.ratio < 1.0) {
      // The ratio test's competitor is the nearest segment that is not a collinear fragment of
      // the best one: an edge split differently by the detector in the two images would
      // otherwise fail it although either fragment is a correct match.
      float second = std::numeric_limits<float>::max();
      for (int j = 0; j < n2; ++j) {
        if (j == best || row[j] >= second) continue;
        if (collinear(b[best], b[j])) continue;
        second = row[j];
      }
      if (second < std::numeric_limits<float>::max() && row[best] >= options.ratio * second)
        continue;
    }
    tentative->add(i, best, true);
  }
}

// Candidates, with the geometric filter only: the `candidates` nearest neighbours of every
// image-1 segment, which need more support than an anchor. They recover matches that the ratio
// test or the mutual check lost to repeated structure or to fragmentation.
void add_candidates(const cv::Mat& distances, double max_distance, int candidates,
                    TentativeMatches* tentative) {
  std::vector<std::pair<float, int>> d;
  for (int i = 0; i < distances.rows; ++i) {
    d.clear();
    const float* row = distances.ptr<float>(i);
    for (int j = 0; j < distances.cols; ++j)
      if (row[j] <= max_distance) d.emplace_back(row[j], j);
    const size_t count = std::min(d.size(), static_cast<size_t>(candidates));
    std::partial_sort(d.begin(), d.begin() + count, d.end());
    for (size_t c = 0; c < count; ++c) tentative->add(i, d[c].second, false);
  }
}

}  // namespace

float line_descriptor_distance(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  if (a.cols != b.cols || a.type() != b.type() || i < 0 || j < 0 || i >= a.rows || j >= b.rows)
    return std::numeric_limits<float>::infinity();
  return segment_distances(a.row(i), b.row(j)).at<float>(0, 0);
}

double max_line_descriptor_distance(const LineMatchingOptions& options, const cv::Mat& descriptors) {
  return descriptors.depth() == CV_8U ? options.max_hamming : 128.0 * options.max_l2;
}

LineMatchingOptions video_line_matching_options() {
  LineMatchingOptions options;
  options.detection.detector = LineDetector::kFld;
  options.detection.min_length_px = 30.0;
  options.detection.adapt_to_contrast = true;
  options.detection.merge_collinear = true;
  // One octave at half resolution with 5 px bands: a third of the full-resolution cost, and as
  // good on the benchmark's ED segments (recall 63.6 % vs 64.4 % at one full-resolution octave).
  options.description.octaves = 1;
  options.description.first_octave = 1;
  options.description.band_width = 5;
  return options;
}

std::vector<LineMatch> match_line_features(const LineFeatures& a, const LineFeatures& b,
                                           const LineMatchingOptions& options,
                                           std::vector<std::pair<int, int>>* pairs) {
  std::vector<LineMatch> matches;
  if (pairs) pairs->clear();
  if (a.descriptors.empty() || b.descriptors.empty() || a.descriptors.cols != b.descriptors.cols ||
      a.descriptors.type() != b.descriptors.type() ||
      a.descriptors.rows != static_cast<int>(a.segments.size()) ||
      b.descriptors.rows != static_cast<int>(b.segments.size()))
    return matches;
  const cv::Mat distances = segment_distances(a.descriptors, b.descriptors);
  const double max_distance = max_line_descriptor_distance(options, a.descriptors);
  TentativeMatches tentative(a.segments, b.segments);
  add_anchors(distances, max_distance, b.segments, options, &tentative);
  const bool filter = options.geometric_filter;
  if (filter && options.candidates > 0)
    add_candidates(distances, max_distance, options.candidates, &tentative);

  const std::vector<Tentative>& list = tentative.list();
  std::vector<bool> keep(list.size());
  if (filter) {
    keep = geometric_filter(a.segments, b.segments, list, options);
  } else {
    for (size_t k = 0; k < list.size(); ++k) keep[k] = list[k].anchor;
  }
  for (size_t k = 0; k < list.size(); ++k) {
    if (!keep[k]) continue;
    LineMatch m;
    m.s1 = a.segments[list[k].i];
    m.s2 = b.segments[list[k].j];
    matches.push_back(m);
    if (pairs) pairs->emplace_back(list[k].i, list[k].j);
  }
  return matches;
}

}  // namespace hybrid_vo
