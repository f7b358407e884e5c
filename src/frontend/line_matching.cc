#include "hybrid_vo/frontend/line_matching.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>
#include <opencv2/line_descriptor.hpp>

#include "hybrid_vo/frontend/gray_image.h"

namespace hybrid_vo {
namespace {

constexpr int kLbdBytes = 32;   // 256-bit binary LBD per octave
constexpr int kLbdFloats = 72;  // float LBD per octave: 9 bands x 8 statistics

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

double wrap_angle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a <= -M_PI) a += 2 * M_PI;
  return a;
}

double direction_angle(const LineSegment& s) {
  return std::atan2(s.p2.y() - s.p1.y(), s.p2.x() - s.p1.x());
}

// The dominant angle among `angles` (radians): the peak of a circular histogram of 10 degree
// bins smoothed with [1 2 1], refined as the mean of the angles within 15 degrees of its centre.
double dominant_angle(const std::vector<double>& angles) {
  constexpr int kBins = 36;
  const double width = 2 * M_PI / kBins;
  auto bin = [&](int b) { return ((b % kBins) + kBins) % kBins; };
  std::vector<double> histogram(kBins, 0.0);
  for (double a : angles) histogram[bin(static_cast<int>(std::floor((a + M_PI) / width)))] += 1;
  int peak = 0;
  double peak_votes = -1.0;
  for (int b = 0; b < kBins; ++b) {
    const double votes = histogram[bin(b - 1)] + 2 * histogram[b] + histogram[bin(b + 1)];
    if (votes > peak_votes) {
      peak_votes = votes;
      peak = b;
    }
  }
  const double centre = -M_PI + (peak + 0.5) * width;
  double sum = 0.0;
  int count = 0;
  for (double a : angles) {
    const double delta = wrap_angle(a - centre);
    if (std::abs(delta) <= 1.5 * width) {
      sum += delta;
      ++count;
    }
  }
  return count > 0 ? wrap_angle(centre + sum / count) : centre;
}

// A tentative match of segment i (image 1) with segment j (image 2).
struct Tentative {
  int i = 0, j = 0;
  bool anchor = false;    // mutual nearest neighbours that passed the ratio test
  double rotation = 0.0;  // from the image-1 to the image-2 direction, radians
};

// Distance between two segments: 0 when they cross, else the smallest endpoint-to-segment one.
double point_segment_distance(const Eigen::Vector2d& p, const LineSegment& s) {
  const Eigen::Vector2d d = s.p2 - s.p1;
  const double l2 = d.squaredNorm();
  const double t = l2 > 0.0 ? std::min(1.0, std::max(0.0, (p - s.p1).dot(d) / l2)) : 0.0;
  return (s.p1 + t * d - p).norm();
}

double segment_distance(const LineSegment& s, const LineSegment& t) {
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const Eigen::Vector2d ds = s.p2 - s.p1, dt = t.p2 - t.p1;
  const double c1 = cross(ds, t.p1 - s.p1), c2 = cross(ds, t.p2 - s.p1);
  const double c3 = cross(dt, s.p1 - t.p1), c4 = cross(dt, s.p2 - t.p1);
  if (c1 * c2 < 0.0 && c3 * c4 < 0.0) return 0.0;
  return std::min(std::min(point_segment_distance(t.p1, s), point_segment_distance(t.p2, s)),
                  std::min(point_segment_distance(s.p1, t), point_segment_distance(s.p2, t)));
}

// Side of segment `t` relative to the oriented line `l` (line_through of a segment): +1 or -1
// when both endpoints lie on that side by more than 1 px, 0 when it crosses or touches the line.
int side(const Eigen::Vector3d& l, const LineSegment& t) {
  const double d1 = l.dot(homogeneous(t.p1)), d2 = l.dot(homogeneous(t.p2));
  if (d1 > 1.0 && d2 > 1.0) return 1;
  if (d1 < -1.0 && d2 < -1.0) return -1;
  return 0;
}

// A segment with its oriented line.
struct Oriented {
  LineSegment s;
  Eigen::Vector3d l;
};

// The sidedness constraint (Bay, Ferrari & Van Gool, "Wide-baseline stereo matching with line
// segments", CVPR 2005): with segments oriented alike in both images, a neighbour that lies left
// of a matched segment in image 1 lies left of it in image 2 too, for any orientation-preserving
// homography and, approximately, for nearby structure in general. Each of the two matches
// (s1, s2) and (t1, t2) is checked against the other's line; crossing segments give no verdict.
bool same_sides(const Oriented& s1, const Oriented& s2, const Oriented& t1, const Oriented& t2) {
  return side(s1.l, t1.s) * side(s2.l, t2.s) >= 0 && side(t1.l, s1.s) * side(t2.l, s2.s) >= 0;
}

// The local position check: the affine map x2 = M x1 + t that best takes the supporters'
// image-1 segments onto their partners' infinite lines (each endpoint on the line: two linear
// equations per match, six unknowns) predicts where the query's image-1 segment lands in image 2.
// The query agrees when both predicted endpoints lie within `max_error_px` of its partner's line
// (or within twice the supporters' own median residual where the neighbourhood is not affine:
// depth edges, strong perspective) and the predicted segment overlaps the partner (a collinear
// neighbour further along the same edge is another segment). Fewer than three supporters, or
// supporters too parallel to fix the map, give no verdict.
enum class Verdict { kAgrees, kDisagrees, kUnknown };

Verdict position_agrees(const std::vector<std::pair<LineSegment, LineSegment>>& supporters,
                        const LineSegment& q1, const LineSegment& q2, double max_error_px) {
  if (supporters.size() < 3) return Verdict::kUnknown;
  const Eigen::Vector2d c1 = q1.midpoint(), c2 = q2.midpoint();
  double scale = 1.0;  // conditioning: coordinates centred on the query and scaled to ~1
  for (const auto& [s1, s2] : supporters)
    scale = std::max(scale, std::max((s1.p1 - c1).norm(), (s1.p2 - c1).norm()));
  const int rows = 2 * static_cast<int>(supporters.size());
  Eigen::MatrixXd A(rows, 6);
  Eigen::VectorXd rhs(rows);
  std::vector<Eigen::Vector3d> lines;
  int r = 0;
  for (const auto& [s1, s2] : supporters) {
    const Eigen::Vector3d l = line_through(s2.p1 - c2, s2.p2 - c2);
    lines.push_back(l);
    for (const Eigen::Vector2d& p : {s1.p1, s1.p2}) {
      const Eigen::Vector2d x = (p - c1) / scale;
      A.row(r) << l.x() * x.x(), l.x() * x.y(), l.x(), l.y() * x.x(), l.y() * x.y(), l.y();
      rhs(r) = -l.z() / scale;
      ++r;
    }
  }
  // Normal equations; a condition number above 1e6 (singular values 1e3 apart) means parallel
  // or too few supporters.
  const Eigen::Matrix<double, 6, 6> AtA = A.transpose() * A;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(AtA);
  const Eigen::Matrix<double, 6, 1> ev = eigen.eigenvalues();  // ascending
  if (!(ev(0) > 1e-6 * ev(5))) return Verdict::kUnknown;
  const Eigen::Matrix<double, 6, 1> u = AtA.ldlt().solve(A.transpose() * rhs);  // M, t / scale
  Eigen::Matrix2d M;
  M << u(0), u(1), u(3), u(4);
  const Eigen::Vector2d t = scale * Eigen::Vector2d(u(2), u(5));
  auto residual = [&](const LineSegment& s1, const Eigen::Vector3d& l2) {
    const Eigen::Vector2d a = M * (s1.p1 - c1) + t, b = M * (s1.p2 - c1) + t;
    return std::max(std::abs(l2.dot(homogeneous(a))), std::abs(l2.dot(homogeneous(b))));
  };
  std::vector<double> residuals;
  for (size_t k = 0; k < supporters.size(); ++k)
    residuals.push_back(residual(supporters[k].first, lines[k]));
  std::nth_element(residuals.begin(), residuals.begin() + residuals.size() / 2, residuals.end());
  const double tolerance = std::max(max_error_px, 2.0 * residuals[residuals.size() / 2]);
  if (residual(q1, line_through(q2.p1 - c2, q2.p2 - c2)) > tolerance) return Verdict::kDisagrees;
  const Eigen::Vector2d along = (q2.p2 - q2.p1).normalized();
  const double ta = along.dot(M * (q1.p1 - c1) + t + c2 - q2.p1);
  const double tb = along.dot(M * (q1.p2 - c1) + t + c2 - q2.p1);
  const bool overlap = std::max(ta, tb) > -tolerance && std::min(ta, tb) < q2.length() + tolerance;
  return overlap ? Verdict::kAgrees : Verdict::kDisagrees;
}

// The geometric filter (see LineMatchingOptions): which tentative matches to keep.
std::vector<bool> geometric_filter(const std::vector<LineSegment>& a,
                                   const std::vector<LineSegment>& b,
                                   const std::vector<Tentative>& tentative,
                                   const LineMatchingOptions& options) {
  const size_t n = tentative.size();
  std::vector<bool> keep(n, false);
  // 1. Global: the dominant rotation of the oriented segment directions (a full turn, since both
  //    images orient by the gradient), by histogram voting over the anchors as in Zhang & Koch
  //    (2013). Perspective spreads the rotations over some tens of degrees around it.
  std::vector<double> anchor_rotations;
  for (const Tentative& t : tentative)
    if (t.anchor) anchor_rotations.push_back(t.rotation);
  if (anchor_rotations.empty()) return keep;
  const double rotation = dominant_angle(anchor_rotations);
  const double max_rotation = options.max_rotation_deviation_deg * M_PI / 180.0;
  std::vector<bool> plausible(n);
  for (size_t k = 0; k < n; ++k)
    plausible[k] = std::abs(wrap_angle(tentative[k].rotation - rotation)) <= max_rotation;

  // 2. Local consensus, in the spirit of GMS (Bian et al., CVPR 2017) and LPM (Ma et al., IJCV
  //    2019): a match is supported by those of its K nearest voters in image 1 whose partners are
  //    also among the K nearest voters of its partner in image 2, rotate alike and keep the same
  //    sides. Neighbourhoods are ranked by segment-to-segment distance, so this holds under any
  //    scale change and smooth viewpoint change, whereas a wrong match's neighbours scatter.
  const double max_local_rotation = options.max_local_rotation_deg * M_PI / 180.0;
  std::vector<Oriented> o1(a.size()), o2(b.size());
  for (size_t i = 0; i < a.size(); ++i) o1[i] = {a[i], line_through(a[i].p1, a[i].p2)};
  for (size_t j = 0; j < b.size(); ++j) o2[j] = {b[j], line_through(b[j].p1, b[j].p2)};
  // The pool of possible voters (the plausible anchors) and, computed once per segment, the
  // segment distances from each image-1 (image-2) segment to the pool's image-1 (image-2) sides.
  std::vector<int> pool;
  for (size_t k = 0; k < n; ++k)
    if (tentative[k].anchor && plausible[k]) pool.push_back(static_cast<int>(k));
  std::vector<std::vector<double>> to1(a.size()), to2(b.size());
  auto distances = [&](bool first, int segment) -> const std::vector<double>& {
    std::vector<double>& d = first ? to1[segment] : to2[segment];
    if (d.empty() && !pool.empty()) {
      d.resize(pool.size());
      for (size_t r = 0; r < pool.size(); ++r) {
        d[r] = first ? segment_distance(a[segment], a[tentative[pool[r]].i])
                     : segment_distance(b[segment], b[tentative[pool[r]].j]);
      }
    }
    return d;
  };
  // Among `voters` (positions into the pool), the k nearest to a segment, skipping the query.
  auto nearest = [&](const std::vector<double>& d, const std::vector<int>& voters, int k,
                     size_t query) {
    std::vector<std::pair<double, int>> order;
    order.reserve(voters.size());
    for (int v : voters)
      if (static_cast<size_t>(pool[v]) != query) order.emplace_back(d[v], v);
    const size_t count = std::min(order.size(), static_cast<size_t>(std::max(k, 0)));
    if (count < order.size()) std::nth_element(order.begin(), order.begin() + count, order.end());
    std::vector<int> out(count);
    for (size_t r = 0; r < count; ++r) out[r] = order[r].second;
    return out;
  };
  std::vector<char> in_near2(pool.size(), 0);
  auto support = [&](size_t query, const std::vector<int>& voters, bool check_position) {
    const Tentative& q = tentative[query];
    // Two random sets of k among n voters share k^2 / n on average: k <= n / 3 bounds a wrong
    // match's chance overlap by k / 3 however few the voters are (the rotation, side and
    // position checks then thin it out).
    const int k = std::min(options.neighbours, static_cast<int>(voters.size()) / 3);
    const std::vector<int> near1 = nearest(distances(true, q.i), voters, k, query);
    const std::vector<int> near2 = nearest(distances(false, q.j), voters, k, query);
    std::vector<std::pair<LineSegment, LineSegment>> supporters;
    for (int v : near2) in_near2[v] = 1;
    for (int v : near1) {
      if (!in_near2[v]) continue;
      const Tentative& t = tentative[pool[v]];
      if (t.i == q.i || t.j == q.j) continue;  // a fragment of the same edge proves nothing
      if (std::abs(wrap_angle(t.rotation - q.rotation)) > max_local_rotation) continue;
      if (!same_sides(o1[q.i], o2[q.j], o1[t.i], o2[t.j])) continue;
      supporters.emplace_back(a[t.i], b[t.j]);
    }
    for (int v : near2) in_near2[v] = 0;
    if (check_position && options.max_position_error_px > 0.0) {
      // A candidate has no distinctiveness of its own: its position must be confirmed.
      const Verdict verdict =
          position_agrees(supporters, a[q.i], b[q.j], options.max_position_error_px);
      if (verdict == Verdict::kDisagrees || (verdict == Verdict::kUnknown && !q.anchor)) return 0;
    }
    return static_cast<int>(supporters.size());
  };
  // The voters are the anchors that the other anchors support (twice, so that rejected anchors
  // stop lending support).
  std::vector<int> voters(pool.size());
  for (size_t v = 0; v < pool.size(); ++v) voters[v] = static_cast<int>(v);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> verified;
    for (int v : voters)
      if (support(pool[v], voters, false) >= options.min_support) verified.push_back(v);
    voters.swap(verified);
  }
  if (static_cast<int>(voters.size()) <= options.min_support) return keep;
  // 3. Every match is then judged against the voters, with the position check: a voter needs
  //    `min_support`, any other match (a failed anchor is out) `min_candidate_support`.
  std::vector<bool> is_voter(n, false);
  for (int v : voters) is_voter[pool[v]] = true;
  for (size_t k = 0; k < n; ++k) {
    if (!plausible[k] || (tentative[k].anchor && !is_voter[k])) continue;
    keep[k] = support(k, voters, true) >=
              (is_voter[k] ? options.min_support : options.min_candidate_support);
  }
  return keep;
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
  std::vector<cv::line_descriptor::KeyLine> keylines;
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
    // One KeyLine per octave, all with the same class_id: BinaryDescriptor::compute describes
    // each in the octave-th level of its pyrDown pyramid (factor 2), along the KeyLine's angle and
    // over numOfPixels samples (computeLBD), so the angle carries the gradient orientation.
    for (int o = 0; o < octaves; ++o) {
      const double scale = base_scale / (1 << o);
      auto in_octave = [&](double v) { return static_cast<float>((v + 0.5) * scale - 0.5); };
      cv::line_descriptor::KeyLine kl;
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
      kl.response = static_cast<float>(s.length() / std::max(gray.cols, gray.rows));
      kl.size = static_cast<float>(std::abs((s.p2.x() - s.p1.x()) * (s.p2.y() - s.p1.y())));
      keylines.push_back(kl);
    }
  }
  if (keylines.empty()) return LineFeatures();

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
  descriptors = descriptors.reshape(1, static_cast<int>(features.segments.size()));
  // LBD normalises by the gradient energy: a segment without any yields NaN; drop it.
  LineFeatures valid;
  std::vector<int> valid_indices;
  for (int r = 0; r < descriptors.rows; ++r) {
    if (!cv::checkRange(descriptors.row(r))) continue;
    valid.segments.push_back(features.segments[r]);
    valid.descriptors.push_back(descriptors.row(r));
    valid_indices.push_back(indices[r]);
  }
  if (kept) *kept = valid_indices;
  return valid;
}

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

LineFeatures detect_line_features(const GrayImage& image, const LineMatchingOptions& options) {
  if (image.empty()) return LineFeatures();
  return describe_line_segments(image, detect_line_segments(image, options.detection), nullptr,
                                options.description);
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
  const int n1 = distances.rows, n2 = distances.cols;
  const double max_distance = max_line_descriptor_distance(options, a.descriptors);

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

  // Anchors: mutual nearest neighbours that pass the ratio test.
  std::vector<Tentative> tentative;
  std::set<std::pair<int, int>> seen;
  auto add = [&](int i, int j, bool anchor) {
    if (!seen.insert({i, j}).second) return;
    Tentative t;
    t.i = i;
    t.j = j;
    t.anchor = anchor;
    t.rotation = wrap_angle(direction_angle(b.segments[j]) - direction_angle(a.segments[i]));
    tentative.push_back(t);
  };
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
        if (collinear(b.segments[best], b.segments[j])) continue;
        second = row[j];
      }
      if (second < std::numeric_limits<float>::max() && row[best] >= options.ratio * second)
        continue;
    }
    add(i, best, true);
  }
  // Candidates, with the geometric filter only: the `candidates` nearest neighbours of every
  // image-1 segment, which need more support than an anchor. They recover matches that the
  // ratio test or the mutual check lost to repeated structure or to fragmentation.
  const bool filter = options.geometric_filter;
  if (filter && options.candidates > 0) {
    std::vector<std::pair<float, int>> d;
    for (int i = 0; i < n1; ++i) {
      d.clear();
      const float* row = distances.ptr<float>(i);
      for (int j = 0; j < n2; ++j)
        if (row[j] <= max_distance) d.emplace_back(row[j], j);
      const size_t count = std::min(d.size(), static_cast<size_t>(options.candidates));
      std::partial_sort(d.begin(), d.begin() + count, d.end());
      for (size_t c = 0; c < count; ++c) add(i, d[c].second, false);
    }
  }

  std::vector<bool> keep(tentative.size());
  if (filter) {
    keep = geometric_filter(a.segments, b.segments, tentative, options);
  } else {
    for (size_t k = 0; k < tentative.size(); ++k) keep[k] = tentative[k].anchor;
  }
  for (size_t k = 0; k < tentative.size(); ++k) {
    if (!keep[k]) continue;
    LineMatch m;
    m.s1 = a.segments[tentative[k].i];
    m.s2 = b.segments[tentative[k].j];
    matches.push_back(m);
    if (pairs) pairs->emplace_back(tentative[k].i, tentative[k].j);
  }
  return matches;
}

}  // namespace hybrid_vo
