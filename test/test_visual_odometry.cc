// The video front end on a rendered sequence: the threaded front end gives exactly the matches
// and poses of the sequential one, line tracking is as correct as full LBD matching and finds
// at least as many matches, and the worker thread and the tracker behave at their edges.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/frontend/line_tracker.h"
#include "hybrid_vo/frontend/visual_odometry.h"
#include "hybrid_vo/frontend/worker_thread.h"
#include "hybrid_vo/render/sequence.h"

namespace {

using namespace hybrid_vo;
using namespace hybrid_vo::render;

constexpr int kFrames = 14;

// A short rendered stereo corridor, shared by the tests (rendering dominates their time).
class VideoFrontEnd : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SequenceOptions options;
    options.out_bag = "unused.bag";
    options.frames = kFrames;
    options.stereo = true;
    options.supersampling = 1;
    sequence_ = new Sequence(make_sequence(options));
    left_ = new std::vector<RenderedView>();
    right_ = new std::vector<cv::Mat>();
    for (int i = 0; i < kFrames; ++i) {
      left_->push_back(render_frame(*sequence_, i));
      right_->push_back(render_frame(*sequence_, i, true).image);
    }
  }
  static void TearDownTestSuite() {
    delete sequence_;
    delete left_;
    delete right_;
  }

  static VisualOdometryInput input(int i, bool stereo) {
    VisualOdometryInput in;
    in.stamp = 1.0 + i / sequence_->options.rate;
    in.image = (*left_)[i].image;
    in.camera.pinhole = sequence_->camera;
    if (stereo) {
      in.right_image = (*right_)[i];
      in.baseline_m = sequence_->options.baseline;
    }
    return in;
  }

  static Sequence* sequence_;
  static std::vector<RenderedView>* left_;
  static std::vector<cv::Mat>* right_;
};

Sequence* VideoFrontEnd::sequence_ = nullptr;
std::vector<RenderedView>* VideoFrontEnd::left_ = nullptr;
std::vector<cv::Mat>* VideoFrontEnd::right_ = nullptr;

bool same_points(const std::vector<PointMatch>& a, const std::vector<PointMatch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k)
    if (a[k].x1 != b[k].x1 || a[k].x2 != b[k].x2) return false;
  return true;
}

bool same_lines(const std::vector<LineMatch>& a, const std::vector<LineMatch>& b) {
  if (a.size() != b.size()) return false;
  for (size_t k = 0; k < a.size(); ++k)
    if (a[k].s1.p1 != b[k].s1.p1 || a[k].s1.p2 != b[k].s1.p2 || a[k].s2.p1 != b[k].s2.p1 ||
        a[k].s2.p2 != b[k].s2.p2)
      return false;
  return true;
}

// Runs the whole sequence twice, threaded and sequential, and compares frame by frame.
void expect_threaded_equals_sequential(const std::vector<VisualOdometryInput>& inputs,
                                       bool track_lines) {
  VisualOdometryOptions threaded, sequential;
  threaded.track_lines = sequential.track_lines = track_lines;
  threaded.concurrent = true;
  sequential.concurrent = false;
  VisualOdometry a(threaded), b(sequential);
  int estimated = 0, with_lines = 0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const VisualOdometryResult ra = a.process(inputs[i]);
    const VisualOdometryResult rb = b.process(inputs[i]);
    ASSERT_EQ(ra.status, rb.status) << "frame " << i;
    EXPECT_TRUE(same_points(ra.matches.points, rb.matches.points)) << "frame " << i;
    EXPECT_TRUE(same_lines(ra.matches.lines, rb.matches.lines)) << "frame " << i;
    EXPECT_EQ(ra.num_line_matches, rb.num_line_matches) << "frame " << i;
    EXPECT_EQ(ra.R_wc, rb.R_wc) << "frame " << i;
    EXPECT_EQ(ra.centre, rb.centre) << "frame " << i;
    EXPECT_EQ(ra.scale_known, rb.scale_known) << "frame " << i;
    estimated += ra.status == VoStatus::kOk;
    with_lines += ra.num_line_matches >= 20;
  }
  // The comparison means something only when frames were estimated with many segments.
  EXPECT_GE(estimated, static_cast<int>(inputs.size()) / 2);
  EXPECT_GE(with_lines, static_cast<int>(inputs.size()) / 2);
}

TEST_F(VideoFrontEnd, ThreadedFrontEndGivesTheSequentialMatchesAndPoses) {
  std::vector<VisualOdometryInput> mono, stereo;
  for (int i = 0; i < kFrames; ++i) {
    mono.push_back(input(i, false));
    stereo.push_back(input(i, true));
  }
  expect_threaded_equals_sequential(mono, true);
  expect_threaded_equals_sequential(mono, false);
  expect_threaded_equals_sequential(stereo, true);
}

// Distance in pixels from the rendered ground truth: a keyframe segment's endpoints carried into
// the current view by their depth, against the matched segment's line.
double line_error_px(const RenderedView& view1, const CameraPose& pose1, const CameraPose& pose2,
                     const PinholeCamera& cam, const LineMatch& m) {
  double worst = 0.0;
  const Eigen::Vector3d l2 = line_through(m.s2.p1, m.s2.p2);
  for (double t : {0.1, 0.9}) {
    // Inside the segment: its endpoints sit on the depth edge that makes it.
    const Eigen::Vector2d p = m.s1.p1 + t * (m.s1.p2 - m.s1.p1);
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    if (x < 0 || y < 0 || x >= view1.depth.cols || y >= view1.depth.rows) return -1.0;
    const float z = view1.depth.at<float>(y, x);
    if (!(z > 0.0f)) return -1.0;
    const Eigen::Vector3d ray((p.x() - cam.cx) / cam.fx, (p.y() - cam.cy) / cam.fy, 1.0);
    const Eigen::Vector3d X = pose1.to_world(ray * z);
    const Eigen::Vector3d Xc = pose2.to_camera(X);
    if (Xc.z() <= 0.0) return -1.0;
    const Eigen::Vector2d q(cam.fx * Xc.x() / Xc.z() + cam.cx, cam.fy * Xc.y() / Xc.z() + cam.cy);
    worst = std::max(worst, std::abs(l2.dot(homogeneous(q))));
  }
  return worst;
}

TEST_F(VideoFrontEnd, LineTrackingIsAsCorrectAsLbdMatchingAndFindsMore) {
  const PinholeCamera& cam = sequence_->camera;
  const LineMatchingOptions matching = video_line_matching_options();
  KltTracker klt;
  int lbd_total = 0, lbd_wrong = 0, tracked_total = 0, tracked_wrong = 0, by_search = 0;
  klt.track((*left_)[0].image);
  LineFeatures previous = detect_line_features((*left_)[0].image, matching);
  for (int i = 1; i < kFrames; ++i) {
    const std::vector<PointMatch> points = klt.track((*left_)[i].image);
    const LineFeatures current = detect_line_features((*left_)[i].image, matching);
    LineTrackingStats stats;
    const std::vector<LineMatch> tracked =
        track_line_segments(previous, current, points, matching, {}, &stats);
    const std::vector<LineMatch> lbd = match_line_features(previous, current, matching);
    const CameraPose pose1 = frame_pose(*sequence_, i - 1), pose2 = frame_pose(*sequence_, i);
    for (const auto& [matches, total, wrong] :
         {std::tie(tracked, tracked_total, tracked_wrong), std::tie(lbd, lbd_total, lbd_wrong)}) {
      for (const LineMatch& m : matches) {
        const double e = line_error_px((*left_)[i - 1], pose1, pose2, cam, m);
        if (e < 0.0) continue;  // no depth under it
        ++total;
        wrong += e > 3.0;
      }
    }
    EXPECT_EQ(stats.tracked + stats.fallback, static_cast<int>(tracked.size()));
    EXPECT_LE(stats.ambiguous, stats.tracked);
    by_search += stats.tracked;
    previous = current;
  }
  ASSERT_GT(lbd_total, 100);
  EXPECT_GE(tracked_total, lbd_total);
  // Precision no worse than LBD's (one wrong match of slack on ~100s of matches).
  EXPECT_LE(static_cast<double>(tracked_wrong) / tracked_total,
            static_cast<double>(lbd_wrong + 1) / lbd_total)
      << tracked_wrong << " of " << tracked_total << " vs " << lbd_wrong << " of " << lbd_total;
  // Most matches come from the search, not the fallback.
  EXPECT_GT(by_search, tracked_total / 2);
}

TEST(LineTracker, WithoutPointMatchesItIsFullLbdMatching) {
  cv::Mat image(240, 320, CV_8UC1, cv::Scalar(40));
  cv::rectangle(image, cv::Rect(60, 50, 120, 90), cv::Scalar(200), cv::FILLED);
  cv::rectangle(image, cv::Rect(200, 120, 80, 80), cv::Scalar(120), cv::FILLED);
  cv::line(image, cv::Point(20, 220), cv::Point(300, 200), cv::Scalar(230), 3);
  const LineMatchingOptions matching = video_line_matching_options();
  const LineFeatures a = detect_line_features(image, matching);
  ASSERT_GT(a.segments.size(), 4u);
  std::vector<std::pair<int, int>> tracked_pairs, lbd_pairs;
  LineTrackingStats stats;
  track_line_segments(a, a, {}, matching, {}, &stats, &tracked_pairs);
  match_line_features(a, a, matching, &lbd_pairs);
  EXPECT_EQ(tracked_pairs, lbd_pairs);
  EXPECT_EQ(stats.predicted, 0);
  EXPECT_EQ(stats.fallback, static_cast<int>(lbd_pairs.size()));
  // And without the fallback, nothing.
  LineTrackingOptions no_fallback;
  no_fallback.descriptor_fallback = false;
  EXPECT_TRUE(track_line_segments(a, a, {}, matching, no_fallback).empty());
  // Empty inputs give no matches.
  EXPECT_TRUE(track_line_segments(LineFeatures(), a, {}, matching).empty());
  EXPECT_TRUE(track_line_segments(a, LineFeatures(), {}, matching).empty());
}

TEST(WorkerThread, RunsJobsInOrderAndRethrowsTheirErrors) {
  for (const bool concurrent : {true, false}) {
    WorkerThread worker(concurrent);
    EXPECT_EQ(worker.concurrent(), concurrent);
    std::vector<int> order;
    {
      WorkerJob first = worker.submit([&] { order.push_back(1); });
      WorkerJob second = worker.submit([&] { order.push_back(2); });
      second.get();
      first.get();
    }
    EXPECT_EQ(order, (std::vector<int>{1, 2}));
    WorkerJob failing = worker.submit([] { throw std::runtime_error("job failed"); });
    EXPECT_THROW(failing.get(), std::runtime_error);
    // An empty handle waits for nothing; the worker still runs jobs after a failure.
    WorkerJob empty;
    EXPECT_NO_THROW(empty.get());
    int value = 0;
    worker.submit([&] { value = 7; }).get();
    EXPECT_EQ(value, 7);
  }
}

}  // namespace
