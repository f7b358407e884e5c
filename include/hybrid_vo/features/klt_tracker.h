#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/features/gray_image.h"
#include "hybrid_vo/features/vignetting.h"
#include "hybrid_vo/features/worker_thread.h"
#include "hybrid_vo/geometry/option_fields.h"

namespace hybrid_vo {

struct KltTrackerOptions {
  int grid_cols = 8, grid_rows = 6;  // bucketing: re-detection fills empty cells first
  double min_distance_px = 10.0;     // between tracked features
  double quality_level = 0.01;       // of cv::goodFeaturesToTrack
  // goodFeaturesToTrack's quality is relative to the strongest corner of a cell, so a cell of
  // white wall still yields "corners" of faint fabric texture, whose tracks mislead the pose
  // (TUM fr3 structure_notexture: 15 deg of orientation error after 126 frames, 4 deg at 1.5).
  // A corner is kept only when the weaker eigenvalue of its structure tensor over the tracking
  // window, as an RMS gradient, reaches this many grey levels per pixel (those panels: 0.4-0.9;
  // KITTI's corners: 1.4 and up at the 10th percentile). 0 keeps every corner: the rendered
  // corridor's low-contrast texture needs its weak corners (drift 1.7 -> 25 deg/100 m at 1.5).
  double min_corner_gradient = 0.0;
  // A point on a straight edge slides along it: KLT follows it across the edge only, and the
  // pose takes the slide (TartanAir's white panels: 20 pairs 0.4-0.7 degrees off each, claiming
  // 0.02). goodFeaturesToTrack admits such points where a cell's strongest corner is far
  // stronger. A corner is kept only when its weaker RMS gradient is at least this share of its
  // stronger one (an edge: near 0; a corner: up to 1). 0 keeps every corner.
  double min_corner_isotropy = 0.0;
  // Lucas-Kanade's cost grows with the window's area: 11 px costs about a quarter of 21 px, and
  // through the odometry it is as accurate or better on KITTI 01 (AUC@10 95.96 against 95.83)
  // and the rendered corridor (ATE 0.0104 against 0.0176 m) (doc/vanishing_points.md).
  int window_px = 11;
  int pyramid_levels = 3;
  double max_forward_backward_px = 1.0;  // forward-backward check of each track
  int max_iterations = 30;              // Lucas-Kanade iterations per pyramid level
  // Motion prediction (constant velocity in the image): the search for a feature starts where it
  // would be if it kept its last image motion (a new feature: the median motion of the tracks in
  // its grid cell) and spans only `predicted_pyramid_levels` levels above full resolution, instead
  // of starting at the feature itself and spanning `pyramid_levels`. A feature that the short
  // search loses is searched for again the long way. The backward search of the
  // forward-backward check mirrors the forward one: it starts at the found position minus the
  // predicted motion. On KITTI this keeps 20 % more tracks that agree with the true epipolar
  // geometry, half as many that do not, and costs a third less (see doc/performance.md). Given frame
  // stamps, the last motion is scaled by the ratio of the time steps, so that a dropped frame
  // does not start the short search at half the true motion (up to kMaxMotionScale).
  bool predict_motion = true;
  int predicted_pyramid_levels = 1;
  // Whether a feature predicted to lie outside the image is dropped without a search. On KITTI
  // 130 features a frame are, and searching them costs 8 % of the front end's instructions for
  // the same accuracy; but where the prediction overshoots (a corridor's turns) the search finds
  // them inside again, and dropping them costs accuracy (rendered corridors 1.3-1.7 -> 1.6-2.2
  // deg/100 m; doc/performance.md). So off by default.
  bool drop_leaving = false;
  // A cell is re-detected only once it misses this fraction of its quota: finding one or two
  // corners costs goodFeaturesToTrack over the whole cell, and most new features die young.
  double redetect_min_missing = 0.0;
  // Re-detection only once the tracks fall below this share of max_features, or of the tracks
  // the last re-detection left: a frame that lost a few tracks needs no new ones, and refilling
  // every frame fed mostly corners that died at their first track. 1: every frame.
  double refill_below = 1.0;
  // The new corners are taken strongest first over the whole image (the weaker RMS gradient of
  // their structure tensor), each cell up to its quota: where the image has strong corners the
  // weak ones (noise on a plain wall, a tile's faint pattern: on the rendered room and TartanAir
  // 58-97 % of the corners weaker than 0.5 grey levels per pixel died at their first track,
  // 6-12 % of those above 2) are left out, and where it has none the weak ones still fill it.
  // false: each cell's own strongest, by goodFeaturesToTrack's quality alone.
  bool strongest_first = true;
  // With strongest_first, corners weaker than weak_corner_gradient (RMS grey levels per pixel)
  // are taken only while the tracker holds fewer than weak_corner_share of max_features: a plain
  // wall's faint corners are what keeps a blank corridor's pose, but where the image has strong
  // corners the weak ones mostly die young and bend the pose.
  double weak_corner_gradient = 1.0;
  double weak_corner_share = 0.25;
  // Re-detection in half the grid's cells per frame, as on a checkerboard whose colours take
  // turns: each cell is refilled every other frame. Most new corners die at their first track
  // (51-70 % on the evaluation sets), so refilling every frame mostly feeds the forward-backward
  // check; every other frame costs 13-25 % less CPU and is as accurate or more on 9 of 13 sets
  // (KITTI AUC@10 -0.07), but the stereo scale's affine refinement and the pairs' honesty on the
  // rendered corridor move (doc/performance.md#a-cpu-budget-issue-44): the CPU budget's first
  // level, not yet the default.
  bool redetect_alternate = false;
  // Re-detection only in the cells that lost tracks since the last frame's (or never held any):
  // where an image has fewer good corners than max_features (a room's walls) a cell stays short
  // of its quota, and looking again every frame finds the corners it passed over before.
  bool redetect_lost_cells = false;
  // Track on the image with its vignetting taken out, the shading measured from the tracks
  // (vignetting.h); corners are still detected on the image as it is. TartanAir's orientation
  // after 188 frames: 3.04 -> 0.4 deg (doc/real_data.md).
  bool correct_vignetting = true;
};

// What the tracks cost and how long they live, since the tracker was made (resets included): the
// work per frame is the features handled, and a feature that dies at its first track bought
// nothing.
struct KltTrackStats {
  int64_t frames = 0;          // frames tracked into
  int64_t searched = 0;        // features searched for (forward; each also backward when found)
  int64_t detected = 0;        // new features
  int64_t lost = 0;            // tracks that ended (not found, or failing the check)
  int64_t lost_at_first = 0;   // ... at their first track
  int64_t lifetime_sum = 0;    // frames each ended track was followed
  std::vector<int64_t> lifetimes;  // lifetimes[k]: tracks that ended after k frames (k < 64)
  int median_lifetime() const;     // of the ended tracks, frames; 0 when none ended
};

// Re-detection's work, cell by cell (KltTracker::plan_detection, detect_cell, add_detections).
struct KltDetection {
  int cols = 1, rows = 1, cell_w = 1, cell_h = 1;
  std::vector<int> wanted;  // per cell: the corners to look for (its quota minus its tracks)
  cv::Mat mask;             // 0 within min_distance_px of a tracked feature
  // Per cell: its corners, strongest first (image pixels), whether each is strong enough
  // (min_corner_gradient, min_corner_isotropy), and its weaker RMS gradient (strongest_first).
  std::vector<std::vector<cv::Point2f>> corners;
  std::vector<std::vector<char>> strong;
  std::vector<std::vector<float>> strength;
  int cells() const { return cols * rows; }
};

template <typename Visit>
void visit_fields(KltTrackerOptions& o, Visit&& visit) {
  HYBRID_VO_FIELDS(positive(), o.grid_cols, o.grid_rows, o.max_forward_backward_px,
                  o.max_iterations);
  HYBRID_VO_FIELDS(non_negative(), o.weak_corner_gradient);
  HYBRID_VO_FIELDS(fraction(), o.weak_corner_share);
  HYBRID_VO_FIELDS(non_negative(), o.min_distance_px, o.min_corner_gradient,
                  o.min_corner_isotropy, o.pyramid_levels, o.predicted_pyramid_levels);
  HYBRID_VO_FIELDS(fraction(), o.redetect_min_missing, o.refill_below);
  HYBRID_VO_FIELDS(positive_fraction(), o.quality_level);
  // Smaller windows lose the texture; a larger one than 401 px tracks nothing a corner does
  // (and the corner strength sums a row of its gradients in an int).
  HYBRID_VO_FIELDS(between(5, 401), o.window_px);
  HYBRID_VO_FIELDS(any_value(), o.predict_motion, o.drop_leaving, o.redetect_alternate,
                  o.redetect_lost_cells,
                  o.strongest_first, o.correct_vignetting);
}

// Sparse optical-flow tracking of corners between consecutive video frames, with re-detection in
// empty buckets; each feature keeps a stable id across frames. Each feature is searched for on its
// own and each bucket filled on its own, so `parallel` (worker_thread.h) may spread both over
// threads: the tracks are the same either way.
class KltTracker {
 public:
  static constexpr double kNoStamp = std::numeric_limits<double>::quiet_NaN();
  // A longer gap than this many of the last time steps is predicted as this many: beyond it the
  // constant-velocity guess is worth less than the long search it would replace.
  static constexpr double kMaxMotionScale = 4.0;
  // `max_features` caps the features tracked (and so the matches per pair); VisualOdometry passes
  // its point features' cap, so that one number bounds the points whatever their source.
  explicit KltTracker(const KltTrackerOptions& options = {}, int max_features = 1000);
  // Tracks the current features into `image` and re-detects: track_existing, then detect_new. Returns the matches between the previous frame and this one (pixels) and their
  // track ids. The first call (or the first after reset) returns no matches. `stamp` (seconds,
  // optional) scales the motion prediction when frames are not evenly spaced.
  std::vector<PointMatch> track(const GrayImage& image, std::vector<int64_t>* ids = nullptr,
                                double stamp = kNoStamp, const ParallelFor& parallel = {});
  // The two halves of track, so that the re-detection, which only the next frame needs, can run
  // while the caller uses the matches. After track_existing, points() holds the tracked features.
  std::vector<PointMatch> track_existing(const GrayImage& image, std::vector<int64_t>* ids = nullptr,
                                         double stamp = kNoStamp,
                                         const ParallelFor& parallel = {});
  // track_existing on the pyramid of the image (build_pyramid), built by the caller so that it
  // serves the frame's other stages too (segments, stereo): one pyramid per frame. `image` is the
  // one the pyramid was built from, as it came (the pyramid's may have its vignetting taken out).
  std::vector<cv::Mat> build_pyramid(const GrayImage& image) const;
  std::vector<PointMatch> track_pyramid(std::vector<cv::Mat> pyramid, const GrayImage& image,
                                        std::vector<int64_t>* ids = nullptr,
                                        double stamp = kNoStamp, const ParallelFor& parallel = {});
  // Fills the buckets of the last tracked image that have too few features; appends to points().
  void detect_new(const ParallelFor& parallel = {});
  // detect_new in three steps, so that a caller can run the cells beside other work: the grid,
  // quotas and mask of the tracked features; the corners of one cell (cells are independent,
  // and detect_cell changes nothing but its own cell of `detection`); and their admission in
  // cell order up to max_features. Nothing may change the tracker in between.
  KltDetection plan_detection() const;
  void detect_cell(KltDetection* detection, int cell) const;
  void add_detections(const KltDetection& detection);
  void reset();
  // The point budget and the re-detection's threshold and alternation from the next frame on (a
  // CPU budget's work level); the options' own otherwise. Tracks beyond a smaller cap leave at the
  // next re-detection, the youngest first.
  void set_work(int max_features, double redetect_min_missing, bool redetect_alternate);
  int num_tracks() const;
  const KltTrackStats& stats() const { return stats_; }
  // Every feature of the last frame (tracked and newly detected) and its id.
  const std::vector<cv::Point2f>& points() const { return points_; }
  const std::vector<int64_t>& ids() const { return ids_; }
  // The last frame's pyramid (cv::buildOpticalFlowPyramid with derivatives, window_px and
  // pyramid_levels), so that matching the same image elsewhere (stereo) need not build it again.
  const std::vector<cv::Mat>& pyramid() const { return previous_; }
  // 1 / V per pixel while the vignetting is corrected (empty otherwise): the pyramid above is of
  // the image times this, so a stereo partner image needs the same (flat_field).
  const cv::Mat& flat_field_gain() const { return gain_map_; }
  const VignettingEstimator& vignetting() const { return vignetting_; }

 private:
  // Where each feature of the previous frame is searched for in the next one; false where there
  // is no prediction (the search then starts at the feature itself and spans all levels).
  std::vector<char> predict(double motion_scale, std::vector<cv::Point2f>* next) const;
  // Ratio of the time since the last frame to the time step its motions were measured over; 1
  // without stamps.
  double motion_scale(double stamp) const;
  // The searches of features [begin, end) into `pyramid` (see track_existing); writes only their
  // slots of `search`.
  struct Search;
  // The tracks' brightness into the vignetting estimate, and the map for the next frame.
  void update_vignetting(const cv::Mat& raw, const std::vector<PointMatch>& matches);
  // Corners are found on the image as it came: its thresholds are in its grey levels.
  const cv::Mat& detection_image() const;
  void search_range(const std::vector<cv::Mat>& pyramid, int begin, int end, Search* search) const;

  KltTrackerOptions options_;
  int max_features_;
  int64_t detections_ = 0;  // re-detections added since the last reset (redetect_alternate)
  int refilled_to_ = 0;     // the tracks after the last re-detection that looked for corners
  // Per grid cell: its tracks after the last frame's re-detection (redetect_lost_cells).
  std::vector<int> cell_tracks_;
  cv::Size size_;
  std::vector<cv::Mat> previous_;  // image pyramid with derivatives, built once per frame
  // The last frame's image as it came (its brightness, and the corners' detection).
  cv::Mat previous_raw_;
  VignettingEstimator vignetting_;
  cv::Mat gain_map_;         // flat_field_gain()
  double map_corner_ = 1.0;  // the corner gain gain_map_ was made for
  std::vector<cv::Point2f> points_;
  std::vector<cv::Point2f> motion_;  // per feature: its last image motion, NaN when new
  std::vector<int64_t> ids_;
  std::vector<int> age_;  // per feature: the frames it has been tracked
  int64_t next_id_ = 0;
  KltTrackStats stats_;
  double stamp_ = kNoStamp;         // of the last tracked frame
  double motion_dt_ = kNoStamp;     // the time step motion_ was measured over
};

}  // namespace hybrid_vo
