// The geometric filter of line matching: of the tentative matches between two images' segments,
// those that agree with the images' geometric change (the global rotation, the local consensus
// of neighbouring matches and their position).
#include "line_geometric_filter.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

namespace hybrid_vo {
namespace {

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

// Distance between two segments: 0 when they cross, else the smallest endpoint-to-segment one.
// Squared until the end: one square root instead of four (the same value: a square root is
// monotonic and correctly rounded).
double point_segment_squared_distance(const Eigen::Vector2d& p, const LineSegment& s) {
  const Eigen::Vector2d d = s.p2 - s.p1;
  const double l2 = d.squaredNorm();
  const double t = l2 > 0.0 ? std::min(1.0, std::max(0.0, (p - s.p1).dot(d) / l2)) : 0.0;
  return (s.p1 + t * d - p).squaredNorm();
}

double segment_distance(const LineSegment& s, const LineSegment& t) {
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  const Eigen::Vector2d ds = s.p2 - s.p1, dt = t.p2 - t.p1;
  const double c1 = cross(ds, t.p1 - s.p1), c2 = cross(ds, t.p2 - s.p1);
  const double c3 = cross(dt, s.p1 - t.p1), c4 = cross(dt, s.p2 - t.p1);
  if (c1 * c2 < 0.0 && c3 * c4 < 0.0) return 0.0;
  return std::sqrt(std::min(
      std::min(point_segment_squared_distance(t.p1, s), point_segment_squared_distance(t.p2, s)),
      std::min(point_segment_squared_distance(s.p1, t), point_segment_squared_distance(s.p2, t))));
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

// 2. Local consensus, in the spirit of GMS (Bian et al., CVPR 2017) and LPM (Ma et al., IJCV
//    2019): a match is supported by those of its K nearest voters in image 1 whose partners are
//    also among the K nearest voters of its partner in image 2, rotate alike and keep the same
//    sides. Neighbourhoods are ranked by segment-to-segment distance, so this holds under any
//    scale change and smooth viewpoint change, whereas a wrong match's neighbours scatter.
class LocalConsensus {
 public:
  LocalConsensus(const std::vector<LineSegment>& a, const std::vector<LineSegment>& b,
                 const std::vector<Tentative>& tentative, const std::vector<bool>& plausible,
                 const LineMatchingOptions& options)
      : a_(a),
        b_(b),
        tentative_(tentative),
        options_(options),
        max_local_rotation_(options.max_local_rotation_deg * M_PI / 180.0),
        o1_(a.size()),
        o2_(b.size()),
        to1_(a.size()),
        to2_(b.size()) {
    for (size_t i = 0; i < a.size(); ++i) o1_[i] = {a[i], line_through(a[i].p1, a[i].p2)};
    for (size_t j = 0; j < b.size(); ++j) o2_[j] = {b[j], line_through(b[j].p1, b[j].p2)};
    for (size_t k = 0; k < tentative.size(); ++k)
      if (tentative[k].anchor && plausible[k]) pool_.push_back(static_cast<int>(k));
    in_near2_.assign(pool_.size(), 0);
  }

  // The possible voters: the plausible anchors (indices into the tentative matches).
  const std::vector<int>& pool() const { return pool_; }

  // The supporters of match `query` among `voters` (positions into the pool); 0 when
  // `check_position` and the position check rejects it.
  int support(size_t query, const std::vector<int>& voters, bool check_position) {
    const Tentative& q = tentative_[query];
    // Two random sets of k among n voters share k^2 / n on average: k <= n / 3 bounds a wrong
    // match's chance overlap by k / 3 however few the voters are (the rotation, side and
    // position checks then thin it out).
    const int k = std::min(options_.neighbours, static_cast<int>(voters.size()) / 3);
    const std::vector<int> near1 = nearest(distances(true, q.i), voters, k, query);
    const std::vector<int> near2 = nearest(distances(false, q.j), voters, k, query);
    std::vector<std::pair<LineSegment, LineSegment>> supporters;
    for (int v : near2) in_near2_[v] = 1;
    for (int v : near1) {
      if (!in_near2_[v]) continue;
      const Tentative& t = tentative_[pool_[v]];
      if (t.i == q.i || t.j == q.j) continue;  // a fragment of the same edge proves nothing
      if (std::abs(wrap_angle(t.rotation - q.rotation)) > max_local_rotation_) continue;
      if (!same_sides(o1_[q.i], o2_[q.j], o1_[t.i], o2_[t.j])) continue;
      supporters.emplace_back(a_[t.i], b_[t.j]);
    }
    for (int v : near2) in_near2_[v] = 0;
    if (check_position && options_.max_position_error_px > 0.0) {
      // A candidate has no distinctiveness of its own: its position must be confirmed.
      const Verdict verdict =
          position_agrees(supporters, a_[q.i], b_[q.j], options_.max_position_error_px);
      if (verdict == Verdict::kDisagrees || (verdict == Verdict::kUnknown && !q.anchor)) return 0;
    }
    return static_cast<int>(supporters.size());
  }

 private:
  // The segment distances from an image-1 (`first`) or image-2 segment to the pool's segments
  // in that image, computed once per segment.
  const std::vector<double>& distances(bool first, int segment) {
    std::vector<double>& d = first ? to1_[segment] : to2_[segment];
    if (d.empty() && !pool_.empty()) {
      d.resize(pool_.size());
      for (size_t r = 0; r < pool_.size(); ++r) {
        d[r] = first ? segment_distance(a_[segment], a_[tentative_[pool_[r]].i])
                     : segment_distance(b_[segment], b_[tentative_[pool_[r]].j]);
      }
    }
    return d;
  }

  // Among `voters`, the k nearest to a segment (its `distances`), skipping the query.
  std::vector<int> nearest(const std::vector<double>& d, const std::vector<int>& voters, int k,
                           size_t query) {
    std::vector<std::pair<double, int>>& order = order_;  // scratch, kept between calls
    order.clear();
    for (int v : voters)
      if (static_cast<size_t>(pool_[v]) != query) order.emplace_back(d[v], v);
    const size_t count = std::min(order.size(), static_cast<size_t>(std::max(k, 0)));
    if (count < order.size()) std::nth_element(order.begin(), order.begin() + count, order.end());
    std::vector<int> out(count);
    for (size_t r = 0; r < count; ++r) out[r] = order[r].second;
    return out;
  }

  const std::vector<LineSegment>& a_;
  const std::vector<LineSegment>& b_;
  const std::vector<Tentative>& tentative_;
  const LineMatchingOptions& options_;
  const double max_local_rotation_;
  std::vector<Oriented> o1_, o2_;
  std::vector<int> pool_;
  std::vector<std::vector<double>> to1_, to2_;
  std::vector<char> in_near2_;  // scratch: the second image's nearest voters of a query
  std::vector<std::pair<double, int>> order_;  // scratch: voters by distance
};

}  // namespace

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

  // 2. The voters are the anchors that the other anchors support (twice, so that rejected
  //    anchors stop lending support).
  LocalConsensus consensus(a, b, tentative, plausible, options);
  const std::vector<int>& pool = consensus.pool();
  std::vector<int> voters(pool.size());
  for (size_t v = 0; v < pool.size(); ++v) voters[v] = static_cast<int>(v);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int> verified;
    for (int v : voters)
      if (consensus.support(pool[v], voters, false) >= options.min_support) verified.push_back(v);
    voters.swap(verified);
  }
  if (static_cast<int>(voters.size()) <= options.min_support) return keep;
  // 3. Every match is then judged against the voters, with the position check: a voter needs
  //    `min_support`, any other match (a failed anchor is out) `min_candidate_support`.
  std::vector<bool> is_voter(n, false);
  for (int v : voters) is_voter[pool[v]] = true;
  for (size_t k = 0; k < n; ++k) {
    if (!plausible[k] || (tentative[k].anchor && !is_voter[k])) continue;
    keep[k] = consensus.support(k, voters, true) >=
              (is_voter[k] ? options.min_support : options.min_candidate_support);
  }
  return keep;
}

}  // namespace hybrid_vo
