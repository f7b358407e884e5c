// The node's input side without ROS: the bounded frame queue between the callbacks and the
// processing thread, the stream monitor that classifies faults, and the latency window.
#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "hybrid_vo/node/frame_queue.h"
#include "hybrid_vo/node/latency_window.h"
#include "hybrid_vo/node/stream_monitor.h"

namespace hybrid_vo {
namespace {

TEST(FrameQueue, DropsTheOldestWhenFull) {
  FrameQueue<int> q(2);
  EXPECT_EQ(q.push(1), 0);
  EXPECT_EQ(q.push(2), 0);
  EXPECT_EQ(q.push(3), 1);  // 1 goes
  EXPECT_EQ(q.push(4), 1);  // 2 goes
  EXPECT_EQ(q.size(), 2u);
  EXPECT_EQ(q.pushed(), 4u);
  EXPECT_EQ(q.dropped(), 2u);
  int v = 0;
  ASSERT_TRUE(q.pop(&v));
  EXPECT_EQ(v, 3);
  ASSERT_TRUE(q.pop(&v));
  EXPECT_EQ(v, 4);
  q.push(5);
  q.clear();  // not counted as dropped
  EXPECT_EQ(q.size(), 0u);
  EXPECT_EQ(q.dropped(), 2u);
  EXPECT_EQ(FrameQueue<int>(0).capacity(), 1u);
}

TEST(FrameQueue, CloseWakesTheConsumer) {
  FrameQueue<int> q(1);
  std::atomic<bool> returned{false};
  bool result = true;
  std::thread consumer([&] {
    int v = 0;
    result = q.pop(&v);
    returned = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(returned);
  q.close();
  consumer.join();
  EXPECT_FALSE(result);
  EXPECT_EQ(q.push(1), 0);  // refused after close
  EXPECT_EQ(q.size(), 0u);
}

// A fast producer and a slow consumer: the consumer sees increasing values only, every value is
// either consumed or counted as dropped, and the backlog never exceeds the capacity.
TEST(FrameQueue, SlowConsumerSeesFramesInOrderAndEveryLossIsCounted) {
  for (size_t capacity : {1u, 3u}) {
    FrameQueue<int> q(capacity);
    std::vector<int> seen;
    std::thread consumer([&] {
      int v = 0;
      while (q.pop(&v)) {
        seen.push_back(v);
        if (v < 0) break;
        std::this_thread::sleep_for(std::chrono::microseconds(300));
      }
    });
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
      q.push(i);
      EXPECT_LE(q.size(), capacity);
      std::this_thread::sleep_for(std::chrono::microseconds(50));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    q.push(-1);  // the end marker
    consumer.join();
    ASSERT_FALSE(seen.empty());
    EXPECT_EQ(seen.back(), -1);
    seen.pop_back();
    for (size_t k = 1; k < seen.size(); ++k) ASSERT_LT(seen[k - 1], seen[k]);
    EXPECT_EQ(seen.size() + q.dropped(), static_cast<size_t>(n));
    EXPECT_GT(q.dropped(), 0u) << "the consumer was meant to be too slow";
  }
}

TEST(StreamMonitor, ClassifiesEachFault) {
  StreamMonitorOptions options;
  options.max_gap_s = 1.0;
  StreamMonitor m(options);
  auto next = [&](double stamp, int w = 640, int h = 480) {
    const StreamEvent e = m.classify(stamp, w, h);
    if (!skips(e)) m.accept(w, h);
    return e;
  };
  EXPECT_EQ(next(1.0), StreamEvent::kFirst);
  EXPECT_EQ(next(1.1), StreamEvent::kNext);
  EXPECT_EQ(next(1.1), StreamEvent::kDuplicate);
  EXPECT_EQ(next(1.05), StreamEvent::kLate);
  EXPECT_EQ(next(1.2), StreamEvent::kNext);
  EXPECT_EQ(next(11.2), StreamEvent::kGap);
  EXPECT_TRUE(m.description().find("forwards by 10.000 s") != std::string::npos)
      << m.description();
  EXPECT_EQ(next(11.3), StreamEvent::kNext);
  EXPECT_EQ(next(11.4, 320, 240), StreamEvent::kSizeChange);
  EXPECT_EQ(next(11.5, 320, 240), StreamEvent::kNext);
  // A bag loop; sizes are not compared across the reset.
  EXPECT_EQ(next(2.0, 640, 480), StreamEvent::kBackwards);
  EXPECT_EQ(next(2.1, 640, 480), StreamEvent::kNext);
  // Rejected input: the frame after it restarts, later ones pair again.
  EXPECT_EQ(m.classify(2.2, 640, 480), StreamEvent::kNext);
  m.reject();
  EXPECT_EQ(m.classify(2.3, 640, 480), StreamEvent::kAfterFault);
  m.reject();  // a burst
  EXPECT_EQ(m.classify(2.4, 640, 480), StreamEvent::kAfterFault);
  m.accept(640, 480);
  EXPECT_EQ(next(2.5), StreamEvent::kNext);
  // A gap counts once, even when the frames around it are rejected.
  EXPECT_EQ(m.classify(5.0, 640, 480), StreamEvent::kGap);
  m.reject();
  EXPECT_EQ(m.classify(5.1, 640, 480), StreamEvent::kAfterFault);
  m.accept(640, 480);

  const StreamCounters& c = m.counters();
  EXPECT_EQ(c.duplicates, 1);
  EXPECT_EQ(c.late, 1);
  EXPECT_EQ(c.gaps, 2);
  EXPECT_EQ(c.size_changes, 1);
  EXPECT_EQ(c.backwards, 1);
  EXPECT_EQ(c.after_faults, 3);
  EXPECT_EQ(c.restarts(), 6);

  m.reset();
  EXPECT_EQ(m.classify(0.5, 100, 100), StreamEvent::kFirst);
  EXPECT_EQ(m.counters().backwards, 1);  // counters survive a reset
}

TEST(StreamMonitor, GapIsRelativeToTheLastFrameSeen) {
  StreamMonitorOptions options;
  options.max_gap_s = 0.5;
  StreamMonitor m(options);
  EXPECT_EQ(m.classify(1.0, 10, 10), StreamEvent::kFirst);
  m.accept(10, 10);
  // Rejected frames still advance the clock: 0.4 s steps are no gap, only rejected input.
  for (double t = 1.4; t < 3.0; t += 0.4) {
    EXPECT_NE(m.classify(t, 10, 10), StreamEvent::kGap) << t;
    m.reject();
  }
  EXPECT_EQ(m.counters().gaps, 0);
}

TEST(LatencyWindow, QuantilesOfTheLastSamples) {
  LatencyWindow w(100);
  EXPECT_EQ(w.quantile(0.5), 0.0);
  for (int i = 1; i <= 100; ++i) w.add(i);
  EXPECT_NEAR(w.quantile(0.5), 50.5, 0.6);
  EXPECT_EQ(w.quantile(1.0), 100.0);
  EXPECT_EQ(w.quantile(0.0), 1.0);
  for (int i = 0; i < 100; ++i) w.add(1000.0);  // the old samples leave the window
  EXPECT_EQ(w.count(), 100u);
  EXPECT_EQ(w.quantile(0.0), 1000.0);
}

}  // namespace
}  // namespace hybrid_vo
