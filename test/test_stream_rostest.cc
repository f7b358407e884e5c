// rostests of the node under faults in its input stream (test/node_faults.test) and under
// overload (test/node_overload.test, the nodelet): rendered frames are published like a camera
// driver or a bag replay would, and the test asserts on ~relative_pose and /diagnostics.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

#include "hybrid_vo/geometry/pose_covariance.h"
#include "hybrid_vo/render/sequence.h"
#include "node_test_utils.h"

namespace hybrid_vo {
namespace {

using testing::covariance_of;
using testing::diagnostic_value;
using testing::image_of;
using testing::info_of;
using testing::NodeHarness;
using testing::publish_static_camera;
using testing::unknown;

const char kFrame[] = "camera_left_optical";

render::Sequence make(int width, int height, int frames) {
  render::SequenceOptions options;
  options.out_bag = "unused.bag";
  options.frames = frames;
  options.width = width;
  options.height = height;
  options.supersampling = 1;
  return render::make_sequence(options);
}

// ------------------------------------------------------------------------------------------------
// Faults

// One fault: where it sits in the answers, what it must add to which diagnostics counter, and how
// many good frames the node needed after it to publish a motion (STATUS_OK) again.
struct Fault {
  std::string name, counter;
  size_t first_answer = 0;  // index into received_ of the first answer after the fault
  bool restarts = true;     // the chain must not be paired across it
  int recovery_frames = -1;
};

class FaultRun {
 public:
  FaultRun() : seq_(make(320, 240, 200)), small_(make(240, 180, 200)) {}

  NodeHarness& harness() { return h_; }
  double stamp() const { return stamp_; }

  // Publishes frame `index` of `seq` at `stamp` and waits for the node's answer.
  const MotionEstimate* good(int index, double stamp, const render::Sequence* seq = nullptr) {
    if (!seq) seq = &seq_;
    const size_t before = h_.received_.size();
    const ros::Time t(stamp);
    h_.left_.publish(image_of(render::render_frame(*seq, index).image, t, kFrame));
    h_.left_info_.publish(info_of(seq->camera, t, kFrame));
    stamp_ = stamp;
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(20.0);
    while (ros::ok() && ros::WallTime::now() < end) {
      ros::spinOnce();
      for (size_t i = before; i < h_.received_.size(); ++i)
        if (h_.received_[i].header.stamp == t) return &h_.received_[i];
      ros::WallDuration(0.005).sleep();
    }
    return nullptr;
  }

  // Good frames from `index` on, 0.1 s apart from `stamp`, until one has a motion (at most
  // `limit`); the number of frames it took, or -1.
  int recover(int* index, double stamp, int limit, const render::Sequence* seq = nullptr) {
    for (int k = 1; k <= limit; ++k) {
      const MotionEstimate* m = good((*index)++, stamp + 0.1 * (k - 1), seq);
      if (!m) {
        ADD_FAILURE() << "no answer for the frame at " << stamp + 0.1 * (k - 1);
        return -1;
      }
      if (m->status == MotionEstimate::STATUS_OK) return k;
    }
    return -1;
  }

  double counter(const std::string& key) {
    h_.spin_for(2.0);  // diagnostics go out once a second, from a 0.5 s timer
    return diagnostic_value(h_.last_odometry_status_, key);
  }

 private:
  render::Sequence seq_, small_;
  NodeHarness h_;
  double stamp_ = 0.0;

 public:
  const render::Sequence& small() const { return small_; }
};

// Each fault of the issue during one replay: the node counts it in diagnostics, publishes no
// motion between frames on both sides of it, and is back to STATUS_OK (and diagnostics OK) within
// kRecoveryFrames good frames.
TEST(Faults, EachFaultIsCountedAndRecoveredFrom) {
  constexpr int kRecoveryFrames = 3;
  FaultRun run;
  NodeHarness& h = run.harness();
  ASSERT_TRUE(h.wait_for_node());
  publish_static_camera(&h);
  h.spin_for(0.5);
  std::vector<Fault> faults;
  int index = 0;
  // A clean start.
  for (int k = 0; k < 8; ++k) ASSERT_NE(run.good(index++, 1.0 + 0.1 * k), nullptr);
  EXPECT_EQ(h.received_.back().status, MotionEstimate::STATUS_OK) << h.received_.back().status_text;

  // Recovery after a fault, whose counter was `before` before it happened (< 0: read it now, for
  // the faults that the node counts at the next good frame).
  auto check_fault = [&](Fault fault, double stamp, const render::Sequence* seq = nullptr,
                         double before = -1.0) {
    SCOPED_TRACE(fault.name);
    if (before < 0) before = run.counter(fault.counter);
    fault.first_answer = h.received_.size();
    fault.recovery_frames = run.recover(&index, stamp, kRecoveryFrames + 2, seq);
    EXPECT_GE(fault.recovery_frames, 1);
    EXPECT_LE(fault.recovery_frames, kRecoveryFrames);
    if (fault.restarts) {
      // The first frame after the fault starts a new chain; its answer names the fault.
      const MotionEstimate& first = h.received_.at(fault.first_answer);
      EXPECT_EQ(first.status, MotionEstimate::STATUS_SKIPPED) << first.status_text;
    }
    const double after = run.counter(fault.counter);
    EXPECT_EQ(h.last_odometry_status_.level, diagnostic_msgs::DiagnosticStatus::OK)
        << h.last_odometry_status_.message;
    if (fault.restarts) {
      // The pose after the fault is published as lost: its covariances say "unknown".
      const auto lost = h.odometry_.find(h.received_.at(fault.first_answer).header.stamp);
      EXPECT_TRUE(lost != h.odometry_.end() && unknown(lost->second.pose.covariance) &&
                  unknown(lost->second.twist.covariance));
    }
    faults.push_back(fault);
    return after - before;
  };

  // 1. The camera_info publisher dies for 2.5 s (25 frames) and comes back.
  {
    Fault f{"camera_info publisher killed and restarted", "camera_info outages"};
    const double outages = run.counter("camera_info outages");
    h.left_info_.shutdown();
    const cv::Mat image = render::render_frame(make(320, 240, 1), 0).image;
    double t = run.stamp();
    for (int k = 0; k < 25; ++k) {
      t += 0.1;
      h.left_.publish(image_of(image, ros::Time(t), kFrame));
      h.spin_for(0.1);
      ++index;  // the camera moves on
    }
    EXPECT_EQ(h.last_odometry_status_.level, diagnostic_msgs::DiagnosticStatus::ERROR);
    EXPECT_NE(h.last_odometry_status_.message.find("camera_info"), std::string::npos)
        << h.last_odometry_status_.message;
    EXPECT_EQ(run.counter("camera_info outages"), outages + 1);
    ros::NodeHandle nh;
    h.left_info_ = nh.advertise<sensor_msgs::CameraInfo>("camera/left/camera_info", 5);
    ASSERT_TRUE(h.wait_for_node());
    h.spin_for(0.3);
    f.counter = "time gaps (restarts)";  // the outage left a 2.5 s gap in the frames
    EXPECT_EQ(check_fault(f, t + 0.1), 1.0);
  }

  // 2. A burst of corrupt images: truncated data, a step shorter than a row, an unknown
  // encoding, no pixels.
  {
    const double bad = run.counter("bad images");
    double t = run.stamp();
    const sensor_msgs::Image good = image_of(render::render_frame(make(320, 240, 1), 0).image,
                                             ros::Time(t), kFrame);
    std::vector<std::function<void(sensor_msgs::Image*)>> corruptions = {
        [](sensor_msgs::Image* m) { m->data.resize(m->data.size() / 2); },
        [](sensor_msgs::Image* m) { m->step = m->width / 2; },
        [](sensor_msgs::Image* m) { m->encoding = "32FC7"; },
        [](sensor_msgs::Image* m) { m->width = m->height = m->step = 0; },
        [](sensor_msgs::Image* m) { m->height *= 3; },
    };
    for (const auto& corrupt : corruptions) {
      t += 0.1;
      sensor_msgs::Image m = good;
      m.header.stamp = ros::Time(t);
      corrupt(&m);
      h.left_.publish(m);
      h.left_info_.publish(info_of(make(320, 240, 1).camera, ros::Time(t), kFrame));
      h.spin_for(0.15);
      ++index;
    }
    EXPECT_EQ(run.counter("bad images"), bad + corruptions.size());
    EXPECT_EQ(h.last_odometry_status_.level, diagnostic_msgs::DiagnosticStatus::ERROR);
    EXPECT_EQ(check_fault({"burst of corrupt images", "restarts after rejected input"}, t + 0.1),
              1.0);
  }

  // 3. Time jumps backwards: the bag loops to its first frame (new, earlier stamps).
  {
    index = 0;
    EXPECT_EQ(check_fault({"time backwards (bag loop)", "time jumps (resets)"}, 0.55), 1.0);
    EXPECT_NE(h.received_.at(faults.back().first_answer).status_text.find("backwards"),
              std::string::npos);
  }

  // 4. Time jumps forwards by 10 s.
  {
    const double t = run.stamp() + 10.0;
    EXPECT_EQ(check_fault({"time forwards by 10 s", "time gaps (restarts)"}, t), 1.0);
    EXPECT_NE(h.received_.at(faults.back().first_answer).status_text.find("forwards by 10"),
              std::string::npos)
        << h.received_.at(faults.back().first_answer).status_text;
  }

  // 5. Duplicate stamps (another image under the last frame's stamp), then a late frame: both
  // skipped without an answer; the stream goes on without a restart.
  {
    const double t = run.stamp();
    const double late = run.counter("late frames skipped");
    const double duplicates = run.counter("duplicate stamps skipped");
    const size_t answers = h.received_.size();
    const ros::Time stamp(t);
    h.left_.publish(image_of(render::render_frame(make(320, 240, 200), index).image, stamp, kFrame));
    h.left_info_.publish(info_of(make(320, 240, 1).camera, stamp, kFrame));
    h.spin_for(0.4);
    h.left_.publish(image_of(render::render_frame(make(320, 240, 200), index).image,
                             ros::Time(t - 0.05), kFrame));
    h.left_info_.publish(info_of(make(320, 240, 1).camera, ros::Time(t - 0.05), kFrame));
    h.spin_for(0.4);
    EXPECT_EQ(h.received_.size(), answers) << "a duplicate or late frame was answered";
    EXPECT_EQ(run.counter("late frames skipped"), late + 1);
    Fault f{"duplicate stamps", "duplicate stamps skipped"};
    f.restarts = false;
    EXPECT_EQ(check_fault(f, t + 0.1, nullptr, duplicates), 1.0);
  }

  // 6. An image lost on the way: its camera_info arrives alone. The synchroniser gives the frame
  // up once the next one completes, and it is counted; the stream goes on without a restart.
  {
    const double incomplete = run.counter("incomplete frames dropped");
    const double t = run.stamp() + 0.1;
    h.left_info_.publish(info_of(make(320, 240, 1).camera, ros::Time(t), kFrame));
    ++index;
    h.spin_for(0.3);
    Fault f{"image lost in transport", "incomplete frames dropped"};
    f.restarts = false;
    EXPECT_EQ(check_fault(f, t + 0.1, nullptr, incomplete), 1.0);
  }

  // 7. The image size switches mid-stream (another camera_info too): 240x180 from here on.
  EXPECT_EQ(check_fault({"image size switched", "image size changes (restarts)"},
                        run.stamp() + 0.1, &run.small()),
            1.0);

  // No motion was estimated across a restarting fault: every motion after it pairs two frames
  // answered after it.
  for (size_t f = 0; f < faults.size(); ++f) {
    if (!faults[f].restarts) continue;
    const size_t begin = faults[f].first_answer;
    const size_t end = f + 1 < faults.size() ? faults[f + 1].first_answer : h.received_.size();
    for (size_t j = begin; j < end; ++j) {
      const MotionEstimate& m = h.received_[j];
      if (m.status != MotionEstimate::STATUS_OK) continue;
      bool inside = false;
      for (size_t i = begin; i < j; ++i) inside = inside || h.received_[i].header.stamp == m.reference_stamp;
      EXPECT_TRUE(inside) << faults[f].name << ": the motion at " << m.header.stamp
                          << " pairs with " << m.reference_stamp << ", before the fault";
    }
  }
  // Every other pose carries a covariance, known once the chain has moved.
  int known = 0;
  for (const auto& [stamp, o] : h.odometry_) {
    EXPECT_TRUE(is_covariance(covariance_of(o.pose.covariance))) << stamp;
    EXPECT_TRUE(is_covariance(covariance_of(o.twist.covariance))) << stamp;
    known += !unknown(o.pose.covariance) && !unknown(o.twist.covariance);
  }
  EXPECT_GE(known, static_cast<int>(h.odometry_.size()) - 3 * static_cast<int>(faults.size()));
  // Frames are paired in order everywhere.
  for (const MotionEstimate& m : h.received_) {
    if (m.status == MotionEstimate::STATUS_OK) {
      EXPECT_LT(m.reference_stamp, m.header.stamp);
    }
  }

  std::string table;
  for (const Fault& f : faults) {
    table += f.name + ": " + std::to_string(f.recovery_frames) + " frames; ";
    RecordProperty("recovery_frames " + f.name, std::to_string(f.recovery_frames));
  }
  std::printf("recovery (good frames until a motion is published again): %s\n", table.c_str());
}

// ------------------------------------------------------------------------------------------------
// Overload

// Publishes KITTI-sized frames at twice the rate the node sustains: the node must drop the oldest
// frames, count every one, start each frame it processes at most one period after it was sent,
// and pair frames in order.
TEST(Overload, DropsTheOldestCountsEveryFrameAndBoundsLatency) {
  using Clock = std::chrono::steady_clock;
  auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
  const render::Sequence seq = make(1241, 376, 40);
  std::vector<sensor_msgs::Image> images;
  for (int i = 0; i < 40; ++i)
    images.push_back(image_of(render::render_frame(seq, i).image, ros::Time(1.0), kFrame));
  // Back and forth along the walk, so that every frame is a plausible successor.
  auto frame_of = [&](int k) {
    const int i = k % 78;
    return i < 40 ? i : 78 - i;
  };
  NodeHarness h;
  ASSERT_TRUE(h.wait_for_node());
  publish_static_camera(&h);
  h.spin_for(0.5);
  std::map<ros::Time, Clock::time_point> sent;
  double stamp = 1.0;
  int k = 0;
  auto publish = [&](double period) {
    sensor_msgs::Image image = images[frame_of(k++)];
    image.header.stamp = ros::Time(stamp);
    sent[image.header.stamp] = Clock::now();
    h.left_.publish(image);
    h.left_info_.publish(info_of(seq.camera, image.header.stamp, kFrame));
    stamp += period;
    return image.header.stamp;
  };

  // The sustainable rate: in lock-step (each frame published once the previous one was
  // answered), the rate the median cycle allows. Not a slower quantile: a load spike on the
  // machine during this measurement would then halve the rate, and the node would keep up with
  // twice it once the spike is over (a CI run beside benchmarks did: 509 passed, this failed).
  std::vector<double> cycles_ms;
  for (int i = 0; i < 25; ++i) {
    const Clock::time_point t0 = Clock::now();
    ASSERT_TRUE(h.wait_for(publish(0.05)));
    if (i >= 5) cycles_ms.push_back(ms(Clock::now() - t0));  // after the first frames' setup
  }
  std::sort(cycles_ms.begin(), cycles_ms.end());
  const double sustainable_hz = 1000.0 / cycles_ms[cycles_ms.size() / 2];
  const double rate = 2.0 * sustainable_hz;
  const double period_ms = 1000.0 / rate;
  const size_t first = h.received_.size();
  const ros::Time first_stamp(stamp);

  // Twice that rate, 6 s long.
  const int frames = std::max(60, static_cast<int>(6.0 * rate));
  const Clock::time_point start = Clock::now();
  for (int i = 0; i < frames; ++i) {
    const Clock::time_point due = start + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(i / rate));
    while (Clock::now() < due) {  // answers are timed when handled: handle them promptly
      ros::spinOnce();
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    publish(1.0 / rate);
  }
  h.spin_for(2.5);  // the last answers and a fresh diagnostics message
  const diagnostic_msgs::DiagnosticStatus& d = h.last_odometry_status_;
  const double queue_drops = diagnostic_value(d, "frames dropped (queue full)");
  const int answered = static_cast<int>(h.received_.size() - first);

  // Every frame is either answered or counted as dropped, and the node was overloaded.
  EXPECT_EQ(answered + queue_drops, frames) << "answered " << answered << ", dropped "
                                            << queue_drops;
  EXPECT_EQ(diagnostic_value(d, "incomplete frames dropped"), 0.0);
  EXPECT_GE(queue_drops, frames / 10) << "the node kept up: no overload";
  EXPECT_GT(diagnostic_value(d, "latency p99 (ms)"), 0.0);

  // Latency: publication to answer. The bounded queue shows in the age of each processed frame
  // when the node took it up, i.e. when it finished the previous one: one period at most (the
  // waiting frame is always the newest), plus transport. This holds whatever else runs on the
  // machine; the latency itself is that age plus the node's processing time.
  std::vector<double> latency_ms, age_ms;
  for (size_t j = first; j < h.received_.size(); ++j) {
    const ros::Time t = h.received_[j].header.stamp;
    ASSERT_TRUE(sent.count(t) && h.answer_times_.count(t));
    latency_ms.push_back(ms(h.answer_times_[t] - sent[t]));
    if (j > first)
      age_ms.push_back(ms(h.answer_times_[h.received_[j - 1].header.stamp] - sent[t]));
  }
  ASSERT_GE(age_ms.size(), 10u);
  std::sort(latency_ms.begin(), latency_ms.end());
  std::sort(age_ms.begin(), age_ms.end());
  auto quantile = [](const std::vector<double>& v, double q) {
    return v[std::min(v.size() - 1, static_cast<size_t>(q * (v.size() - 1) + 0.5))];
  };
  EXPECT_LT(quantile(age_ms, 0.95), period_ms + 30.0);
  const double p50 = quantile(latency_ms, 0.5), p99 = quantile(latency_ms, 0.99);

  // In order: answers come in increasing stamps, each motion pairs with an earlier answer.
  for (size_t j = first; j < h.received_.size(); ++j) {
    const MotionEstimate& m = h.received_[j];
    EXPECT_GE(m.header.stamp, first_stamp);
    if (j > first) {
      EXPECT_LT(h.received_[j - 1].header.stamp, m.header.stamp);
    }
    if (m.status != MotionEstimate::STATUS_OK) continue;
    EXPECT_LT(m.reference_stamp, m.header.stamp);
    EXPECT_TRUE(h.motions_.count(m.reference_stamp)) << "reference never answered";
  }
  char summary[320];
  std::snprintf(summary, sizeof(summary),
                "overload: sustainable %.1f Hz, fed %.1f Hz (period %.1f ms), %d frames, %d "
                "answered, %.0f dropped, latency p50 %.1f ms, p99 %.1f ms (%.2f periods), age "
                "at processing p95 %.1f ms",
                sustainable_hz, rate, period_ms, frames, answered, queue_drops, p50, p99,
                p99 / period_ms, quantile(age_ms, 0.95));
  std::printf("%s\n", summary);
  RecordProperty("overload", summary);
}

}  // namespace
}  // namespace hybrid_vo

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "hybrid_vo_stream_rostest");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
