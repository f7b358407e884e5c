#include "hybrid_vo/features/segment_flow.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace hybrid_vo {
namespace {

using Vec2 = Eigen::Vector2f;

// Bilinear intensity; (x, y) within [0, cols - 1] x [0, rows - 1] (profile() checks).
inline float bilinear(const cv::Mat& image, float x, float y) {
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
  const uchar* r0 = image.ptr<uchar>(y0) + x0;
  const uchar* r1 = r0 + image.step[0];
  return (1.0f - ay) * ((1.0f - ax) * r0[0] + ax * r0[1]) + ay * ((1.0f - ax) * r1[0] + ax * r1[1]);
}

bool inside(const cv::Mat& image, const Vec2& p) {
  return p.x() >= 0.0f && p.y() >= 0.0f && p.x() <= image.cols - 1.0f &&
         p.y() <= image.rows - 1.0f;
}

// The profile across an edge: the image at c + (first + j) n for j < count, the border
// replicated beyond the image (a segment along the border keeps its profile there).
void profile(const cv::Mat& image, const Vec2& c, const Vec2& n, float first, int count,
             float* out) {
  const float x_max = image.cols - 1.0f, y_max = image.rows - 1.0f;
  for (int j = 0; j < count; ++j) {
    const Vec2 p = c + (first + static_cast<float>(j)) * n;
    out[j] = bilinear(image, std::clamp(p.x(), 0.0f, x_max), std::clamp(p.y(), 0.0f, y_max));
  }
}

// A profile made zero-mean and of unit norm; returns its norm before (0 when flat: less than a
// grey level over the whole profile, no edge to follow).
float normalise(const float* values, int count, float* out) {
  float mean = 0.0f;
  for (int k = 0; k < count; ++k) mean += values[k];
  mean /= static_cast<float>(count);
  float norm = 0.0f;
  for (int k = 0; k < count; ++k) {
    out[k] = values[k] - mean;
    norm += out[k] * out[k];
  }
  if (!(norm > 1.0f)) return 0.0f;
  const float root = std::sqrt(norm), scale = 1.0f / root;
  for (int k = 0; k < count; ++k) out[k] *= scale;
  return root;
}

// The normalised correlations of a normalised template (count values) with `window` at the
// offsets 0 .. offsets - 1 (at most kMaxOffsets: track_segments_by_flow takes no search_px
// beyond 40, 81 offsets). The offsets are the inner loop, so that it
// vectorises; each offset's sums still run over k in order, as one offset's loop would.
constexpr int kMaxOffsets = 96;
void correlations(const float* normalised, const float* window, int count, int offsets,
                  float* out) {
  float sum[kMaxOffsets] = {}, square[kMaxOffsets] = {}, dot[kMaxOffsets] = {};
  for (int k = 0; k < count; ++k) {
    const float* shifted = window + k;
    for (int d = 0; d < offsets; ++d) {
      sum[d] += shifted[d];
      square[d] += shifted[d] * shifted[d];
      dot[d] += normalised[k] * shifted[d];
    }
  }
  for (int d = 0; d < offsets; ++d) {
    const float variance = square[d] - sum[d] * sum[d] / static_cast<float>(count);
    out[d] = variance > 1e-3f ? dot[d] / std::sqrt(variance) : 0.0f;
  }
}

// An image point in level `level`'s pixels (pyrDown maps x to (x + 0.5) / 2 - 0.5).
Vec2 at_level(const Vec2& p, int level) {
  const float s = 1.0f / static_cast<float>(1 << level);
  return Vec2((p.x() + 0.5f) * s - 0.5f, (p.y() + 0.5f) * s - 0.5f);
}

// One sample's searches along the predicted normal n from its predicted place q (full
// resolution pixels), by the profile taken at s across the old normal m.
struct SampleSearch {
  const std::vector<cv::Mat>& from;
  const std::vector<cv::Mat>& to;
  const SegmentFlowOptions& options;

  // The correlations at offsets -range..range (pixels of `level`) around q; false when the
  // template is flat (no edge to follow).
  bool scores(const Vec2& s, const Vec2& m, const Vec2& q, const Vec2& n, int level, int range,
              float* out) const {
    const int h = options.profile_half_px, width = 2 * h + 1;
    float tmpl[64], normalised[64], window[160];
    profile(from[level], at_level(s, level), m, -h, width, tmpl);
    if (!(normalise(tmpl, width, normalised) > 0.0f)) return false;
    profile(to[level], at_level(q, level), n, -h - range, width + 2 * range, window);
    correlations(normalised, window, width, 2 * range + 1, out);
    return true;
  }

  // From offset `o` (pixels of level `start`, where the segment's coarse search put the sample)
  // down the finer levels, +-3 pixels at the first and +-2 at the next (at level 0 too when it
  // starts there), to the edge at full resolution; false when not found.
  bool refine(const Vec2& s, const Vec2& m, const Vec2& q, const Vec2& n, int start, float o,
              float* offset) const {
    const int h = options.profile_half_px, width = 2 * h + 1;
    float tmpl[64], normalised[64], window[160], scores[8];
    for (int level = std::max(0, start - 1); level >= 0; --level) {
      if (level < start) o *= 2.0f;
      // One more pixel below the coarse level, which halves its pixel and its error doubles.
      const int range = level == start - 1 ? 3 : 2;
      profile(from[level], at_level(s, level), m, -h, width, tmpl);
      const float contrast = normalise(tmpl, width, normalised);
      if (!(contrast > 0.0f)) return false;
      // The window spans one more pixel each side than the offsets searched (the gradient
      // peak's).
      const int count = width + 2 * range + 2;
      profile(to[level], at_level(q, level), n, o - h - range - 1, count, window);
      correlations(normalised, window + 1, width, 2 * range + 1, scores);
      int best = 0;
      for (int d = 0; d <= 2 * range; ++d)
        if (scores[d] > scores[best]) best = d;
      // The best within the search: one at its end would lie beyond it.
      if (best == 0 || best == 2 * range) return false;
      o += static_cast<float>(best - range);
      if (level > 0) continue;
      // Full resolution: as alike as the template, of a like contrast (the correlation alone
      // takes a faint edge for the strong one followed), then the edge itself: the extreme of
      // the derivative across it, of the template's sign, within a pixel of where the
      // template's centre landed, to a fraction of a pixel by a parabola. Each frame measures
      // the edge afresh, as a detector would, instead of carrying the last frame's error on.
      if (scores[best] < options.min_correlation) return false;
      float centred[64];
      const float found_contrast = normalise(window + 1 + best, width, centred);
      if (!(found_contrast * options.max_contrast_ratio >= contrast &&
            found_contrast <= options.max_contrast_ratio * contrast))
        return false;
      const float polarity = tmpl[h + 1] - tmpl[h - 1] >= 0.0f ? 1.0f : -1.0f;
      const int c = best + 1 + h;
      const auto derivative = [&](int j) { return polarity * (window[j + 1] - window[j - 1]); };
      int peak = c;
      for (int j = c - 1; j <= c + 1; ++j)
        if (derivative(j) > derivative(peak)) peak = j;
      const float left = derivative(peak - 1), top = derivative(peak),
                  right = derivative(peak + 1);
      if (!(top > 0.0f) || left > top || right > top) return false;
      const float curvature = left - 2.0f * top + right;
      const float fraction = curvature < 0.0f ? 0.5f * (left - right) / curvature : 0.0f;
      *offset = o + static_cast<float>(peak - c) + std::clamp(fraction, -0.5f, 0.5f);
      return true;
    }
    return false;
  }
};

// The segment's coarse search: the offset across it at its middle and the change of that offset
// from end to end (its turn) that the samples' correlations agree on best, or false when none
// is clear. Samples alone are often ambiguous (a panel's seams, tiles: parallel edges of the
// same contrast a few pixels apart), a whole segment seldom.
struct CoarseFit {
  int offset = 0;     // index into the scores (0 .. 2 range) at the segment's middle
  double turn = 0.0;  // offset at the end minus that at the start (level pixels)
  int at(float where) const { return offset + static_cast<int>(std::lround(turn * (where - 0.5))); }
};
// `scores` holds each sample's 2 range + 1 correlations in a row.
bool coarse_fit(const std::vector<float>& scores, const std::vector<float>& where, int range,
                int max_turn, const SegmentFlowOptions& o, CoarseFit* fit) {
  const int offsets = 2 * range + 1, usable = static_cast<int>(where.size());
  // Per offset the best turn's mean correlation over the samples (half a pixel steps; a sample
  // the turn takes beyond the search counts as uncorrelated, lest turns gain by dropping the
  // samples that disagree).
  std::vector<float> total(offsets, -2.0f);
  std::vector<double> turn_of(offsets, 0.0);
  std::vector<float> sum(offsets);
  for (int half_steps = -2 * max_turn; half_steps <= 2 * max_turn; ++half_steps) {
    CoarseFit turned;
    turned.turn = 0.5 * half_steps;
    // Per offset d the sum over the samples i of scores[i][d + shift], in the order of i; the
    // offsets are the inner loop, over those whose d + shift lies inside the search.
    std::fill(sum.begin(), sum.end(), 0.0f);
    for (int i = 0; i < usable; ++i) {
      const int shift = turned.at(where[i]);
      const float* own = scores.data() + static_cast<size_t>(i) * offsets;
      for (int d = std::max(0, -shift); d < std::min(offsets, offsets - shift); ++d)
        sum[d] += own[d + shift];
    }
    for (int d = 0; d < offsets; ++d) {
      if (sum[d] / usable > total[d]) {
        total[d] = sum[d] / usable;
        turn_of[d] = turned.turn;
      }
    }
  }
  const int best = static_cast<int>(std::max_element(total.begin(), total.end()) - total.begin());
  // Another peak nearly as good (inside the search: one at its end may be the best's slope).
  const float rival = static_cast<float>(o.rival_ratio * (1.0 - total[best]) + o.rival_margin);
  for (int d = 1; d + 1 < offsets; ++d) {
    if (std::abs(d - best) < 2) continue;
    if (total[d] >= total[d - 1] && total[d] >= total[d + 1] && 1.0f - total[d] <= rival)
      return false;
  }
  fit->offset = best;
  fit->turn = turn_of[best];
  return true;
}

// A total-least-squares line through `points`: a point on it and its unit direction.
void fit_line(const std::vector<Eigen::Vector2d>& points, Eigen::Vector2d* centre,
              Eigen::Vector2d* direction) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& p : points) scatter += (p - mean) * (p - mean).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(scatter);
  *centre = mean;
  *direction = eig.eigenvectors().col(1);
}

SegmentFlow track_one(const std::vector<cv::Mat>& from, const std::vector<cv::Mat>& to,
                      const LineSegment& segment, const LineSegment& predicted, float reach,
                      int levels, const SegmentFlowOptions& o) {
  SegmentFlow flow;
  const double length = segment.length(), predicted_length = predicted.length();
  if (!(length > 2.0 * o.end_inset_px) || !(predicted_length > 2.0 * o.end_inset_px) ||
      !all_finite(segment.p1) || !all_finite(segment.p2) || !all_finite(predicted.p1) ||
      !all_finite(predicted.p2))
    return flow;
  const int samples = std::clamp(
      static_cast<int>(std::lround((length - 2.0 * o.end_inset_px) / o.sample_spacing_px)) + 1,
      std::max(2, o.min_samples), std::max(2, o.max_samples));
  const Vec2 a1 = segment.p1.cast<float>(), a2 = segment.p2.cast<float>();
  const Vec2 b1 = predicted.p1.cast<float>(), b2 = predicted.p2.cast<float>();
  const Vec2 v = (a2 - a1).normalized(), m(-v.y(), v.x());
  const Vec2 u = (b2 - b1).normalized(), n(-u.y(), u.x());
  const SampleSearch search{from, to, o};
  const double inset_a = o.end_inset_px / length, inset_b = o.end_inset_px / predicted_length;
  // The coarse search starts at the finest level whose search_px pixels cover the reach: a
  // wider search than the prediction needs meets more parallel edges of the same contrast.
  int start = 0;
  while (start < levels && reach > static_cast<float>(o.search_px << start)) ++start;
  const int range =
      std::clamp(static_cast<int>(std::ceil(reach / (1 << start))), 2, o.search_px);
  const float scale = 1.0f / static_cast<float>(1 << start);
  const int max_turn = std::min(
      range, static_cast<int>(std::ceil(predicted_length * scale *
                                        std::tan(o.coarse_turn_deg * M_PI / 180.0))));
  const int offsets = 2 * range + 1;
  std::vector<Vec2> old_at, new_at;
  std::vector<float> where, scores;  // scores: a row of offsets per sample
  old_at.reserve(samples);
  new_at.reserve(samples);
  where.reserve(samples);
  scores.resize(static_cast<size_t>(samples) * offsets);
  for (int i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / (samples - 1);
    const float ta = static_cast<float>(inset_a + t * (1.0 - 2.0 * inset_a));
    const float tb = static_cast<float>(inset_b + t * (1.0 - 2.0 * inset_b));
    const Vec2 s = a1 + ta * (a2 - a1), q = b1 + tb * (b2 - b1);
    if (!inside(from[0], s) || !inside(to[0], q)) continue;
    ++flow.samples;
    float* sample_scores = scores.data() + old_at.size() * offsets;
    if (!search.scores(s, m, q, n, start, range, sample_scores)) continue;
    old_at.push_back(s);
    new_at.push_back(q);
    where.push_back(static_cast<float>(t));
  }
  scores.resize(old_at.size() * offsets);
  CoarseFit coarse;
  if (static_cast<int>(old_at.size()) < std::max(2, o.min_inliers) ||
      !coarse_fit(scores, where, range, max_turn, o, &coarse))
    return flow;
  std::vector<Eigen::Vector2d> found;
  found.reserve(old_at.size());
  for (size_t i = 0; i < old_at.size(); ++i) {
    // The sample's own peak within a pixel of the segment's fit (the turn is coarse).
    const float* own = scores.data() + i * offsets;
    int k = std::clamp(coarse.at(where[i]), 0, 2 * range);
    const int fitted = k;
    for (int j = std::max(0, fitted - 1); j <= std::min(2 * range, fitted + 1); ++j)
      if (own[j] > own[k]) k = j;
    const float at = static_cast<float>(k - range);
    float offset = 0.0f;
    if (search.refine(old_at[i], m, new_at[i], n, start, at, &offset))
      found.push_back((new_at[i] + offset * n).cast<double>());
  }
  const int min_inliers = std::max(2, o.min_inliers);
  if (static_cast<int>(found.size()) < min_inliers) return flow;

  // The line through the samples that agree: refitted without those off it.
  Eigen::Vector2d centre, direction;
  std::vector<char> inlier(found.size(), 1);
  std::vector<Eigen::Vector2d> kept = found;
  std::vector<double> residuals(found.size()), sorted;
  for (int round = 0; round < 3; ++round) {
    fit_line(kept, &centre, &direction);
    const Eigen::Vector2d normal(-direction.y(), direction.x());
    for (size_t k = 0; k < found.size(); ++k) residuals[k] = std::abs(normal.dot(found[k] - centre));
    // Within max_residual_px, and within three robust sigmas (the median's) of a line whose
    // samples agree better: a sample near a corner sees the other edge in its profile.
    sorted.assign(residuals.begin(), residuals.end());
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double threshold =
        std::min(o.max_residual_px, std::max(o.min_residual_px, 3.0 * 1.4826 * sorted[sorted.size() / 2]));
    kept.clear();
    for (size_t k = 0; k < found.size(); ++k) {
      inlier[k] = residuals[k] <= threshold;
      if (inlier[k]) kept.push_back(found[k]);
    }
    if (static_cast<int>(kept.size()) < min_inliers) return flow;
  }
  fit_line(kept, &centre, &direction);
  const Eigen::Vector2d normal(-direction.y(), direction.x());
  flow.inliers = static_cast<int>(kept.size());
  if (flow.inliers < o.min_inlier_share * flow.samples) return flow;
  const Eigen::Vector2d along = (predicted.p2 - predicted.p1) / predicted_length;
  if (direction.dot(along) < 0.0) direction = -direction;
  if (direction.dot(along) < std::cos(o.max_turn_deg * M_PI / 180.0)) return flow;
  double square = 0.0;
  for (const Eigen::Vector2d& p : kept) square += std::pow(normal.dot(p - centre), 2);
  flow.rms_px = std::sqrt(square / flow.inliers);

  // The ends, measured as a detector finds them: from the outermost samples on the line,
  // outward along it while the edge is there (its step across the line at least half the
  // samples' median, two pixels in a row missing it end it), up to end_search_px beyond the
  // predicted ends. Along the edge the flow says nothing, so the prediction alone would let the
  // ends drift, and a sample's profile near a corner sees the other edge.
  const cv::Mat& image = to[0];
  const Eigen::Vector2d across(-direction.y(), direction.x());
  const auto step_across = [&](const Eigen::Vector2d& p, double* step) {
    const Eigen::Vector2d a = p + across, b = p - across;
    if (!inside(image, a.cast<float>()) || !inside(image, b.cast<float>())) return false;
    *step = bilinear(image, static_cast<float>(a.x()), static_cast<float>(a.y())) -
            bilinear(image, static_cast<float>(b.x()), static_cast<float>(b.y()));
    return true;
  };
  std::vector<double> steps, positions;
  steps.reserve(kept.size());
  positions.reserve(kept.size());
  for (const Eigen::Vector2d& p : kept) {
    double step = 0.0;
    if (step_across(p, &step)) steps.push_back(step);
    positions.push_back(direction.dot(p - centre));
  }
  if (steps.empty()) return flow;
  std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
  const double typical = steps[steps.size() / 2];
  const auto walk = [&](double from, double limit, double sign) {
    double end = from;
    int missed = 0;
    for (double t = from + sign; sign * (limit - t) >= 0.0 && missed < 2; t += sign) {
      double step = 0.0;
      const bool edge = step_across(centre + t * direction, &step) && step * typical > 0.0 &&
                        std::abs(step) >= 0.5 * std::abs(typical);
      missed = edge ? 0 : missed + 1;
      if (edge) end = t;
    }
    return end;
  };
  const double lo = *std::min_element(positions.begin(), positions.end());
  const double hi = *std::max_element(positions.begin(), positions.end());
  const double predicted_lo = direction.dot(predicted.p1 - centre) - o.end_search_px;
  const double predicted_hi = direction.dot(predicted.p2 - centre) + o.end_search_px;
  flow.segment = LineSegment(centre + walk(lo, predicted_lo, -1.0) * direction,
                             centre + walk(hi, predicted_hi, 1.0) * direction);
  flow.found = flow.segment.length() >= o.min_length_px;
  return flow;
}

}  // namespace

std::vector<cv::Mat> pyramid_images(const std::vector<cv::Mat>& pyramid) {
  std::vector<cv::Mat> levels;
  for (const cv::Mat& level : pyramid)
    if (level.type() == CV_8UC1) levels.push_back(level);
  return levels;
}

std::vector<SegmentFlow> track_segments_by_flow(const std::vector<cv::Mat>& from,
                                                const std::vector<cv::Mat>& to,
                                                const std::vector<LineSegment>& segments,
                                                const std::vector<LineSegment>& predicted,
                                                const std::vector<double>& reach_px,
                                                const SegmentFlowOptions& options,
                                                const ParallelFor& parallel) {
  const int n = static_cast<int>(segments.size());
  std::vector<SegmentFlow> flows(n);
  if (from.empty() || to.empty() || from[0].size() != to[0].size() || from[0].cols < 2 ||
      from[0].rows < 2 || options.profile_half_px < 2 || options.profile_half_px > 30 ||
      options.search_px > 40)
    return flows;
  // The coarse levels both pyramids have, of at least the search's size.
  int levels = 0;
  while (levels < options.levels && levels + 1 < static_cast<int>(std::min(from.size(), to.size())) &&
         from[levels + 1].cols >= 8 && from[levels + 1].rows >= 8)
    ++levels;
  const bool predictions = predicted.size() == segments.size();
  const bool reaches = reach_px.size() == segments.size();
  const double widest = static_cast<double>(options.search_px << levels);
  constexpr int kChunk = 8;
  run_indices(parallel, (n + kChunk - 1) / kChunk, [&](int chunk) {
    for (int i = chunk * kChunk; i < std::min(n, (chunk + 1) * kChunk); ++i) {
      const double reach = reaches && reach_px[i] >= 0.0 ? std::min(reach_px[i], widest) : widest;
      flows[i] = track_one(from, to, segments[i], predictions ? predicted[i] : segments[i],
                           static_cast<float>(reach), levels, options);
    }
  });
  return flows;
}

}  // namespace hybrid_vo
