// Segments followed by their flow (segment_flow.h, line_flow_tracker.h): on a synthetic image
// moved by a known homography each segment lands on its true line, sub-pixel; a segment whose
// edge is gone is reported lost; degenerate input gives no segment and no crash; the tracker
// keeps its ids, merges what one detection continues and asks for the detector when its tracks
// thin out.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "hybrid_vo/features/line_flow_tracker.h"
#include "hybrid_vo/features/segment_flow.h"
#include "image_test_utils.h"

namespace {

using namespace hybrid_vo;

constexpr int kWidth = 640, kHeight = 480;

Eigen::Vector2d apply(const Eigen::Matrix3d& H, const Eigen::Vector2d& p) {
  const Eigen::Vector3d q = H * homogeneous(p);
  return q.head<2>() / q.z();
}

LineSegment apply(const Eigen::Matrix3d& H, const LineSegment& s) {
  return LineSegment(apply(H, s.p1), apply(H, s.p2));
}

// A small rotation about the image centre, a shift and a slight perspective.
Eigen::Matrix3d motion(double angle_deg, double dx, double dy) {
  const double a = angle_deg * M_PI / 180.0;
  Eigen::Matrix3d T, R, P;
  T << 1, 0, kWidth / 2.0 + dx, 0, 1, kHeight / 2.0 + dy, 0, 0, 1;
  R << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  P << 1, 0, -kWidth / 2.0, 0, 1, -kHeight / 2.0, 2e-5, -1e-5, 1;
  return T * R * P;
}

cv::Mat warp(const cv::Mat& image, const Eigen::Matrix3d& H) {
  cv::Mat h(3, 3, CV_64F), out;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) h.at<double>(r, c) = H(r, c);
  cv::warpPerspective(image, out, h, image.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return out;
}

// Grey quadrilaterals on a faintly textured background; their sides are the segments (oriented
// by nothing in particular: the flow keeps p1 and p2 as given).
struct Scene {
  cv::Mat background;
  std::vector<std::vector<Eigen::Vector2d>> shapes;
  std::vector<double> shades;
  std::vector<LineSegment> segments;
};

Scene quadrilaterals() {
  cv::theRNG().state = 7;
  Scene scene;
  const cv::Mat texture = hybrid_vo::testing::blurred_noise(kHeight, kWidth, 3.0);
  texture.convertTo(scene.background, CV_32F, 0.15, 100.0);  // 100..138: faint
  scene.shapes = {
      {{80, 60}, {260, 70}, {250, 200}, {90, 190}},
      {{360, 80}, {560, 60}, {580, 220}, {380, 240}},
      {{120, 280}, {300, 300}, {280, 430}, {100, 420}},
      {{400, 300}, {590, 290}, {560, 440}, {420, 420}},
  };
  scene.shades = {30, 220, 200, 40};
  for (const auto& shape : scene.shapes)
    for (size_t c = 0; c < shape.size(); ++c)
      scene.segments.push_back(LineSegment(shape[c], shape[(c + 1) % shape.size()]));
  return scene;
}

// The scene seen through homography H: the background warped, each quadrilateral's area
// measured on 4 x 4 points per pixel (pixel centres at integer coordinates, so that an edge lies
// exactly on its side), then blurred like a lens.
cv::Mat render(const Scene& scene, const Eigen::Matrix3d& H) {
  cv::Mat image = warp(scene.background, H);
  for (size_t k = 0; k < scene.shapes.size(); ++k) {
    std::vector<Eigen::Vector3d> sides;  // l.x >= 0 inside, counter-clockwise or not
    std::vector<Eigen::Vector2d> corners;
    for (const Eigen::Vector2d& p : scene.shapes[k]) corners.push_back(apply(H, p));
    Eigen::Vector2d centre = Eigen::Vector2d::Zero();
    for (const Eigen::Vector2d& p : corners) centre += p / corners.size();
    for (size_t c = 0; c < corners.size(); ++c) {
      Eigen::Vector3d l = line_through(corners[c], corners[(c + 1) % corners.size()]);
      if (l.dot(homogeneous(centre)) < 0.0) l = -l;
      sides.push_back(l);
    }
    double x0 = kWidth, y0 = kHeight, x1 = 0, y1 = 0;
    for (const Eigen::Vector2d& p : corners) {
      x0 = std::min(x0, p.x()), y0 = std::min(y0, p.y());
      x1 = std::max(x1, p.x()), y1 = std::max(y1, p.y());
    }
    for (int y = std::max(0, static_cast<int>(y0) - 1); y <= std::min(kHeight - 1, static_cast<int>(y1) + 1); ++y)
      for (int x = std::max(0, static_cast<int>(x0) - 1); x <= std::min(kWidth - 1, static_cast<int>(x1) + 1); ++x) {
        int in = 0;
        for (int i = 0; i < 4; ++i)
          for (int j = 0; j < 4; ++j) {
            const Eigen::Vector3d p(x - 0.375 + 0.25 * j, y - 0.375 + 0.25 * i, 1.0);
            bool inside = true;
            for (const Eigen::Vector3d& l : sides) inside = inside && l.dot(p) >= 0.0;
            in += inside;
          }
        float& v = image.at<float>(y, x);
        v += (in / 16.0f) * (static_cast<float>(scene.shades[k]) - v);
      }
  }
  cv::GaussianBlur(image, image, cv::Size(0, 0), 0.8);
  cv::Mat out;
  image.convertTo(out, CV_8U);
  return out;
}

std::vector<cv::Mat> levels(const cv::Mat& image) {
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(image, pyramid, cv::Size(11, 11), 3, true);
  return pyramid_images(pyramid);
}

// The larger distance of `truth`'s ends to `found`'s line (px).
double line_error(const LineSegment& found, const LineSegment& truth) {
  const Eigen::Vector3d l = line_through(found.p1, found.p2);
  return std::max(std::abs(l.dot(homogeneous(truth.p1))), std::abs(l.dot(homogeneous(truth.p2))));
}

TEST(SegmentFlow, SegmentsMovedByAHomographyLandOnTheirTrueLines) {
  const Scene scene = quadrilaterals();
  const std::vector<cv::Mat> from = levels(render(scene, Eigen::Matrix3d::Identity()));
  // Predicted where they were (no prediction), then predicted 3 px off: both within the search.
  for (const double shift : {0.0, 3.0}) {
    const Eigen::Matrix3d H = motion(2.0, 11.3, -6.7);
    const std::vector<cv::Mat> to = levels(render(scene, H));
    std::vector<LineSegment> predicted;
    for (const LineSegment& s : scene.segments) {
      const LineSegment moved = apply(H, s);
      const Eigen::Vector2d off(shift, -shift);
      predicted.push_back(shift > 0.0 ? LineSegment(moved.p1 + off, moved.p2 + off) : s);
    }
    const std::vector<SegmentFlow> flows =
        track_segments_by_flow(from, to, scene.segments, predicted);
    ASSERT_EQ(flows.size(), scene.segments.size());
    for (size_t k = 0; k < flows.size(); ++k) {
      ASSERT_TRUE(flows[k].found) << "segment " << k << " shift " << shift << " samples "
                                  << flows[k].samples << " inliers " << flows[k].inliers;
      const LineSegment truth = apply(H, scene.segments[k]);
      EXPECT_LT(line_error(flows[k].segment, truth), 0.2) << "segment " << k;
      // p1 and p2 keep their roles, and the ends stay near the true ones.
      EXPECT_GT((flows[k].segment.p2 - flows[k].segment.p1).dot(truth.p2 - truth.p1), 0.0);
      // The ends are where the edge ends, up to the prediction's error along it (4.2 px here;
      // without a prediction the sides slid 10-15 px along themselves).
      if (shift > 0.0) {
        EXPECT_LT((flows[k].segment.p1 - truth.p1).norm(), 5.0) << "segment " << k;
        EXPECT_LT((flows[k].segment.p2 - truth.p2).norm(), 5.0) << "segment " << k;
      }
      EXPECT_GE(flows[k].inliers, flows[k].samples * 3 / 4);
      EXPECT_LT(flows[k].rms_px, 0.3);
    }
  }
}

TEST(SegmentFlow, ASegmentWhoseEdgeIsGoneIsLost) {
  const Scene scene = quadrilaterals();
  const Eigen::Matrix3d H = motion(0.5, 2.0, 1.0);
  cv::Mat next = render(scene, H);
  // The second quadrilateral painted over with the background's mean: its four sides are gone.
  cv::rectangle(next, cv::Rect(340, 40, 270, 220), cv::Scalar(119), cv::FILLED);
  const std::vector<SegmentFlow> flows =
      track_segments_by_flow(levels(render(scene, Eigen::Matrix3d::Identity())), levels(next), scene.segments, {});
  for (size_t k = 0; k < flows.size(); ++k) EXPECT_EQ(flows[k].found, k < 4 || k >= 8) << k;
}

TEST(SegmentFlow, DegenerateInputGivesNoSegmentAndNoCrash) {
  const Scene scene = quadrilaterals();
  const std::vector<cv::Mat> from = levels(render(scene, Eigen::Matrix3d::Identity()));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<LineSegment> odd = {
      LineSegment({nan, 10}, {100, 10}),       // not finite
      LineSegment({50, 50}, {50, 50}),         // no length
      LineSegment({-500, -500}, {-400, -500}), // outside the image
      LineSegment({0, 0}, {639, 0}),           // along the border: no edge across it
  };
  for (const SegmentFlow& f : track_segments_by_flow(from, from, odd, {})) EXPECT_FALSE(f.found);
  // No images, or images of other sizes: nothing found.
  EXPECT_FALSE(track_segments_by_flow({}, from, scene.segments, {})[0].found);
  EXPECT_FALSE(track_segments_by_flow(from, levels(cv::Mat(100, 100, CV_8U, cv::Scalar(0))),
                                      scene.segments, {})[0].found);
  // A flat image has no edge to follow.
  const cv::Mat flat(kHeight, kWidth, CV_8U, cv::Scalar(128));
  for (const SegmentFlow& f : track_segments_by_flow(levels(flat), levels(flat), scene.segments, {}))
    EXPECT_FALSE(f.found);
  // A prediction with NaN ends.
  std::vector<LineSegment> predicted(scene.segments.size(), LineSegment({nan, nan}, {1, 1}));
  for (const SegmentFlow& f : track_segments_by_flow(from, from, scene.segments, predicted))
    EXPECT_FALSE(f.found);
}

TEST(LineFlowTracker, KeepsIdsAlongTheFlowAndAsksForTheDetectorWhenTracksThinOut) {
  const Scene scene = quadrilaterals();
  LineFlowTrackerOptions options;
  options.max_frames_between_detections = 100;
  options.max_seconds_between_detections = 100.0;
  LineFlowTracker tracker(options);
  tracker.track(levels(render(scene, Eigen::Matrix3d::Identity())), 1.0);
  EXPECT_TRUE(tracker.wants_detection());  // nothing to follow yet
  tracker.add_detections(scene.segments);
  const std::vector<int64_t> ids = tracker.ids();
  ASSERT_EQ(ids.size(), scene.segments.size());
  EXPECT_FALSE(tracker.wants_detection());

  // Three frames of a steady motion: every track follows it, with its id.
  Eigen::Matrix3d H = Eigen::Matrix3d::Identity();
  for (int frame = 1; frame <= 3; ++frame) {
    H = motion(0.7, 4.0, 2.5) * H;
    LineTrackingStats stats;
    tracker.track(levels(render(scene, H)), 1.0 + 0.1 * frame, Eigen::Matrix3d::Identity(), nullptr, {},
                  &stats);
    EXPECT_EQ(stats.matched, static_cast<int>(scene.segments.size())) << "frame " << frame;
    EXPECT_EQ(tracker.ids(), ids);
    const std::vector<LineSegment> segments = tracker.segments();
    for (size_t k = 0; k < segments.size(); ++k)
      EXPECT_LT(line_error(segments[k], apply(H, scene.segments[k])), 0.3) << "frame " << frame;
  }
  EXPECT_FALSE(tracker.wants_detection());

  // A detection continues each track (the true sides, longer by a few pixels: fresh ends); a new
  // segment starts its own. The tracks keep the lines the flow measured, and reach the
  // detections' ends.
  const std::vector<LineSegment> followed = tracker.segments();
  std::vector<LineSegment> detected;
  for (const LineSegment& s : scene.segments) {
    const LineSegment t = apply(H, s);
    const Eigen::Vector2d u = (t.p2 - t.p1).normalized();
    detected.push_back(LineSegment(t.p1 - 3.0 * u, t.p2 + 3.0 * u));
  }
  detected.push_back(LineSegment({10, 470}, {200, 470}));
  tracker.add_detections(detected);
  EXPECT_EQ(tracker.num_tracks(), static_cast<int>(scene.segments.size()) + 1);
  const std::vector<int64_t> after = tracker.ids();
  EXPECT_TRUE(std::equal(ids.begin(), ids.end(), after.begin()));
  const std::vector<LineSegment> refreshed = tracker.segments();
  for (size_t k = 0; k < followed.size(); ++k) {
    EXPECT_LT(line_error(refreshed[k], followed[k]), 1e-6) << "segment " << k;
    EXPECT_NEAR(refreshed[k].length(), detected[k].length(), 0.1) << "segment " << k;
  }

  // The second and third quadrilaterals painted over: half the tracks are lost, and the tracker
  // wants the detector.
  cv::Mat next = render(scene, H);
  cv::rectangle(next, cv::Rect(330, 30, 300, 240), cv::Scalar(119), cv::FILLED);
  cv::rectangle(next, cv::Rect(60, 250, 270, 220), cv::Scalar(119), cv::FILLED);
  LineTrackingStats stats;
  tracker.track(levels(next), 1.5, Eigen::Matrix3d::Identity(), nullptr, {}, &stats);
  EXPECT_GE(stats.dropped, 8);
  EXPECT_TRUE(tracker.wants_detection());
}

TEST(LineFlowTracker, TheDetectorRunsAgainAfterAFewFramesOrAShortWhile) {
  const Scene scene = quadrilaterals();
  const std::vector<cv::Mat> image = levels(render(scene, Eigen::Matrix3d::Identity()));
  for (const double seconds : {0.25, 100.0}) {
    LineFlowTrackerOptions options;
    options.max_frames_between_detections = 4;
    options.max_seconds_between_detections = seconds;
    LineFlowTracker tracker(options);
    tracker.track(image, 1.0);
    tracker.add_detections(scene.segments);
    int frames = 1;
    while (frames < 10) {
      tracker.track(image, 1.0 + 0.1 * frames);
      if (tracker.wants_detection()) break;
      ++frames;
    }
    // 0.25 s: the frame at 1.3 s would come too late; else the fourth frame after it.
    EXPECT_EQ(frames, seconds < 1.0 ? 2 : 3) << seconds;
  }
}

TEST(LineFlowTracker, OneDetectionContinuingTwoTracksMergesThemIntoTheOldest) {
  LineFlowTracker tracker;
  const Scene scene = quadrilaterals();
  tracker.track(levels(render(scene, Eigen::Matrix3d::Identity())), 1.0);
  tracker.add_detections({LineSegment({100, 100}, {200, 100}), LineSegment({210, 100.5}, {300, 100.5})});
  ASSERT_EQ(tracker.num_tracks(), 2);
  tracker.add_detections({LineSegment({95, 100.2}, {305, 100.2})});
  ASSERT_EQ(tracker.num_tracks(), 1);
  EXPECT_EQ(tracker.ids()[0], 0);
  EXPECT_NEAR(tracker.segments()[0].p1.x(), 95.0, 1e-9);
  // Opposite contrast (reversed direction) continues nothing: a new track.
  tracker.add_detections({LineSegment({305, 100.2}, {95, 100.2})});
  EXPECT_EQ(tracker.num_tracks(), 2);
}

// Points on a grid, each where H takes it.
std::vector<PointMatch> grid_motion(const Eigen::Matrix3d& H, double spacing) {
  std::vector<PointMatch> motion;
  for (double y = 5; y < kHeight; y += spacing)
    for (double x = 5; x < kWidth; x += spacing) {
      PointMatch m;
      m.x1 = Eigen::Vector2d(x, y);
      m.x2 = apply(H, m.x1);
      motion.push_back(m);
    }
  return motion;
}

TEST(PointFlowField, PredictsASegmentByThePointsAroundIt) {
  const Eigen::Matrix3d H = motion(1.5, 14.0, -9.0);
  const PointFlowField field(grid_motion(H, 16.0));
  const LineSegment s({150, 200}, {400, 260});
  LineSegment predicted;
  double spread = -1.0;
  ASSERT_TRUE(field.predict(s, 40.0, 4, &predicted, &spread));
  // The field is smooth: the ends land within a pixel of where H takes them.
  EXPECT_LT((predicted.p1 - apply(H, s.p1)).norm(), 1.0);
  EXPECT_LT((predicted.p2 - apply(H, s.p2)).norm(), 1.0);
  EXPECT_LT(spread, 0.5);
  // Too few points near it, or none at all: no prediction.
  EXPECT_FALSE(PointFlowField(grid_motion(H, 200.0)).predict(s, 10.0, 4, &predicted, &spread));
  EXPECT_FALSE(PointFlowField().predict(s, 40.0, 4, &predicted, &spread));
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(field.predict(LineSegment({nan, 0}, {1, 1}), 40.0, 4, &predicted, &spread));
}

TEST(LineFlowTracker, ThePointsCarryYoungTracksFartherThanTheirOwnReach) {
  const Scene scene = quadrilaterals();
  const Eigen::Matrix3d H = motion(0.5, 21.0, 0.0);
  const std::vector<cv::Mat> first = levels(render(scene, Eigen::Matrix3d::Identity()));
  const std::vector<cv::Mat> second = levels(render(scene, H));
  const PointFlowField points(grid_motion(H, 16.0));
  for (const bool with_points : {false, true}) {
    LineFlowTracker tracker;
    tracker.track(first, 1.0);
    tracker.add_detections(scene.segments);
    LineTrackingStats stats;
    tracker.track(second, 1.1, Eigen::Matrix3d::Identity(), with_points ? &points : nullptr, {},
                  &stats);
    // A young track is looked for 12 px around the rotation's prediction: the sides that move
    // 21 px across themselves are beyond it.
    if (!with_points) {
      EXPECT_LT(stats.matched, static_cast<int>(scene.segments.size()));
      continue;
    }
    EXPECT_EQ(stats.matched, static_cast<int>(scene.segments.size()));
    const std::vector<LineSegment> segments = tracker.segments();
    for (size_t k = 0; k < segments.size(); ++k)
      EXPECT_LT(line_error(segments[k], apply(H, scene.segments[k])), 0.2) << "segment " << k;
  }
}

TEST(LineFlowTracker, NewTracksStartOnTheEdgeAsTheFlowMeasuresIt) {
  // A detector's line a third of a pixel off the edge: the track starts on the edge itself, so
  // that every frame of it measures the same thing.
  const Scene scene = quadrilaterals();
  LineFlowTracker tracker;
  tracker.track(levels(render(scene, Eigen::Matrix3d::Identity())), 1.0);
  std::vector<LineSegment> detected;
  for (const LineSegment& s : scene.segments) {
    const Eigen::Vector2d u = (s.p2 - s.p1).normalized(), n(-u.y(), u.x());
    detected.push_back(LineSegment(s.p1 + 0.35 * n, s.p2 + 0.35 * n));
  }
  tracker.add_detections(detected);
  const std::vector<LineSegment> started = tracker.segments();
  ASSERT_EQ(started.size(), scene.segments.size());
  for (size_t k = 0; k < started.size(); ++k)
    EXPECT_LT(line_error(started[k], scene.segments[k]), 0.15) << "segment " << k;
}

}  // namespace
