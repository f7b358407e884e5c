// Wide-baseline matching of points and segments on synthetic planar scenes related by a known
// homography, the camera model's distortion, and degenerate input.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/features/camera_model.h"
#include "hybrid_vo/features/fisheye_rectifier.h"
#include "hybrid_vo/features/line_matching.h"
#include "hybrid_vo/features/point_matching.h"

namespace hybrid_vo {
namespace {

constexpr int kWidth = 640, kHeight = 480;
constexpr int kCanvasWidth = 1400, kCanvasHeight = 1100;

cv::Point rand_point(cv::RNG& rng, int w, int h) { return {rng.uniform(0, w), rng.uniform(0, h)}; }

// A textured plane: smooth random shading, rotated rectangles, text-like blobs and long straight
// edges, drawn on a canvas larger than both views so that neither sees past its border.
cv::Mat render_canvas(uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat coarse(kCanvasHeight / 40, kCanvasWidth / 40, CV_8U);
  rng.fill(coarse, cv::RNG::UNIFORM, 70, 180);
  cv::Mat canvas;
  cv::resize(coarse, canvas, cv::Size(kCanvasWidth, kCanvasHeight), 0, 0, cv::INTER_CUBIC);
  for (int k = 0; k < 110; ++k) {  // rotated rectangles
    const cv::RotatedRect r(
        cv::Point2f(rng.uniform(0, kCanvasWidth), rng.uniform(0, kCanvasHeight)),
        cv::Size2f(rng.uniform(30, 160), rng.uniform(30, 160)),
        static_cast<float>(rng.uniform(0.0, 180.0)));
    cv::Point2f corners[4];
    r.points(corners);
    std::vector<cv::Point> polygon(corners, corners + 4);
    cv::fillConvexPoly(canvas, polygon, cv::Scalar(rng.uniform(0, 256)), cv::LINE_AA);
  }
  const std::string letters = "ABCDEFGHKLMNPRSTUVWXYZ0123456789#%&";
  for (int k = 0; k < 150; ++k) {  // text-like blobs
    std::string word;
    for (int c = rng.uniform(2, 6); c > 0; --c) word += letters[rng.uniform(0, letters.size())];
    cv::putText(canvas, word, rand_point(rng, kCanvasWidth, kCanvasHeight),
                rng.uniform(0, 2) ? cv::FONT_HERSHEY_SIMPLEX : cv::FONT_HERSHEY_DUPLEX,
                rng.uniform(0.6, 1.6), cv::Scalar(rng.uniform(0, 2) ? 15 : 240), rng.uniform(1, 4),
                cv::LINE_AA);
  }
  for (int k = 0; k < 45; ++k) {  // long straight edges
    cv::line(canvas, rand_point(rng, kCanvasWidth, kCanvasHeight),
             rand_point(rng, kCanvasWidth, kCanvasHeight), cv::Scalar(rng.uniform(0, 2) ? 10 : 245),
             rng.uniform(2, 6), cv::LINE_AA);
  }
  return canvas;
}

Eigen::Matrix3d to_eigen(const cv::Matx33d& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) e(r, c) = m(r, c);
  return e;
}

// Two views of a canvas and the homography from view 1 to view 2 (pixels).
struct ViewPair {
  cv::Mat image1, image2;
  Eigen::Matrix3d H;
};

// View 1 is the canvas' central window; view 2 looks at it rotated by `degrees`, scaled by
// `scale` and with a perspective tilt.
ViewPair make_views(const cv::Mat& canvas, double degrees, double scale, double tilt) {
  const double cx = kCanvasWidth / 2.0, cy = kCanvasHeight / 2.0;
  const cv::Matx33d to_view1(1, 0, kWidth / 2.0 - cx, 0, 1, kHeight / 2.0 - cy, 0, 0, 1);
  const double a = degrees * M_PI / 180.0;
  const cv::Matx33d centre(1, 0, -cx, 0, 1, -cy, 0, 0, 1);
  const cv::Matx33d rotate(scale * std::cos(a), -scale * std::sin(a), 0, scale * std::sin(a),
                           scale * std::cos(a), 0, 0, 0, 1);
  const cv::Matx33d perspective(1, 0, 0, 0, 1, 0, tilt, -0.5 * tilt, 1);
  const cv::Matx33d back(1, 0, kWidth / 2.0, 0, 1, kHeight / 2.0, 0, 0, 1);
  const cv::Matx33d to_view2 = back * perspective * rotate * centre;
  ViewPair views;
  cv::warpPerspective(canvas, views.image1, to_view1, cv::Size(kWidth, kHeight), cv::INTER_LINEAR,
                      cv::BORDER_REFLECT);
  cv::warpPerspective(canvas, views.image2, to_view2, cv::Size(kWidth, kHeight), cv::INTER_LINEAR,
                      cv::BORDER_REFLECT);
  views.H = to_eigen(to_view2 * to_view1.inv());
  // Both views must see the canvas only, not its reflected border.
  const Eigen::Matrix3d from_view2 = to_eigen(to_view2.inv());
  for (const Eigen::Vector2d& corner :
       {Eigen::Vector2d(0, 0), Eigen::Vector2d(kWidth, 0), Eigen::Vector2d(0, kHeight),
        Eigen::Vector2d(kWidth, kHeight)}) {
    const Eigen::Vector2d c = (from_view2 * homogeneous(corner)).hnormalized();
    EXPECT_TRUE(c.x() > 0 && c.y() > 0 && c.x() < kCanvasWidth && c.y() < kCanvasHeight)
        << "view 2 sees past the canvas at " << c.transpose();
  }
  return views;
}

Eigen::Vector2d apply(const Eigen::Matrix3d& H, const Eigen::Vector2d& x) {
  return (H * homogeneous(x)).hnormalized();
}

bool point_correct(const Eigen::Matrix3d& H, const PointMatch& m, double tolerance = 2.0) {
  return (apply(H, m.x1) - m.x2).norm() < tolerance;
}

// Both endpoints of s1 mapped by H within `tolerance` of s2's infinite line, and the mapped
// segment overlapping s2.
bool line_correct(const Eigen::Matrix3d& H, const LineMatch& m, double tolerance = 2.0) {
  const Eigen::Vector2d p = apply(H, m.s1.p1), q = apply(H, m.s1.p2);
  const Eigen::Vector3d l = line_through(m.s2.p1, m.s2.p2);
  if (std::abs(l.dot(homogeneous(p))) > tolerance || std::abs(l.dot(homogeneous(q))) > tolerance)
    return false;
  const Eigen::Vector2d u = (m.s2.p2 - m.s2.p1).normalized();
  const double t1 = u.dot(p - m.s2.p1), t2 = u.dot(q - m.s2.p1);
  return std::max(t1, t2) > 0.0 && std::min(t1, t2) < m.s2.length();
}

template <typename Match, typename Correct>
double fraction_correct(const std::vector<Match>& matches, Correct correct) {
  if (matches.empty()) return 0.0;
  int good = 0;
  for (const Match& m : matches) good += correct(m) ? 1 : 0;
  return static_cast<double>(good) / matches.size();
}

class HomographyScene : public ::testing::TestWithParam<int> {};

// Mild and wide baselines: rotation, zoom out and tilt.
ViewPair scene_for(int which) {
  const cv::Mat canvas = render_canvas(17 + which);
  if (which == 0) return make_views(canvas, 12.0, 0.95, 2e-4);
  if (which == 1) return make_views(canvas, -20.0, 0.8, -3e-4);
  return make_views(canvas, 40.0, 1.2, 4e-4);
}

TEST_P(HomographyScene, SiftPointMatchesAreCorrect) {
  const ViewPair v = scene_for(GetParam());
  const PointMatchingOptions options;  // SIFT
  const auto matches = match_point_features(detect_point_features(v.image1, options),
                                            detect_point_features(v.image2, options), options);
  const double correct =
      fraction_correct(matches, [&](const PointMatch& m) { return point_correct(v.H, m); });
  std::printf("[   INFO   ] SIFT: %zu matches, %.1f %% within 2 px\n", matches.size(),
              100.0 * correct);
  EXPECT_GE(matches.size(), 100u);
  EXPECT_GE(correct, 0.9) << matches.size() << " matches";
}

// ORB reports a keypoint at the resolution of the pyramid level that found it (scale 1.2^octave),
// so its tolerance is 2 px of that level.
TEST_P(HomographyScene, OrbPointMatchesAreCorrect) {
  const ViewPair v = scene_for(GetParam());
  const PointMatchingOptions options = video_point_matching_options();
  const PointFeatures f1 = detect_point_features(v.image1, options);
  const PointFeatures f2 = detect_point_features(v.image2, options);
  std::vector<std::pair<int, int>> pairs;
  const auto matches = match_point_features(f1, f2, options, &pairs);
  ASSERT_EQ(pairs.size(), matches.size());
  int correct = 0;
  for (size_t k = 0; k < matches.size(); ++k) {
    const int octave =
        std::max(f1.keypoints[pairs[k].first].octave, f2.keypoints[pairs[k].second].octave);
    correct += point_correct(v.H, matches[k], 2.0 * std::pow(options.orb_scale_factor, octave));
  }
  std::printf("[   INFO   ] ORB: %zu matches, %.1f %% within 2 px of their level\n", matches.size(),
              100.0 * correct / std::max<size_t>(matches.size(), 1));
  EXPECT_GE(matches.size(), 100u);
  EXPECT_GE(correct, 0.9 * matches.size()) << matches.size() << " matches";
}

TEST_P(HomographyScene, LineMatchesAreCorrectAndOriented) {
  const ViewPair v = scene_for(GetParam());
  for (const bool video : {false, true}) {
    SCOPED_TRACE(video ? "video preset (FLD, 1 octave)" : "defaults (LSD, 3 octaves)");
    const LineMatchingOptions options =
        video ? video_line_matching_options() : LineMatchingOptions();
    // detect_line_features, with every other detected segment reversed first: the orientation
    // must come from the description, whatever the detector's.
    auto features = [&](const cv::Mat& image) {
      std::vector<LineSegment> segments = detect_line_segments(image, options.detection);
      for (size_t k = 0; k < segments.size(); k += 2) std::swap(segments[k].p1, segments[k].p2);
      return describe_line_segments(image, segments, nullptr, options.description);
    };
    const LineFeatures f1 = features(v.image1), f2 = features(v.image2);
    std::vector<std::pair<int, int>> pairs;
    const auto matches = match_line_features(f1, f2, options, &pairs);
    ASSERT_EQ(pairs.size(), matches.size());
    int correct = 0, oriented = 0;
    for (size_t k = 0; k < matches.size(); ++k) {
      // `pairs` indexes the features' segments, and the matches carry them unchanged.
      EXPECT_EQ(matches[k].s1.p1, f1.segments[pairs[k].first].p1);
      EXPECT_EQ(matches[k].s2.p2, f2.segments[pairs[k].second].p2);
      if (!line_correct(v.H, matches[k])) continue;
      ++correct;
      // The mapped image-1 direction agrees with the image-2 direction.
      const Eigen::Vector2d d1 = apply(v.H, matches[k].s1.p2) - apply(v.H, matches[k].s1.p1);
      if (d1.dot(matches[k].s2.p2 - matches[k].s2.p1) > 0.0) ++oriented;
    }
    std::printf("[   INFO   ] lines (%s): %zu matches, %.1f %% correct\n",
                video ? "video preset" : "defaults", matches.size(),
                100.0 * correct / std::max<size_t>(matches.size(), 1));
    EXPECT_GE(matches.size(), 30u);
    EXPECT_GE(correct, 0.9 * matches.size()) << matches.size() << " matches";
    EXPECT_EQ(oriented, correct);
  }
}

INSTANTIATE_TEST_SUITE_P(Baselines, HomographyScene, ::testing::Values(0, 1, 2));

// LBD's convention, checked directly: the dark side of every described segment is on the left of
// p1->p2 as seen on screen, i.e. the image is brighter along (-dy, dx).
TEST(LineMatching, SegmentsKeepTheDarkSideOnTheLeft) {
  cv::Mat image(240, 320, CV_8U, cv::Scalar(200));
  cv::rectangle(image, cv::Rect(100, 60, 120, 100), cv::Scalar(40), cv::FILLED);
  cv::circle(image, cv::Point(60, 180), 5, cv::Scalar(120), cv::FILLED);  // some texture
  const std::vector<LineSegment> edges = {{{100, 80}, {100, 140}}, {{100, 140}, {100, 80}},
                                          {{120, 60}, {200, 60}},  {{200, 60}, {120, 60}},
                                          {{220, 70}, {220, 150}}, {{200, 160}, {120, 160}}};
  std::vector<int> kept;
  const LineFeatures f = describe_line_segments(image, edges, &kept);
  ASSERT_EQ(f.segments.size(), edges.size());
  for (const LineSegment& s : f.segments) {
    const Eigen::Vector2d u = (s.p2 - s.p1).normalized(), left(-u.y(), u.x());
    const Eigen::Vector2d bright = s.midpoint() + 4.0 * left, dark = s.midpoint() - 4.0 * left;
    EXPECT_GT(image.at<uchar>(cvRound(bright.y()), cvRound(bright.x())),
              image.at<uchar>(cvRound(dark.y()), cvRound(dark.x())));
  }
  // The same edge given either way round gets the same orientation and the same descriptor.
  EXPECT_EQ(f.segments[0].p1, f.segments[1].p1);
  EXPECT_EQ(cv::norm(f.descriptors.row(0), f.descriptors.row(1), cv::NORM_L2), 0.0);
}

// describe_line_segments drops what it cannot describe and reports the kept indices.
TEST(LineMatching, DescribeGivenSegmentsReportsKeptIndices) {
  const ViewPair v = scene_for(0);
  LineMatchingOptions options;
  std::vector<LineSegment> segments = detect_line_segments(v.image1, options.detection);
  ASSERT_GT(segments.size(), 20u);
  segments.resize(20);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  segments.insert(segments.begin() + 3, LineSegment({nan, 5}, {50, 50}));         // not finite
  segments.insert(segments.begin() + 7, LineSegment({10, 10}, {12, 11}));         // too short
  segments.insert(segments.begin() + 11, LineSegment({-500, -80}, {-420, -90}));  // outside
  std::vector<int> kept;
  const LineFeatures f = describe_line_segments(v.image1, segments, &kept);
  ASSERT_EQ(kept.size(), f.segments.size());
  ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.segments.size()));
  EXPECT_EQ(f.descriptors.type(), CV_32F);
  EXPECT_EQ(f.descriptors.cols, 72 * options.description.octaves);
  const std::set<int> dropped = {3, 7, 11};
  std::set<int> kept_set(kept.begin(), kept.end());
  for (int d : dropped) EXPECT_EQ(kept_set.count(d), 0u);
  EXPECT_GE(kept.size(), 20u - 2u);  // the detections themselves have contrast, bar a rare one
  for (size_t r = 0; r < kept.size(); ++r) {
    const LineSegment& in = segments[kept[r]];
    const LineSegment& out = f.segments[r];
    // Same segment, possibly reversed.
    EXPECT_TRUE((in.p1 == out.p1 && in.p2 == out.p2) || (in.p1 == out.p2 && in.p2 == out.p1));
  }
  // The binary form: 32 bytes per octave.
  LineDescriptionOptions binary;
  binary.float_descriptor = false;
  binary.octaves = 2;
  const LineFeatures fb = describe_line_segments(v.image1, segments, nullptr, binary);
  EXPECT_EQ(fb.descriptors.type(), CV_8U);
  EXPECT_EQ(fb.descriptors.cols, 64);
  EXPECT_EQ(fb.descriptors.rows, static_cast<int>(fb.segments.size()));
}

// A repeated motif (the same glyphs and boxes on a grid, plus sparse unique shapes): the ratio
// test and the mutual check must each remove wrong matches that plain nearest neighbours keep.
cv::Mat render_repetitive_canvas() {
  cv::Mat canvas(kCanvasHeight, kCanvasWidth, CV_8U, cv::Scalar(150));
  for (int y = 40; y < kCanvasHeight - 40; y += 70) {
    for (int x = 40; x < kCanvasWidth - 40; x += 90) {
      cv::rectangle(canvas, cv::Rect(x, y, 60, 40), cv::Scalar(40), 3, cv::LINE_AA);
      cv::putText(canvas, "K7", cv::Point(x + 10, y + 32), cv::FONT_HERSHEY_SIMPLEX, 0.9,
                  cv::Scalar(230), 2, cv::LINE_AA);
    }
  }
  cv::RNG rng(5);
  for (int k = 0; k < 25; ++k)
    cv::circle(canvas, rand_point(rng, kCanvasWidth, kCanvasHeight), rng.uniform(4, 15),
               cv::Scalar(rng.uniform(0, 256)), cv::FILLED, cv::LINE_AA);
  for (int k = 0; k < 25; ++k) {
    const cv::RotatedRect r(
        cv::Point2f(rng.uniform(0, kCanvasWidth), rng.uniform(0, kCanvasHeight)),
        cv::Size2f(rng.uniform(30, 120), rng.uniform(30, 120)),
        static_cast<float>(rng.uniform(0.0, 180.0)));
    cv::Point2f corners[4];
    r.points(corners);
    std::vector<cv::Point> polygon(corners, corners + 4);
    cv::fillConvexPoly(canvas, polygon, cv::Scalar(rng.uniform(0, 256)), cv::LINE_AA);
  }
  return canvas;
}

TEST(PointMatching, RatioAndMutualRemoveWrongMatchesOnRepetitiveScene) {
  const ViewPair v = make_views(render_repetitive_canvas(), 8.0, 0.9, 1e-4);
  for (const bool orb : {false, true}) {
    SCOPED_TRACE(orb ? "ORB" : "SIFT");
    const PointMatchingOptions base = orb ? video_point_matching_options() : PointMatchingOptions();
    const PointFeatures f1 = detect_point_features(v.image1, base);
    const PointFeatures f2 = detect_point_features(v.image2, base);
    auto wrong = [&](double ratio, bool mutual) {
      PointMatchingOptions options = base;
      options.ratio = ratio;
      options.mutual = mutual;
      int count = 0;
      for (const PointMatch& m : match_point_features(f1, f2, options))
        count += point_correct(v.H, m) ? 0 : 1;
      return count;
    };
    const int plain = wrong(1.0, false);
    std::printf("[   INFO   ] %s wrong matches: plain %d, ratio %d, mutual %d, both %d\n",
                orb ? "ORB" : "SIFT", plain, wrong(0.8, false), wrong(1.0, true), wrong(0.8, true));
    EXPECT_GT(plain, 20);  // the scene is ambiguous enough to test anything
    EXPECT_LT(wrong(0.8, false), plain / 2);
    EXPECT_LT(wrong(1.0, true), plain);
    EXPECT_LT(wrong(0.8, true), wrong(0.8, false) + 1);
  }
}

TEST(LineMatching, RatioMutualAndGeometryRemoveWrongMatchesOnRepetitiveScene) {
  const ViewPair v = make_views(render_repetitive_canvas(), 8.0, 0.9, 1e-4);
  const LineFeatures f1 = detect_line_features(v.image1);
  const LineFeatures f2 = detect_line_features(v.image2);
  auto count = [&](double ratio, bool mutual, bool geometric, int* correct) {
    LineMatchingOptions options;
    options.ratio = ratio;
    options.mutual = mutual;
    options.geometric_filter = geometric;
    int wrong = 0;
    *correct = 0;
    for (const LineMatch& m : match_line_features(f1, f2, options))
      (line_correct(v.H, m) ? *correct : wrong) += 1;
    return wrong;
  };
  int correct_plain, correct_ratio, correct_mutual, correct_both, correct_filtered;
  const int plain = count(1.0, false, false, &correct_plain);
  const int ratio = count(0.8, false, false, &correct_ratio);
  const int mutual = count(1.0, true, false, &correct_mutual);
  const int both = count(0.8, true, false, &correct_both);
  const int filtered = count(0.8, true, true, &correct_filtered);
  std::printf(
      "[   INFO   ] wrong/correct: plain %d/%d, ratio %d/%d, mutual %d/%d, both %d/%d, "
      "with the geometric filter %d/%d\n",
      plain, correct_plain, ratio, correct_ratio, mutual, correct_mutual, both, correct_both,
      filtered, correct_filtered);
  EXPECT_GT(plain, 20);
  EXPECT_LT(ratio, plain);
  EXPECT_LT(mutual, plain);
  EXPECT_LE(both, std::min(ratio, mutual));
  // The geometric filter leaves (almost) only correct matches, and more than the checks alone.
  EXPECT_LE(filtered, 0.1 * (filtered + correct_filtered));
  EXPECT_GT(correct_filtered, correct_both);
}

// The camera model.
CameraModel kitti_like_camera() {
  CameraModel c;
  c.pinhole = PinholeCamera(718.9, 716.5, 607.2, 185.2, 1241, 376);
  c.distortion = {-0.28, 0.074, 0.0008, -0.0003, -0.01};
  return c;
}

TEST(CameraModel, UndistortInvertsDistort) {
  const CameraModel camera = kitti_like_camera();
  EXPECT_TRUE(camera.valid());
  EXPECT_TRUE(camera.has_distortion());
  double worst = 0.0;
  for (double x = 0; x <= 1240; x += 40) {
    for (double y = 0; y <= 375; y += 25) {
      const Eigen::Vector2d p(x, y);
      worst = std::max(worst, (camera.distort(camera.undistort(p)) - p).norm());
      worst = std::max(worst, (camera.undistort(camera.distort(p)) - p).norm());
    }
  }
  EXPECT_LT(worst, 1e-6);
  CameraModel pinhole_only = camera;
  pinhole_only.distortion = {0, 0, 0, 0, 0};
  EXPECT_FALSE(pinhole_only.has_distortion());
  EXPECT_EQ(pinhole_only.undistort(Eigen::Vector2d(3, 4)), Eigen::Vector2d(3, 4));
  CameraModel broken = camera;
  broken.distortion[1] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(broken.valid());
}

TEST(CameraModel, UndistortAgreesWithOpenCv) {
  const CameraModel camera = kitti_like_camera();
  const cv::Matx33d K(camera.pinhole.fx, 0, camera.pinhole.cx, 0, camera.pinhole.fy,
                      camera.pinhole.cy, 0, 0, 1);
  const std::vector<double> D(camera.distortion.begin(), camera.distortion.end());
  std::vector<cv::Point2d> distorted, undistorted;
  for (double x = 0; x <= 1240; x += 62)
    for (double y = 0; y <= 375; y += 25) distorted.emplace_back(x, y);
  cv::undistortPoints(
      distorted, undistorted, K, D, cv::noArray(), K,
      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 1000, 1e-12));
  double worst = 0.0;
  for (size_t k = 0; k < distorted.size(); ++k) {
    const Eigen::Vector2d ours = camera.undistort({distorted[k].x, distorted[k].y});
    worst = std::max(worst, (ours - Eigen::Vector2d(undistorted[k].x, undistorted[k].y)).norm());
  }
  EXPECT_LT(worst, 1e-6);
  // And the forward model agrees with cv::projectPoints.
  std::vector<cv::Point3d> rays;
  for (const cv::Point2d& u : undistorted)
    rays.emplace_back((u.x - K(0, 2)) / K(0, 0), (u.y - K(1, 2)) / K(1, 1), 1.0);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, projected);
  for (size_t k = 0; k < rays.size(); ++k) {
    const Eigen::Vector2d ours = camera.distort({undistorted[k].x, undistorted[k].y});
    EXPECT_LT((ours - Eigen::Vector2d(projected[k].x, projected[k].y)).norm(), 1e-6);
  }
}

TEST(CameraModel, UndistortMatchesUndistortsEachImageWithItsCamera) {
  const CameraModel camera1 = kitti_like_camera();
  CameraModel camera2 = camera1;
  camera2.pinhole.fx = 500.0;
  camera2.distortion = {0.1, -0.02, 0.0, 0.001, 0.0};
  TwoViewMatches truth;
  truth.points.push_back({Eigen::Vector2d(100, 50), Eigen::Vector2d(900, 300)});
  truth.lines.push_back({LineSegment({10, 20}, {300, 40}), LineSegment({1000, 350}, {700, 10})});
  truth.vps.push_back(VpMatch());
  TwoViewMatches matches = truth;
  for (PointMatch& m : matches.points) {
    m.x1 = camera1.distort(m.x1);
    m.x2 = camera2.distort(m.x2);
  }
  for (LineMatch& m : matches.lines) {
    m.s1 = LineSegment(camera1.distort(m.s1.p1), camera1.distort(m.s1.p2));
    m.s2 = LineSegment(camera2.distort(m.s2.p1), camera2.distort(m.s2.p2));
  }
  undistort_matches(camera1, camera2, &matches);
  EXPECT_LT((matches.points[0].x1 - truth.points[0].x1).norm(), 1e-6);
  EXPECT_LT((matches.points[0].x2 - truth.points[0].x2).norm(), 1e-6);
  EXPECT_LT((matches.lines[0].s1.p2 - truth.lines[0].s1.p2).norm(), 1e-6);
  EXPECT_LT((matches.lines[0].s2.p1 - truth.lines[0].s2.p1).norm(), 1e-6);
  EXPECT_EQ(matches.vps[0].d1, truth.vps[0].d1);
  undistort_matches(camera1, camera2, nullptr);  // no crash
}

// A 150-degree equidistant lens on a 640 x 480 image (the renderer's fisheye), with real
// coefficients: theta_d = theta (1 - 0.02 theta^2 + 0.003 theta^4 ...).
CameraModel fisheye_150() {
  CameraModel c;
  c.model = LensModel::kEquidistant;
  c.distortion = {-0.02, 0.003, -0.0005, 0.0001, 0.0};
  const double half = 75.0 * M_PI / 180.0;
  const double theta_d = half * (1 - 0.02 * half * half + 0.003 * std::pow(half, 4) -
                                 0.0005 * std::pow(half, 6) + 0.0001 * std::pow(half, 8));
  const double f = 319.5 / theta_d;
  c.pinhole = PinholeCamera(f, f, 319.5, 239.5, 640, 480);
  return c;
}

cv::Matx33d K_of(const PinholeCamera& p) { return {p.fx, 0, p.cx, 0, p.fy, p.cy, 0, 0, 1}; }

TEST(CameraModel, EquidistantAgreesWithOpenCvFisheye) {
  const CameraModel camera = fisheye_150();
  EXPECT_TRUE(camera.has_distortion());
  EXPECT_EQ(camera_model_problem(camera), "");
  const cv::Vec4d D(camera.distortion[0], camera.distortion[1], camera.distortion[2],
                    camera.distortion[3]);
  // Forward: undistorted normalised points through cv::fisheye::distortPoints.
  std::vector<cv::Point2d> normalised, distorted;
  for (double x = -3.0; x <= 3.0; x += 0.25)
    for (double y = -2.0; y <= 2.0; y += 0.25) normalised.emplace_back(x, y);
  cv::fisheye::distortPoints(normalised, distorted, K_of(camera.pinhole), D);
  double worst = 0.0;
  for (size_t k = 0; k < normalised.size(); ++k) {
    const Eigen::Vector2d ours =
        camera.distort(camera.pinhole.denormalize({normalised[k].x, normalised[k].y}));
    worst = std::max(worst, (ours - Eigen::Vector2d(distorted[k].x, distorted[k].y)).norm());
  }
  EXPECT_LT(worst, 1e-6);
  // Backward: pixels whose rays are in front, through cv::fisheye::undistortPoints.
  std::vector<cv::Point2d> pixels, undistorted;
  for (double x = 0; x < 640; x += 40)
    for (double y = 0; y < 480; y += 40)
      if (camera.ray({x, y}).z() > 0.1) pixels.emplace_back(x, y);
  cv::fisheye::undistortPoints(pixels, undistorted, K_of(camera.pinhole), D, cv::noArray(),
                               K_of(camera.pinhole),
                               cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
                                                100, 1e-12));
  worst = 0.0;
  for (size_t k = 0; k < pixels.size(); ++k) {
    const Eigen::Vector2d ours = camera.undistort({pixels[k].x, pixels[k].y});
    worst = std::max(worst, (ours - Eigen::Vector2d(undistorted[k].x, undistorted[k].y)).norm());
  }
  EXPECT_LT(worst, 1e-4);
}

// Every pixel of the image: distort(undistort(p)) returns to p within 0.01 px where a pinhole
// pixel exists (rays less than 90 degrees off the axis), project(ray(p)) everywhere, and the
// pixels beyond 90 degrees (the 150-degree lens' corners reach 95) have no pinhole pixel.
TEST(CameraModel, EquidistantUndistortionRoundTripOverTheImage) {
  const CameraModel camera = fisheye_150();
  double worst = 0.0, worst_ray = 0.0, widest = 0.0;
  int pinhole_pixels = 0, beyond = 0;
  for (int y = 0; y < 480; ++y) {
    for (int x = 0; x < 640; ++x) {
      const Eigen::Vector2d p(x, y);
      const Eigen::Vector3d ray = camera.ray(p);
      ASSERT_TRUE(all_finite(ray)) << x << ", " << y;
      widest = std::max(widest, std::acos(ray.z()) * 180.0 / M_PI);
      Eigen::Vector2d back;
      ASSERT_TRUE(camera.project(3.0 * ray, &back));
      worst_ray = std::max(worst_ray, (back - p).norm());
      const Eigen::Vector2d u = camera.undistort(p);
      if (ray.z() > 1e-3) {
        ASSERT_TRUE(all_finite(u)) << x << ", " << y;
        worst = std::max(worst, (camera.distort(u) - p).norm());
        ++pinhole_pixels;
      } else if (ray.z() < -1e-3) {
        EXPECT_FALSE(all_finite(u)) << x << ", " << y;
        ++beyond;
      }
    }
  }
  EXPECT_LT(worst, 0.01);
  EXPECT_LT(worst_ray, 0.01);
  EXPECT_GT(widest, 93.0);  // the corners see behind the image plane
  EXPECT_LT(widest, 96.0);
  EXPECT_GT(beyond, 100);
  EXPECT_GT(pinhole_pixels, 300000);
  // The horizontal field of view is 150 degrees: the image's left and right edges at 75.
  EXPECT_NEAR(std::acos(camera.ray({319.5 - 319.5, 239.5}).z()) * 180.0 / M_PI, 75.0, 1e-6);
  // Matches beyond 90 degrees become NaN, which the estimator leaves out.
  TwoViewMatches matches;
  matches.points.push_back({Eigen::Vector2d(0, 0), Eigen::Vector2d(320, 240)});
  undistort_matches(camera, camera, &matches);
  EXPECT_FALSE(all_finite(matches.points[0].x1));
  EXPECT_TRUE(all_finite(matches.points[0].x2));
}

TEST(CameraModel, EquidistantCoefficientsThatFoldBackAreAProblem) {
  CameraModel camera = fisheye_150();
  camera.distortion = {-0.5, 0.0, 0.0, 0.0, 0.0};  // theta_d peaks at sqrt(2/3) rad
  EXPECT_NE(camera_model_problem(camera).find("fold back at 46.8 deg"), std::string::npos)
      << camera_model_problem(camera);
  camera.distortion[0] = std::nan("");
  EXPECT_EQ(camera_model_problem(camera), "a non-finite distortion coefficient");
  camera.distortion = {0, 0, 0, 0, 0};  // the ideal equidistant lens
  EXPECT_EQ(camera_model_problem(camera), "");
  EXPECT_TRUE(camera.has_distortion());
}

// Lines straight in space are curves in the fisheye image and straight again in the rectified
// view; the tables are built once per camera.
TEST(FisheyeRectifier, StraightLinesComeOutStraight) {
  const CameraModel camera = fisheye_150();
  cv::Mat fisheye(480, 640, CV_8UC1, cv::Scalar(0));
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> lines = {
      {{-3.0, -1.0, 2.0}, {3.0, -1.2, 2.5}},  // across the top, bent by the lens
      {{-1.5, -2.0, 3.0}, {-1.0, 2.0, 2.0}},
      {{1.2, 1.5, 1.5}, {2.5, -1.0, 4.0}}};
  for (const auto& [a, b] : lines) {
    std::vector<cv::Point> curve;
    for (int k = 0; k <= 400; ++k) {
      Eigen::Vector2d p;
      ASSERT_TRUE(camera.project(a + (b - a) * k / 400.0, &p));
      curve.emplace_back(static_cast<int>(std::lround(p.x() * 16)),
                         static_cast<int>(std::lround(p.y() * 16)));
    }
    cv::polylines(fisheye, curve, false, cv::Scalar(255), 2, cv::LINE_AA, 4);
  }
  FisheyeRectifier rectifier(100.0);
  cv::Mat rectified;
  CameraModel view;
  std::string reason;
  ASSERT_TRUE(rectifier.rectify(camera, Eigen::Matrix3d::Identity(), fisheye, &rectified, &view,
                                &reason))
      << reason;
  EXPECT_FALSE(view.has_distortion());
  EXPECT_NEAR(view.pinhole.fx, 320.0 / std::tan(50.0 * M_PI / 180.0), 1e-9);
  cv::Mat intensity;
  rectified.convertTo(intensity, CV_32F);
  for (const auto& [a, b] : lines) {
    // Across the straight line between the endpoints' pinhole pixels, the drawn curve's centre
    // (the intensity centroid within 10 px) lies on it.
    const Eigen::Vector2d pa = view.pinhole.denormalize(a.head<2>() / a.z());
    const Eigen::Vector2d pb = view.pinhole.denormalize(b.head<2>() / b.z());
    const Eigen::Vector2d normal = Eigen::Vector2d(pa.y() - pb.y(), pb.x() - pa.x()).normalized();
    int inside = 0;
    double worst = 0.0;
    for (int k = 1; k < 100; ++k) {
      const Eigen::Vector2d p = pa + (pb - pa) * k / 100.0;
      if (p.x() < 12 || p.y() < 12 || p.x() > 627 || p.y() > 467) continue;
      ++inside;
      double sum = 0.0, moment = 0.0;
      for (double d = -10.0; d <= 10.0; d += 0.25) {
        const Eigen::Vector2d q = p + d * normal;
        cv::Mat patch;
        cv::getRectSubPix(intensity, cv::Size(1, 1), cv::Point2f(q.x(), q.y()), patch);
        sum += patch.at<float>(0, 0);
        moment += d * patch.at<float>(0, 0);
      }
      ASSERT_GT(sum, 0.0) << "no line near " << p.transpose();
      worst = std::max(worst, std::abs(moment / sum));
    }
    EXPECT_GT(inside, 30);
    EXPECT_LT(worst, 0.5);
  }
  // Same camera: no new tables; another one (or another rotation): new tables.
  ASSERT_TRUE(rectifier.rectify(camera, Eigen::Matrix3d::Identity(), fisheye, &rectified, &view,
                                &reason));
  EXPECT_EQ(rectifier.maps_built(), 1);
  CameraModel other = camera;
  other.distortion[0] = -0.021;
  ASSERT_TRUE(rectifier.rectify(other, Eigen::Matrix3d::Identity(), fisheye, &rectified, &view,
                                &reason));
  EXPECT_EQ(rectifier.maps_built(), 2);
  // Refused: a pinhole camera, an image of another size, a field of view of 180 degrees.
  EXPECT_FALSE(rectifier.rectify(kitti_like_camera(), Eigen::Matrix3d::Identity(), fisheye,
                                 &rectified, &view, &reason));
  EXPECT_FALSE(rectifier.rectify(camera, Eigen::Matrix3d::Identity(), fisheye(cv::Rect(0, 0, 320, 240)),
                                 &rectified, &view, &reason));
  EXPECT_EQ(reason, "the image is not the camera's size");
  FisheyeRectifier flat(180.0);
  EXPECT_FALSE(flat.rectify(camera, Eigen::Matrix3d::Identity(), fisheye, &rectified, &view,
                            &reason));
}

// Degenerate input: empty results, no crash.
// Issue 30, white panels: a dark last row and column (TUM's Kinect frames) are no scene lines;
// panel edges of a few grey levels are found only when the threshold follows the contrast; and
// a faint edge that breaks up is joined again.
TEST(LineDetection, IgnoresTheImageBorderAndFindsFaintEdgesWhole) {
  cv::Mat image(240, 320, CV_8UC1, cv::Scalar(120));
  cv::rectangle(image, cv::Rect(80, 60, 140, 110), cv::Scalar(126), cv::FILLED);  // faint panel
  image.row(image.rows - 1).setTo(25);
  image.col(image.cols - 1).setTo(25);
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  LineDetectionOptions options;
  options.min_length_px = 30.0;
  options.detector = LineDetector::kLsd;  // LSD finds the border's edge (FLD's Canny does not)
  for (const LineSegment& s : detect_line_segments(image, options))
    EXPECT_FALSE(along_image_border(s, image.cols, image.rows, 2.0))
        << s.p1.transpose() << " - " << s.p2.transpose();
  options.border_margin_px = 0.0;
  int along = 0;
  for (const LineSegment& s : detect_line_segments(image, options))
    along += along_image_border(s, image.cols, image.rows, 2.0);
  EXPECT_GE(along, 1) << "the border is an edge to the detector itself";

  options.detector = LineDetector::kFld;
  options.border_margin_px = 2.0;
  EXPECT_TRUE(detect_line_segments(image, options).empty()) << "6 grey levels: below FLD's 50";
  options.adapt_to_contrast = true;
  EXPECT_LT(line_gradient_threshold(image, options), kFldDefaultGradient);
  const std::vector<LineSegment> faint = detect_line_segments(image, options);
  EXPECT_GE(faint.size(), 4u);
  double longest = 0.0;
  for (const LineSegment& s : faint) longest = std::max(longest, s.length());
  EXPECT_GT(longest, 100.0);
  // A strong image keeps the detector's own threshold.
  cv::Mat strong(240, 320, CV_8UC1, cv::Scalar(40));
  cv::rectangle(strong, cv::Rect(80, 60, 140, 110), cv::Scalar(220), cv::FILLED);
  EXPECT_DOUBLE_EQ(line_gradient_threshold(strong, options), kFldDefaultGradient);

  // A dashed edge, 40 px pieces 8 px apart, is one segment once joined; a parallel edge 6 px
  // away is another.
  std::vector<LineSegment> pieces;
  for (int k = 0; k < 5; ++k)
    pieces.push_back(LineSegment({20.0 + 48 * k, 100.0}, {60.0 + 48 * k, 100.4}));
  pieces.push_back(LineSegment({20.0, 106.0}, {200.0, 106.0}));
  options.merge_collinear = true;
  const std::vector<LineSegment> joined = merge_collinear_segments(pieces, options);
  ASSERT_EQ(joined.size(), 2u);
  const LineSegment& dashed = joined[0].midpoint().y() < joined[1].midpoint().y() ? joined[0]
                                                                                 : joined[1];
  const LineSegment& parallel = &dashed == &joined[0] ? joined[1] : joined[0];
  EXPECT_NEAR(dashed.length(), 232.0, 1.0);
  EXPECT_NEAR(dashed.midpoint().y(), 100.2, 0.3);
  EXPECT_NEAR(parallel.midpoint().y(), 106.0, 1e-9);
  options.merge_gap_px = 5.0;
  EXPECT_EQ(merge_collinear_segments(pieces, options).size(), 6u);
}

TEST(FrontendMatching, EmptyAndBlackImagesGiveEmptyResults) {
  const cv::Mat empty, black(kHeight, kWidth, CV_8U, cv::Scalar(0));
  const cv::Mat black_bgr(kHeight, kWidth, CV_8UC3, cv::Scalar(0, 0, 0));
  for (const PointMatchingOptions& options :
       {PointMatchingOptions(), video_point_matching_options()}) {
    for (const cv::Mat* image : {&empty, &black, &black_bgr}) {
      const PointFeatures f = detect_point_features(*image, options);
      EXPECT_TRUE(f.keypoints.empty());
      EXPECT_TRUE(match_point_features(f, f, options).empty());
    }
  }
  const ViewPair v = scene_for(0);
  const PointFeatures textured = detect_point_features(v.image1);
  ASSERT_FALSE(textured.keypoints.empty());
  EXPECT_TRUE(match_point_features(textured, PointFeatures()).empty());
  EXPECT_TRUE(match_point_features(PointFeatures(), textured).empty());

  for (const LineMatchingOptions& options :
       {LineMatchingOptions(), video_line_matching_options()}) {
    for (const cv::Mat* image : {&empty, &black, &black_bgr}) {
      const LineFeatures f = detect_line_features(*image, options);
      EXPECT_TRUE(f.segments.empty());
      EXPECT_TRUE(f.descriptors.empty());
      EXPECT_TRUE(match_line_features(f, f, options).empty());
    }
  }
  const std::vector<LineSegment> segments = {LineSegment({10, 10}, {200, 100})};
  std::vector<int> kept = {42};
  EXPECT_TRUE(describe_line_segments(black, segments, &kept).segments.empty());
  EXPECT_TRUE(kept.empty());
  EXPECT_TRUE(describe_line_segments(empty, segments, &kept).segments.empty());
  EXPECT_TRUE(describe_line_segments(v.image1, {}, &kept).segments.empty());
  const LineFeatures lines = detect_line_features(v.image1);
  ASSERT_FALSE(lines.segments.empty());
  std::vector<std::pair<int, int>> pairs = {{1, 2}};
  EXPECT_TRUE(match_line_features(lines, LineFeatures(), {}, &pairs).empty());
  EXPECT_TRUE(pairs.empty());
  // Descriptors of different forms do not match each other.
  LineDescriptionOptions binary;
  binary.float_descriptor = false;
  const LineFeatures other = describe_line_segments(v.image1, lines.segments, nullptr, binary);
  EXPECT_TRUE(match_line_features(lines, other).empty());
}

}  // namespace
}  // namespace hybrid_vo
