#include "hybrid_vo/features/klt_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "hybrid_vo/features/gray_image.h"
#include "hybrid_vo/features/lucas_kanade.h"

namespace hybrid_vo {
namespace {

constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();

bool known(const cv::Point2f& motion) { return std::isfinite(motion.x); }

float median_of(std::vector<float>* v) {
  std::nth_element(v->begin(), v->begin() + v->size() / 2, v->end());
  return (*v)[v->size() / 2];
}

// The tracker's searches: lucas_kanade_search with its own window, levels and iterations.
void search(const std::vector<cv::Mat>& from_pyramid, const std::vector<cv::Mat>& to_pyramid,
            const std::vector<cv::Point2f>& from, const std::vector<int>& which, int levels,
            const KltTrackerOptions& options, std::vector<cv::Point2f>* to,
            std::vector<char>* found) {
  lucas_kanade_search(from_pyramid, to_pyramid, from, which, levels, options.pyramid_levels,
                      cv::Size(options.window_px, options.window_px), options.max_iterations, to,
                      found);
}

// The structure tensor of `gray` over a window x window square at p, as RMS gradients (Sobel /
// 8: grey levels per pixel) along its weaker and its stronger direction; zeros where the window
// leaves the image.
struct CornerStrength {
  double weaker = 0.0, stronger = 0.0;
};

CornerStrength corner_strength(const cv::Mat& gray, const cv::Point2f& p, int window) {
  const int r = window / 2 + 1;  // one more pixel for the derivative's support
  const cv::Rect box(static_cast<int>(std::lround(p.x)) - r, static_cast<int>(std::lround(p.y)) - r,
                     2 * r + 1, 2 * r + 1);
  if ((box & cv::Rect(0, 0, gray.cols, gray.rows)) != box) return {};
  // The 3x3 Sobel responses inside the box, written out: cv::Sobel on a box this small costs
  // ten times the arithmetic in setting up (a quarter of a 30 Hz room's front end), and gives
  // these same values (integers times 1/8). The products are summed as integers: each is a
  // multiple of 1/64 and every partial sum stays far below 2^53 / 64, so the double sums were
  // exact and are the integer sums times 1/64, bit for bit.
  int64_t sum_xx = 0, sum_xy = 0, sum_yy = 0;
  for (int y = box.y + 1; y < box.y + box.height - 1; ++y) {
    const uchar* above = gray.ptr<uchar>(y - 1);
    const uchar* row = gray.ptr<uchar>(y);
    const uchar* below = gray.ptr<uchar>(y + 1);
    // A row's sums fit an int: each product is at most 1020^2, and window_px at most 401.
    int row_xx = 0, row_xy = 0, row_yy = 0;
    for (int x = box.x + 1; x < box.x + box.width - 1; ++x) {
      const int gx = (above[x + 1] + 2 * row[x + 1] + below[x + 1]) -
                     (above[x - 1] + 2 * row[x - 1] + below[x - 1]);
      const int gy = (below[x - 1] + 2 * below[x] + below[x + 1]) -
                     (above[x - 1] + 2 * above[x] + above[x + 1]);
      row_xx += gx * gx;
      row_xy += gx * gy;
      row_yy += gy * gy;
    }
    sum_xx += row_xx;
    sum_xy += row_xy;
    sum_yy += row_yy;
  }
  const double xx = sum_xx / 64.0, xy = sum_xy / 64.0, yy = sum_yy / 64.0;
  const double n = (box.width - 2.0) * (box.height - 2.0);
  const double half_trace = 0.5 * (xx + yy), det = xx * yy - xy * xy;
  const double root = std::sqrt(std::max(0.0, half_trace * half_trace - det));
  return {std::sqrt(std::max(0.0, half_trace - root) / n),
          std::sqrt(std::max(0.0, half_trace + root) / n)};
}

}  // namespace

KltTracker::KltTracker(const KltTrackerOptions& options, int max_features)
    : options_(options), max_features_(max_features) {}

void KltTracker::set_work(int max_features, double redetect_min_missing, bool redetect_alternate) {
  max_features_ = std::max(1, max_features);
  options_.redetect_min_missing = std::clamp(redetect_min_missing, 0.0, 1.0);
  options_.redetect_alternate = redetect_alternate;
}

void KltTracker::reset() {
  previous_.clear();
  previous_raw_.release();
  size_ = cv::Size();
  points_.clear();
  motion_.clear();
  ids_.clear();
  age_.clear();
  stamp_ = motion_dt_ = kNoStamp;
  detections_ = 0;
  refilled_to_ = 0;
  cell_tracks_.clear();
}

int KltTracker::num_tracks() const { return static_cast<int>(points_.size()); }

int KltTrackStats::median_lifetime() const {
  int64_t seen = 0;
  for (size_t k = 0; k < lifetimes.size(); ++k) {
    seen += lifetimes[k];
    if (lost > 0 && 2 * seen >= lost) return static_cast<int>(k);
  }
  return lost > 0 ? static_cast<int>(lifetimes.size()) : 0;
}

double KltTracker::motion_scale(double stamp) const {
  const double dt = stamp - stamp_;
  // NaN (no stamps) and non-increasing stamps fail both tests and keep the plain prediction.
  if (!(dt > 0.0) || !(motion_dt_ > 0.0)) return 1.0;
  return std::min(kMaxMotionScale, dt / motion_dt_);
}

std::vector<char> KltTracker::predict(double motion_scale, std::vector<cv::Point2f>* next) const {
  const size_t n = points_.size();
  next->assign(points_.begin(), points_.end());
  std::vector<char> predicted(n, 0);
  if (!options_.predict_motion) return predicted;
  // New features move like the median track of their grid cell (of the image when it has none).
  const int cols = std::max(1, options_.grid_cols), rows = std::max(1, options_.grid_rows);
  const int cell_w = std::max(1, (size_.width + cols - 1) / cols);
  const int cell_h = std::max(1, (size_.height + rows - 1) / rows);
  const int image_cell = cols * rows;
  auto cell_of = [&](const cv::Point2f& p) {
    const int cx = std::min(cols - 1, std::max(0, static_cast<int>(p.x) / cell_w));
    const int cy = std::min(rows - 1, std::max(0, static_cast<int>(p.y) / cell_h));
    return cy * cols + cx;
  };
  std::vector<std::vector<float>> dx(image_cell + 1), dy(image_cell + 1);
  for (size_t i = 0; i < n; ++i) {
    if (!known(motion_[i])) continue;
    for (const int c : {cell_of(points_[i]), image_cell}) {
      dx[c].push_back(motion_[i].x);
      dy[c].push_back(motion_[i].y);
    }
  }
  if (dx[image_cell].empty()) return predicted;  // no motion seen yet
  std::vector<cv::Point2f> cell_motion(image_cell + 1);
  for (int c = image_cell; c >= 0; --c) {
    cell_motion[c] = dx[c].empty() ? cell_motion[image_cell]
                                   : cv::Point2f(median_of(&dx[c]), median_of(&dy[c]));
  }
  for (size_t i = 0; i < n; ++i) {
    (*next)[i] +=
        motion_scale * (known(motion_[i]) ? motion_[i] : cell_motion[cell_of(points_[i])]);
    predicted[i] = 1;
  }
  return predicted;
}

std::vector<PointMatch> KltTracker::track(const GrayImage& image, std::vector<int64_t>* ids,
                                          double stamp, const ParallelFor& parallel) {
  std::vector<PointMatch> matches = track_existing(image, ids, stamp, parallel);
  detect_new(parallel);
  return matches;
}

// One frame's searches, a slot per feature of the previous frame.
struct KltTracker::Search {
  std::vector<cv::Point2f> predicted_at;  // where the search starts
  std::vector<char> predicted;            // whether it has a prediction (else: the long way)
  int short_levels = 0;
  std::vector<cv::Point2f> next, back;    // found in this frame, and back in the previous one
  std::vector<char> found, back_found, long_way;
};

void KltTracker::search_range(const std::vector<cv::Mat>& pyramid, int begin, int end,
                              Search* s) const {
  // Forward: short searches from the predictions; what they lose, and what has no prediction,
  // the long way.
  std::vector<int> short_search, long_search;
  const cv::Rect2f bounds(0.0f, 0.0f, pyramid[0].cols - 1.0f, pyramid[0].rows - 1.0f);
  for (int i = begin; i < end; ++i) {
    if (s->predicted[i] && options_.drop_leaving && !bounds.contains(s->predicted_at[i]))
      continue;  // lost without a search (found stays 0)
    (s->predicted[i] ? short_search : long_search).push_back(i);
  }
  search(previous_, pyramid, points_, short_search, s->short_levels, options_, &s->next,
         &s->found);
  for (int i : short_search)
    if (!s->found[i]) long_search.push_back(i);
  std::sort(long_search.begin(), long_search.end());
  for (int i : long_search) s->long_way[i] = 1;
  search(previous_, pyramid, points_, long_search, -1, options_, &s->next, &s->found);

  // Forward-backward consistency (Kalal et al. 2010) rejects drifting and occluded tracks. The
  // backward search mirrors the forward one: a feature found the short way is searched for
  // back from its position minus the predicted motion, over the same levels. A feature found
  // outside the image is lost whatever the way back says, so it is not searched for.
  std::vector<int> back_short, back_long;
  for (int i = begin; i < end; ++i) {
    if (!s->found[i] || !bounds.contains(s->next[i])) continue;
    if (s->long_way[i]) {
      back_long.push_back(i);
    } else {
      back_short.push_back(i);
      s->back[i] = s->next[i] - (s->predicted_at[i] - points_[i]);
    }
  }
  search(pyramid, previous_, s->next, back_short, s->short_levels, options_, &s->back,
         &s->back_found);
  search(pyramid, previous_, s->next, back_long, -1, options_, &s->back, &s->back_found);
}

std::vector<cv::Mat> KltTracker::build_pyramid(const GrayImage& image) const {
  // Each frame's pyramid (with the derivatives LK needs) is built once: it serves the forward
  // search into this frame, the backward search out of it, and the next frame's forward search.
  std::vector<cv::Mat> pyramid;
  if (image.empty()) return pyramid;
  const cv::Size window(options_.window_px, options_.window_px);
  cv::buildOpticalFlowPyramid(flat_field(image.mat(), gain_map_), pyramid, window,
                              options_.pyramid_levels, true);
  return pyramid;
}

std::vector<PointMatch> KltTracker::track_existing(const GrayImage& image,
                                                   std::vector<int64_t>* ids, double stamp,
                                                   const ParallelFor& parallel) {
  return track_pyramid(build_pyramid(image), image, ids, stamp, parallel);
}

std::vector<PointMatch> KltTracker::track_pyramid(std::vector<cv::Mat> pyramid,
                                                  const GrayImage& image,
                                                  std::vector<int64_t>* ids, double stamp,
                                                  const ParallelFor& parallel) {
  std::vector<PointMatch> matches;
  if (ids) ids->clear();
  if (pyramid.empty()) return matches;
  const cv::Size size = pyramid[0].size();
  if (!previous_.empty() && size_ != size) {
    reset();
    vignetting_.reset();
    gain_map_.release();
  }
  // The image as it came, for its brightness and the corners.
  const cv::Mat raw = image.mat().size() == size ? image.mat() : pyramid[0];

  if (!previous_.empty() && !points_.empty()) {
    const int n = static_cast<int>(points_.size());
    Search s;
    s.predicted = predict(motion_scale(stamp), &s.predicted_at);
    s.short_levels =
        std::max(0, std::min(options_.predicted_pyramid_levels, options_.pyramid_levels));
    s.next = s.predicted_at;
    s.back.resize(n);
    s.found.assign(n, 0);
    s.back_found.assign(n, 0);
    s.long_way.assign(n, 0);
    // Chunks of features, small enough for two threads to share the work evenly.
    constexpr int kChunk = 32;
    run_indices(parallel, (n + kChunk - 1) / kChunk, [&](int chunk) {
      search_range(pyramid, chunk * kChunk, std::min(n, (chunk + 1) * kChunk), &s);
    });

    std::vector<cv::Point2f> kept, kept_motion;
    std::vector<int64_t> kept_ids;
    std::vector<int> kept_age;
    const double max_fb_sq = options_.max_forward_backward_px * options_.max_forward_backward_px;
    ++stats_.frames;
    stats_.searched += n;
    if (stats_.lifetimes.empty()) stats_.lifetimes.assign(64, 0);
    const auto lose = [&](int age) {
      ++stats_.lost;
      stats_.lost_at_first += age == 0;
      stats_.lifetime_sum += age;
      ++stats_.lifetimes[std::min<size_t>(age, stats_.lifetimes.size() - 1)];
    };
    for (int i = 0; i < n; ++i) {
      const int age = i < static_cast<int>(age_.size()) ? age_[i] : 0;
      // Found outside the image: never searched back (search_range).
      const cv::Point2f d = s.back[i] - points_[i];
      if (!s.found[i] || !s.back_found[i] || d.dot(d) > max_fb_sq) {
        lose(age);
        continue;
      }
      PointMatch m;
      m.x1 = Eigen::Vector2d(points_[i].x, points_[i].y);
      m.x2 = Eigen::Vector2d(s.next[i].x, s.next[i].y);
      matches.push_back(m);
      if (ids) ids->push_back(ids_[i]);
      kept.push_back(s.next[i]);
      kept_motion.push_back(s.next[i] - points_[i]);
      kept_ids.push_back(ids_[i]);
      kept_age.push_back(age + 1);
    }
    if (options_.correct_vignetting) update_vignetting(raw, matches);
    points_ = std::move(kept);
    motion_ = std::move(kept_motion);
    ids_ = std::move(kept_ids);
    age_ = std::move(kept_age);
  }
  // The motions just measured span this time step (NaN without stamps).
  motion_dt_ = stamp - stamp_;
  stamp_ = stamp;
  size_ = size;
  previous_ = std::move(pyramid);
  // A copy: the caller may reuse its image's buffer for the next frame.
  if (options_.correct_vignetting) previous_raw_ = raw.clone();
  else previous_raw_.release();
  return matches;
}

void KltTracker::update_vignetting(const cv::Mat& raw, const std::vector<PointMatch>& matches) {
  if (previous_raw_.empty() || previous_raw_.size() != raw.size()) return;
  std::vector<cv::Point2f> from, to;
  from.reserve(matches.size());
  to.reserve(matches.size());
  for (const PointMatch& m : matches) {
    from.emplace_back(static_cast<float>(m.x1.x()), static_cast<float>(m.x1.y()));
    to.emplace_back(static_cast<float>(m.x2.x()), static_cast<float>(m.x2.y()));
  }
  vignetting_.add_pair(previous_raw_, raw, from, to);
  if (!vignetting_.active()) {
    gain_map_.release();
    return;
  }
  // A new map (never written in place: a stereo job may still read the last one) only when the
  // corners' gain moved by half a percent.
  if (gain_map_.size() != raw.size() ||
      std::abs(vignetting_.corner_gain() - map_corner_) > 0.005) {
    gain_map_ = vignetting_gain_map(raw.size(), vignetting_.a(), vignetting_.b());
    map_corner_ = vignetting_.corner_gain();
  }
}

const cv::Mat& KltTracker::detection_image() const {
  return previous_raw_.empty() ? previous_[0] : previous_raw_;
}

void KltTracker::detect_new(const ParallelFor& parallel) {
  KltDetection detection = plan_detection();
  run_indices(parallel, detection.cells(), [&](int cell) { detect_cell(&detection, cell); });
  add_detections(detection);
}

KltDetection KltTracker::plan_detection() const {
  KltDetection d;
  if (previous_.empty()) {
    d.cols = d.rows = 0;
    return d;
  }
  // Level 0 of the pyramid is the image (inside the border the pyramid adds).
  const cv::Mat& gray = detection_image();
  // Re-detection by buckets keeps features spread over the image (a cluster of tracks on one
  // textured object makes a poorly conditioned relative pose). With fewer features than cells
  // the grid gets coarser, so that every cell has a quota of at least one and max_features stays
  // a cap: the features, and so the matches that reach the estimator, never exceed it.
  const int max_features = std::max(1, max_features_);
  int cols = std::max(1, options_.grid_cols), rows = std::max(1, options_.grid_rows);
  while (cols * rows > max_features && (cols > 1 || rows > 1)) {
    if (cols >= rows) --cols;
    else --rows;
  }
  d.cols = cols;
  d.rows = rows;
  const int quota = std::max(1, max_features / d.cells());
  d.cell_w = (gray.cols + cols - 1) / cols;
  d.cell_h = (gray.rows + rows - 1) / rows;
  std::vector<int> count(d.cells(), 0);
  d.mask = cv::Mat(gray.size(), CV_8U, cv::Scalar(255));
  for (const cv::Point2f& p : points_) {
    const int cx = std::min(cols - 1, static_cast<int>(p.x) / d.cell_w);
    const int cy = std::min(rows - 1, static_cast<int>(p.y) / d.cell_h);
    ++count[cy * cols + cx];
    cv::circle(d.mask, p, static_cast<int>(options_.min_distance_px), cv::Scalar(0), cv::FILLED);
  }
  d.wanted.resize(d.cells());
  const int min_missing = static_cast<int>(std::ceil(options_.redetect_min_missing * quota));
  const bool alternate = options_.redetect_alternate && !points_.empty();
  // Enough tracks: no re-detection at all this frame. Enough is measured against what the last
  // re-detection left too: where the image has fewer good corners than max_features (a room's
  // walls), the tracks never reach the cap, and a re-detection every frame would pay to find the
  // same weak corners again.
  const double refill = options_.refill_below;
  const bool enough = !points_.empty() && refill < 1.0 &&
                      (points_.size() >= refill * max_features ||
                       static_cast<double>(points_.size()) >= refill * refilled_to_);
  const bool lost_only = options_.redetect_lost_cells &&
                         static_cast<int>(cell_tracks_.size()) == d.cells();
  for (int c = 0; c < d.cells(); ++c) {
    d.wanted[c] = enough ? 0 : quota - count[c];
    if (lost_only && count[c] >= cell_tracks_[c] && cell_tracks_[c] > 0) d.wanted[c] = 0;
    if (d.wanted[c] < min_missing) d.wanted[c] = 0;
    const int cx = c % cols, cy = c / cols;
    if (alternate && (cx + cy + detections_) % 2 != 0) d.wanted[c] = 0;
  }
  d.corners.resize(d.cells());
  d.strong.resize(d.cells());
  d.strength.resize(d.cells());
  return d;
}

void KltTracker::detect_cell(KltDetection* d, int c) const {
  if (previous_.empty() || c < 0 || c >= d->cells() || d->wanted[c] <= 0) return;
  const cv::Mat& gray = detection_image();
  const int cx = c % d->cols, cy = c / d->cols;
  const cv::Rect cell = cv::Rect(cx * d->cell_w, cy * d->cell_h, d->cell_w, d->cell_h) &
                        cv::Rect(0, 0, gray.cols, gray.rows);
  if (cell.width < 8 || cell.height < 8) return;
  // All the cell may want: add_detections takes fewer when max_features leaves less room, and
  // goodFeaturesToTrack's first k corners are the same whatever the maximum (it admits them
  // strongest first and stops at the maximum).
  // Strongest first: twice the cell's want, so that its stronger corners compete with the other
  // cells' for the image's share.
  std::vector<cv::Point2f>& corners = d->corners[c];
  const int candidates = options_.strongest_first ? 2 * d->wanted[c] : d->wanted[c];
  cv::goodFeaturesToTrack(gray(cell), corners, candidates, options_.quality_level,
                          options_.min_distance_px, d->mask(cell));
  d->strong[c].assign(corners.size(), 1);
  d->strength[c].assign(corners.size(), 0.0f);
  for (size_t k = 0; k < corners.size(); ++k) {
    corners[k] += cv::Point2f(static_cast<float>(cell.x), static_cast<float>(cell.y));
    if (!(options_.min_corner_gradient > 0.0) && !(options_.min_corner_isotropy > 0.0) &&
        !options_.strongest_first)
      continue;
    const CornerStrength strength = corner_strength(gray, corners[k], options_.window_px);
    d->strength[c][k] = static_cast<float>(strength.weaker);
    // Zeros: the window leaves the image (a band meeting the border looks like a corner).
    if (!(strength.stronger > 0.0) || strength.weaker < options_.min_corner_gradient ||
        strength.weaker < options_.min_corner_isotropy * strength.stronger)
      d->strong[c][k] = 0;
  }
}

void KltTracker::add_detections(const KltDetection& d) {
  ++detections_;
  const int max_features = std::max(1, max_features_);
  const auto add = [&](const cv::Point2f& p) {
    points_.push_back(p);
    motion_.push_back(cv::Point2f(kUnknown, kUnknown));
    ids_.push_back(next_id_++);
    age_.push_back(0);
    ++stats_.detected;
  };
  const int cells = std::min(d.cells(), static_cast<int>(d.corners.size()));
  if (options_.strongest_first) {
    // Every cell's candidates, strongest first over the image; each cell up to its want. Two
    // cells' candidates may lie closer than min_distance_px across their border: the later one
    // gives way.
    std::vector<std::pair<float, std::pair<int, int>>> order;
    for (int c = 0; c < cells; ++c)
      for (size_t k = 0; k < d.corners[c].size(); ++k)
        if (d.strong[c][k]) order.push_back({d.strength[c][k], {c, static_cast<int>(k)}});
    std::stable_sort(order.begin(), order.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    std::vector<int> taken(cells, 0);
    const size_t first_new = points_.size();
    const float min_sq = static_cast<float>(options_.min_distance_px * options_.min_distance_px);
    const int weak_room = static_cast<int>(options_.weak_corner_share * max_features);
    for (const auto& [strength, at] : order) {
      if (static_cast<int>(points_.size()) >= max_features) break;
      if (strength < options_.weak_corner_gradient &&
          static_cast<int>(points_.size()) >= weak_room)
        break;
      const auto [c, k] = at;
      if (taken[c] >= d.wanted[c]) continue;
      const cv::Point2f& p = d.corners[c][k];
      bool crowded = false;
      for (size_t j = first_new; j < points_.size() && !crowded; ++j) {
        const cv::Point2f e = points_[j] - p;
        crowded = e.dot(e) < min_sq;
      }
      if (crowded) continue;
      add(p);
      ++taken[c];
    }
  } else {
    for (int c = 0; c < cells; ++c) {
      const int room = max_features - static_cast<int>(points_.size());
      const int take = std::min({room, d.wanted[c], static_cast<int>(d.corners[c].size())});
      for (int k = 0; k < take; ++k)
        if (d.strong[c][k]) add(d.corners[c][k]);
    }
  }
  // Tracks crowding into a few cells can still exceed the cap: keep the oldest (lowest ids).
  if (static_cast<int>(points_.size()) > max_features) {
    std::vector<size_t> order(points_.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return ids_[a] < ids_[b]; });
    order.resize(max_features);
    std::sort(order.begin(), order.end());
    std::vector<cv::Point2f> kept, kept_motion;
    std::vector<int64_t> kept_ids;
    std::vector<int> kept_age;
    for (size_t i : order) {
      kept.push_back(points_[i]);
      kept_motion.push_back(motion_[i]);
      kept_ids.push_back(ids_[i]);
      kept_age.push_back(age_[i]);
    }
    points_ = std::move(kept);
    motion_ = std::move(kept_motion);
    ids_ = std::move(kept_ids);
    age_ = std::move(kept_age);
  }
  for (int c = 0; c < cells; ++c)
    if (d.wanted[c] > 0) {
      refilled_to_ = static_cast<int>(points_.size());
      break;
    }
  cell_tracks_.assign(d.cells(), 0);
  if (d.cells() <= 0) return;
  for (const cv::Point2f& p : points_) {
    const int cx = std::clamp(static_cast<int>(p.x) / std::max(1, d.cell_w), 0, d.cols - 1);
    const int cy = std::clamp(static_cast<int>(p.y) / std::max(1, d.cell_h), 0, d.rows - 1);
    ++cell_tracks_[cy * d.cols + cx];
  }
}

}  // namespace hybrid_vo
