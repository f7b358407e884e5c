// The node's input side: the bounded frame queue between the callbacks and the processing
// thread, the stream monitor that classifies faults, the latency window, and the decoding of
// compressed images (PNG and JPEG bytes, and sensor_msgs/CompressedImage with its format).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "hybrid_vo/features/image_codec.h"
#include "hybrid_vo/node/compressed_image.h"
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

// The spare slots open only while the consumer keeps up: a fake clock drives arrivals 33 ms
// apart and a consumer taking `service` seconds a frame.
TEST(FrameQueue, SpareSlotsHoldFramesBehindOneSlowFrameButNotUnderOverload) {
  double now = 0.0;
  FrameQueue<int> q(1, 2, [&] { return now; });
  EXPECT_EQ(q.spare(), 2u);
  int v = 0;
  // Nothing measured yet: a first frame's set-up is no overload.
  EXPECT_TRUE(q.keeping_up());
  // Twenty frames at 30 Hz, each taken at once and served in 20 ms.
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(q.push(i), 0);
    ASSERT_TRUE(q.pop(&v));
    EXPECT_EQ(v, i);
    now += 0.020;
    q.finished();
    now += 0.013;  // the next arrival
  }
  EXPECT_TRUE(q.keeping_up());
  // One frame takes 100 ms: three arrive meanwhile and all wait.
  q.push(20);
  ASSERT_TRUE(q.pop(&v));
  for (int i = 21; i <= 23; ++i) {
    now += 0.033;
    EXPECT_EQ(q.push(i), 0) << "frame " << i;
  }
  now += 0.001;
  q.finished();
  EXPECT_EQ(q.size(), 3u);
  for (int i = 21; i <= 23; ++i) {
    ASSERT_TRUE(q.pop(&v));
    EXPECT_EQ(v, i);
    now += 0.005;  // the backlog served quickly
    q.finished();
  }
  EXPECT_TRUE(q.keeping_up()) << "one slow frame is no overload";
  EXPECT_EQ(q.dropped(), 0u);

  // Overload: every frame takes 66 ms, two periods. Within five frames the spare slots close and
  // at most one frame waits, the oldest dropped.
  q.push(199);
  for (int i = 100; i < 130; ++i) {
    ASSERT_TRUE(q.pop(&v));
    now += 0.033;
    q.push(2 * i);
    now += 0.033;
    q.push(2 * i + 1);
    q.finished();  // 66 ms since the pop
    if (i >= 110) {
      EXPECT_FALSE(q.keeping_up());
      EXPECT_LE(q.size(), 1u);
    }
  }
  EXPECT_GT(q.dropped(), 15u);
  EXPECT_EQ(FrameQueue<int>(1).spare(), 0u);
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

// A camera-like grey image: smooth texture with edges, so that JPEG behaves as on real frames.
cv::Mat test_image(int width = 96, int height = 64) {
  cv::Mat noise(height, width, CV_8UC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 256);
  cv::Mat image;
  cv::GaussianBlur(noise, image, cv::Size(0, 0), 1.5);
  cv::rectangle(image, cv::Point(width / 4, height / 4), cv::Point(width / 2, height / 2),
                cv::Scalar(240), cv::FILLED);
  return image;
}

std::vector<uint8_t> encoded(const std::string& ext, const cv::Mat& image,
                             const std::vector<int>& params = {}) {
  std::vector<uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(ext, image, bytes, params));
  return bytes;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

sensor_msgs::CompressedImage compressed(const std::string& format, std::vector<uint8_t> bytes) {
  sensor_msgs::CompressedImage m;
  m.format = format;
  m.data = std::move(bytes);
  return m;
}

TEST(ImageCodec, HeadersSayCodecSizeChannelsAndDepth) {
  const cv::Mat grey = test_image();
  cv::Mat colour, wide;
  cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  grey.convertTo(wide, CV_16U, 256.0);
  struct Case {
    std::vector<uint8_t> bytes;
    ImageCodec codec;
    int channels, depth;
  };
  const std::vector<Case> cases = {
      {encoded(".png", grey), ImageCodec::kPng, 1, 8},
      {encoded(".png", colour), ImageCodec::kPng, 3, 8},
      {encoded(".png", wide), ImageCodec::kPng, 1, 16},
      {encoded(".jpg", grey), ImageCodec::kJpeg, 1, 8},
      {encoded(".jpg", colour, {cv::IMWRITE_JPEG_PROGRESSIVE, 1}), ImageCodec::kJpeg, 3, 8},
  };
  for (const Case& c : cases) {
    EncodedImageHeader h;
    std::string reason;
    ASSERT_TRUE(read_image_header(c.bytes, &h, &reason)) << reason;
    EXPECT_EQ(h.codec, c.codec);
    EXPECT_EQ(h.width, grey.cols);
    EXPECT_EQ(h.height, grey.rows);
    EXPECT_EQ(h.channels, c.channels);
    EXPECT_EQ(h.bit_depth, c.depth);
  }
}

TEST(ImageCodec, DecodesEightAndSixteenBitGreyAndColour) {
  const cv::Mat grey = test_image();
  std::string reason;
  cv::Mat out;
  // PNG is lossless: exactly the image.
  ASSERT_TRUE(decode_gray8(encoded(".png", grey), &out, &reason, grey.cols, grey.rows)) << reason;
  EXPECT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(out, grey, cv::NORM_INF), 0.0);
  // 16 bits: the high byte, as the node reads a raw mono16 image.
  cv::Mat wide;
  grey.convertTo(wide, CV_16U, 256.0);
  wide += cv::Scalar(255);  // low bytes that must not round the high one up
  ASSERT_TRUE(decode_gray8(encoded(".png", wide), &out, &reason)) << reason;
  EXPECT_EQ(out.type(), CV_8UC1);
  EXPECT_LE(cv::norm(out, grey, cv::NORM_INF), 1.0);
  // Colour turns grey: a colour image of equal channels is its grey image.
  cv::Mat colour;
  cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  ASSERT_TRUE(decode_gray8(encoded(".png", colour), &out, &reason)) << reason;
  EXPECT_LE(cv::norm(out, grey, cv::NORM_INF), 1.0);
  // JPEG at quality 95: close to the image, grey or colour.
  for (const cv::Mat& image : {grey, colour}) {
    ASSERT_TRUE(decode_gray8(encoded(".jpg", image, {cv::IMWRITE_JPEG_QUALITY, 95}), &out,
                             &reason))
        << reason;
    ASSERT_EQ(out.size(), grey.size());
    cv::Mat difference;
    cv::absdiff(out, grey, difference);
    EXPECT_LT(cv::mean(difference)[0], 2.0);
  }
}

TEST(ImageCodec, TruncatedJpegIsRefusedAtEveryLength) {
  const std::vector<uint8_t> jpeg = encoded(".jpg", test_image(), {cv::IMWRITE_JPEG_QUALITY, 95});
  cv::Mat out;
  std::string reason;
  ASSERT_TRUE(decode_gray8(jpeg, &out, &reason)) << reason;
  for (size_t n = 0; n < jpeg.size(); n += 1 + n / 16) {
    const std::vector<uint8_t> cut(jpeg.begin(), jpeg.begin() + n);
    EXPECT_FALSE(decode_gray8(cut, &out, &reason)) << n << " bytes";
    EXPECT_FALSE(reason.empty());
  }
  // Cut in the entropy-coded data: libjpeg alone would fill the rest with grey.
  const std::vector<uint8_t> half(jpeg.begin(), jpeg.begin() + jpeg.size() / 2);
  EXPECT_FALSE(decode_gray8(half, &out, &reason));
  EXPECT_TRUE(contains(reason, "JPEG cut short")) << reason;
}

TEST(ImageCodec, TruncatedPngIsRefused) {
  const std::vector<uint8_t> png = encoded(".png", test_image());
  cv::Mat out;
  std::string reason;
  for (size_t n : {size_t{0}, size_t{7}, size_t{20}, png.size() / 2, png.size() - 13}) {
    const std::vector<uint8_t> cut(png.begin(), png.begin() + n);
    EXPECT_FALSE(decode_gray8(cut, &out, &reason)) << n << " bytes";
    EXPECT_FALSE(reason.empty());
  }
}

TEST(ImageCodec, WrongSizeGarbageAndEmptyAreRefusedWithTheirReason) {
  const cv::Mat grey = test_image(96, 64);
  cv::Mat out;
  std::string reason;
  EXPECT_FALSE(decode_gray8(encoded(".png", grey), &out, &reason, 640, 480));
  EXPECT_TRUE(contains(reason, "PNG of 96x64, but 640x480 expected")) << reason;
  EXPECT_FALSE(decode_gray8(encoded(".jpg", grey), &out, &reason, 64, 96));
  EXPECT_TRUE(contains(reason, "JPEG of 96x64, but 64x96 expected")) << reason;
  // A header that claims a huge image is refused before anything is allocated.
  std::vector<uint8_t> huge = encoded(".png", grey);
  const uint8_t kBigEndian60000[4] = {0x00, 0x00, 0xEA, 0x60};
  for (int k = 0; k < 4; ++k) huge[16 + k] = huge[20 + k] = kBigEndian60000[k];
  EXPECT_FALSE(decode_gray8(huge, &out, &reason));
  EXPECT_TRUE(contains(reason, "PNG of 60000x60000 is beyond")) << reason;
  EXPECT_FALSE(decode_gray8({}, &out, &reason));
  EXPECT_TRUE(contains(reason, "no bytes")) << reason;
  EXPECT_FALSE(decode_gray8({'G', 'I', 'F', '8', '9', 'a', 0, 0}, &out, &reason));
  EXPECT_TRUE(contains(reason, "neither PNG nor JPEG (first bytes 47 49 46 38)")) << reason;
  // A valid header over damaged data.
  std::vector<uint8_t> damaged = encoded(".png", grey);
  for (size_t k = 40; k < damaged.size(); k += 3) damaged[k] ^= 0x5A;
  EXPECT_FALSE(decode_gray8(damaged, &out, &reason));
  EXPECT_TRUE(contains(reason, "cannot decode the PNG")) << reason;
}

TEST(CompressedImage, FormatsOfCompressedImageTransport) {
  CompressedFormat f;
  std::string reason;
  ASSERT_TRUE(parse_compressed_format("mono8; png compressed ", &f, &reason)) << reason;
  EXPECT_EQ(f.encoding, "mono8");
  EXPECT_EQ(f.codec, ImageCodec::kPng);
  ASSERT_TRUE(parse_compressed_format("bgr8; jpeg compressed bgr8", &f, &reason)) << reason;
  EXPECT_EQ(f.encoding, "bgr8");
  EXPECT_EQ(f.codec, ImageCodec::kJpeg);
  ASSERT_TRUE(parse_compressed_format("jpeg", &f, &reason)) << reason;  // older publishers
  EXPECT_EQ(f.codec, ImageCodec::kJpeg);
  EXPECT_TRUE(f.encoding.empty());
  ASSERT_TRUE(parse_compressed_format("", &f, &reason)) << reason;
  EXPECT_EQ(f.codec, ImageCodec::kUnknown);
  EXPECT_FALSE(parse_compressed_format("16UC1; compressedDepth png", &f, &reason));
  EXPECT_TRUE(contains(reason, "compressed depth image")) << reason;
  EXPECT_FALSE(parse_compressed_format("theora", &f, &reason));
  EXPECT_TRUE(contains(reason, "not JPEG or PNG")) << reason;
}

TEST(CompressedImage, MessagesDecodeOrAreRefusedWithTheirReason) {
  const cv::Mat grey = test_image();
  cv::Mat out;
  std::string reason;
  ASSERT_TRUE(gray_from_compressed(compressed("mono8; png compressed ", encoded(".png", grey)),
                                   grey.cols, grey.rows, &out, &reason))
      << reason;
  EXPECT_EQ(cv::norm(out, grey, cv::NORM_INF), 0.0);
  ASSERT_TRUE(gray_from_compressed(compressed("mono8; jpeg compressed mono8", encoded(".jpg", grey)),
                                   grey.cols, grey.rows, &out, &reason))
      << reason;
  EXPECT_FALSE(gray_from_compressed(compressed("mono8; png compressed ", {}), grey.cols,
                                    grey.rows, &out, &reason));
  EXPECT_EQ(reason, "empty compressed image");
  EXPECT_FALSE(gray_from_compressed(compressed("mono8; png compressed ", encoded(".png", grey)),
                                    2 * grey.cols, grey.rows, &out, &reason));
  EXPECT_TRUE(contains(reason, "PNG of 96x64, but 192x64 expected")) << reason;
  EXPECT_FALSE(gray_from_compressed(compressed("mono8; png compressed ", encoded(".jpg", grey)),
                                    grey.cols, grey.rows, &out, &reason));
  EXPECT_TRUE(contains(reason, "names PNG, but the payload is JPEG")) << reason;
  const std::vector<uint8_t> jpeg = encoded(".jpg", grey);
  EXPECT_FALSE(gray_from_compressed(
      compressed("mono8; jpeg compressed mono8",
                 std::vector<uint8_t>(jpeg.begin(), jpeg.begin() + jpeg.size() * 2 / 3)),
      grey.cols, grey.rows, &out, &reason));
  EXPECT_TRUE(contains(reason, "JPEG cut short")) << reason;
}

}  // namespace
}  // namespace hybrid_vo
