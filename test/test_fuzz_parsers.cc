// Every parser and message conversion of fuzz/fuzz_targets.h under a deterministic random
// mutation of its seeds (2,000 inputs per target, seconds in all): no crash, no broken promise, a
// clear error for every rejected input. scripts/fuzz runs the same targets under libFuzzer with
// ASan and UBSan for longer; `test_fuzz_parsers --write-seeds DIR` writes its seed corpora.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <boost/make_shared.hpp>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud.h>

#include "fuzz/fuzz_targets.h"
#include "hybrid_vo/node/conversions.h"

namespace hybrid_vo {
namespace fuzz {
namespace {

constexpr int kInputsPerTarget = 2000;

// Byte-level mutations for every target; token- and line-level ones for the text formats, with
// the values that break parsers: non-numbers, overflows, signs, separators, empty fields.
class Mutator {
 public:
  Mutator(std::vector<std::string> seeds, bool text, uint64_t seed)
      : seeds_(std::move(seeds)), text_(text), rng_(seed) {}

  std::string next() {
    std::string s = seeds_[uniform(seeds_.size())];
    const int n = 1 + static_cast<int>(uniform(4));
    for (int i = 0; i < n; ++i) mutate(&s);
    return s;
  }

 private:
  size_t uniform(size_t n) { return n == 0 ? 0 : static_cast<size_t>(rng_() % n); }

  void mutate(std::string* s) {
    static const char kBytes[] = {'\0', '\xff', '\n', '\r', ' ', ',', '#', '-', '.', 'e',
                                  '0',  '9',    '\x7f', '\x80', '\t', ':'};
    static const char* kTokens[] = {
        "nan", "-nan", "inf", "-inf", "1e308", "-1e308", "1e309", "0", "-0", "4.9e-324",
        "2147483648", "-2147483649", "9223372036854775808", "18446744073709551616", "0x1p3",
        "", " ", "1e", "+", "-", ".", "#", ",", "1,5", "00001", "-1", "3", "4", "1e20", "-1e20",
        "99999999999", "P0:", "P1:", "camera", "PINHOLE", "OPENCV_FISHEYE", "FOV", "rig"};
    const size_t ops = text_ ? 10 : 7;
    const size_t op = uniform(ops);
    if (s->empty() && op != 2) {
      s->push_back(kBytes[uniform(sizeof(kBytes))]);
      return;
    }
    const size_t at = uniform(s->size());
    switch (op) {
      case 0:
        (*s)[at] = static_cast<char>((*s)[at] ^ (1 << uniform(8)));
        break;
      case 1:
        (*s)[at] = kBytes[uniform(sizeof(kBytes))];
        break;
      case 2: {
        std::string bytes;
        for (size_t n = 1 + uniform(8); n > 0; --n) bytes.push_back(static_cast<char>(rng_()));
        s->insert(std::min(at, s->size()), bytes);
        break;
      }
      case 3:
        s->erase(at, 1 + uniform(16));
        break;
      case 4: {
        const std::string piece = s->substr(at, 1 + uniform(32));
        s->insert(uniform(s->size()), piece);
        break;
      }
      case 5:
        s->resize(at);
        break;
      case 6: {  // an interesting 4- or 8-byte value (sizes, floats, doubles)
        static const uint32_t k32[] = {0xffffffffu, 0x80000000u, 0x7fffffffu, 0x10001u, 0x7f800000u,
                                       0x7fc00000u, 0xff800000u, 0u, 1u};
        static const uint64_t k64[] = {0x7ff0000000000000ull, 0x7ff8000000000000ull,
                                       0xfff0000000000000ull, 0x8000000000000000ull,
                                       0x7fefffffffffffffull, 1ull};
        if (uniform(2) == 0 && at + 4 <= s->size()) {
          std::memcpy(&(*s)[at], &k32[uniform(std::size(k32))], 4);
        } else if (at + 8 <= s->size()) {
          std::memcpy(&(*s)[at], &k64[uniform(std::size(k64))], 8);
        }
        break;
      }
      case 7: {  // a token
        size_t begin = at;
        while (begin > 0 && !std::strchr(" ,\t\n", (*s)[begin - 1])) --begin;
        size_t end = at;
        while (end < s->size() && !std::strchr(" ,\t\n", (*s)[end])) ++end;
        s->replace(begin, end - begin, kTokens[uniform(std::size(kTokens))]);
        break;
      }
      case 8: {  // a line: deleted, duplicated, or taken from another seed
        const size_t begin = s->rfind('\n', at) == std::string::npos ? 0 : s->rfind('\n', at) + 1;
        const size_t end = std::min(s->size(), s->find('\n', at) == std::string::npos
                                                   ? s->size()
                                                   : s->find('\n', at) + 1);
        const std::string line = s->substr(begin, end - begin);
        const size_t what = uniform(3);
        if (what == 0) {
          s->erase(begin, end - begin);
        } else if (what == 1) {
          s->insert(begin, line);
        } else {
          const std::string& other = seeds_[uniform(seeds_.size())];
          const size_t from = uniform(other.size() + 1);
          const size_t stop = other.find('\n', from);
          s->insert(begin, other.substr(from, stop == std::string::npos ? stop : stop - from + 1));
        }
        break;
      }
      case 9:  // the separator of multi-file inputs: one more, or one fewer
        if (const size_t p = s->find(kPartSeparator); p != std::string::npos && uniform(2) == 0)
          s->erase(p, std::strlen(kPartSeparator));
        else
          s->insert(at, kPartSeparator);
        break;
    }
  }

  std::vector<std::string> seeds_;
  bool text_;
  std::mt19937_64 rng_;
};

class FuzzParser : public ::testing::TestWithParam<std::string> {};

TEST_P(FuzzParser, MutatedInputsAreAcceptedOrRejectedWithAClearError) {
  const Target* target = find_target(GetParam());
  ASSERT_NE(target, nullptr);
  const std::vector<std::string> seeds = target->seeds();
  ASSERT_FALSE(seeds.empty());
  // The first seed is valid: the harness reaches the parser's end.
  const Outcome first = target->run(reinterpret_cast<const uint8_t*>(seeds[0].data()), seeds[0].size());
  EXPECT_TRUE(first.accepted) << first.error;
  EXPECT_EQ(first.violation, "");

  Mutator mutator(seeds, target->text, std::hash<std::string>()(target->name));
  int accepted = 0, rejected = 0, violations = 0;
  for (int i = 0; i < kInputsPerTarget; ++i) {
    const std::string input = mutator.next();
    const Outcome o = target->run(reinterpret_cast<const uint8_t*>(input.data()), input.size());
    (o.accepted ? accepted : rejected)++;
    if (!o.violation.empty() && ++violations <= 5)
      ADD_FAILURE() << target->name << ": " << o.violation << "\ninput (" << input.size()
                    << " bytes): '" << input << "'";
  }
  EXPECT_EQ(violations, 0);
  RecordProperty("accepted", accepted);
  RecordProperty("rejected", rejected);
  std::cout << target->name << ": " << kInputsPerTarget << " inputs, " << accepted << " accepted, "
            << rejected << " rejected\n";
}

std::vector<std::string> names() {
  std::vector<std::string> all;
  for (const Target& t : targets()) all.push_back(t.name);
  return all;
}

INSTANTIATE_TEST_SUITE_P(Targets, FuzzParser, ::testing::ValuesIn(names()),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param;
                         });

// Inputs the fuzzers found or that are hard to find by mutation: each was a crash, an undefined
// behaviour or a silently wrong value before its fix.
TEST(FuzzRegressions, KnownInputs) {
  struct Case {
    const char* target;
    std::string input;
    bool accepted;
  };
  auto bytes = [](std::initializer_list<std::string> parts) {
    std::string s;
    for (const std::string& p : parts) s += p;
    return s;
  };
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::vector<Case> cases = {
      // An image whose height * step wraps around 32 bits to the data size: cv_bridge's own
      // check passes and the pixels would be read far past the data.
      {"image", bytes({std::string("\x00\x01", 2), u32(1), u32(0x10001), u32(0x10000),
                       std::string(1, '\0'), std::string(0x10000, 'x')}),
       false},
      // A width whose row size wraps around: step >= width * channels in 32 bits.
      {"image", bytes({std::string("\x02\x01", 2), u32(0x55555556), u32(1), u32(2),
                       std::string(1, '\0'), std::string(2, 'x')}),
       false},
      // Strecha image sizes beyond an int.
      {"strecha", "1 0 0\n0 1 0\n0 0 1\n0 0 0\n1 0 0 0 1 0 0 0 1\n0 0 0\n1e20 1e20\n", false},
  };
  for (const Case& c : cases) {
    const Target* target = find_target(c.target);
    ASSERT_NE(target, nullptr);
    const Outcome o = target->run(reinterpret_cast<const uint8_t*>(c.input.data()), c.input.size());
    EXPECT_EQ(o.accepted, c.accepted) << c.target << ": " << o.error;
    EXPECT_EQ(o.violation, "") << c.target;
  }
}

// mono16 in either byte order gives the same one-channel grey image (cv_bridge returned a
// big-endian one as two 8-bit channels); a row step that is not a whole number of 16-bit values
// (OpenCV throws on it) is rejected.
TEST(FuzzRegressions, Mono16InEitherByteOrderAndAnOddStep) {
  auto mono16 = [](bool big_endian, uint32_t step, std::vector<uint8_t> data) {
    auto image = boost::make_shared<sensor_msgs::Image>();
    image->encoding = "mono16";
    image->width = 2;
    image->height = 1;
    image->step = step;
    image->is_bigendian = big_endian;
    image->data = std::move(data);
    return image;
  };
  for (const bool big : {false, true}) {
    cv::Mat gray;
    std::string error;
    const std::vector<uint8_t> data = big ? std::vector<uint8_t>{0x12, 0x00, 0xab, 0x00}
                                          : std::vector<uint8_t>{0x00, 0x12, 0x00, 0xab};
    ASSERT_TRUE(gray_from_image(mono16(big, 4, data), &gray, &error)) << error;
    ASSERT_EQ(gray.type(), CV_8UC1) << (big ? "big" : "little") << " endian";
    ASSERT_EQ(gray.cols, 2);
    EXPECT_EQ(gray.at<uint8_t>(0, 0), 0x12);
    EXPECT_EQ(gray.at<uint8_t>(0, 1), 0xab);
  }
  cv::Mat gray;
  std::string error;
  EXPECT_FALSE(gray_from_image(mono16(false, 5, {1, 2, 3, 4, 5}), &gray, &error));
  EXPECT_NE(error.find("malformed image"), std::string::npos) << error;
}

// A right camera_info whose fx or Tx give no finite positive baseline (fx infinite, or a ratio
// that overflows or underflows) has no baseline: stereo depth from it would be inf or zero.
TEST(FuzzRegressions, BaselineIsFiniteAndPositiveOrAbsent) {
  struct Case {
    double fx, tx;
    bool has_baseline;
  };
  const double inf = std::numeric_limits<double>::infinity();
  const Case cases[] = {{718.856, -386.1448, true}, {718.856, 386.1448, true},
                        {inf, -386.0, false},       {1e-300, -1e300, false},
                        {1e300, -1e-300, false},    {718.856, 0.0, false},
                        {-718.856, -386.0, false},  {718.856, inf, false}};
  for (const Case& c : cases) {
    sensor_msgs::CameraInfo info;
    info.P[0] = c.fx;
    info.P[3] = c.tx;
    double baseline = -1.0;
    EXPECT_EQ(baseline_from_info(info, &baseline), c.has_baseline) << c.fx << " " << c.tx;
    if (c.has_baseline) EXPECT_NEAR(baseline, 386.1448 / 718.856, 1e-12);
  }
}

// VINS ids are floats: one that is not a finite integer would become an arbitrary id shared by
// every such feature, i.e. false matches between frames. Such features are skipped.
TEST(FuzzRegressions, VinsFeaturesWithoutAValidIdAreSkipped) {
  sensor_msgs::PointCloud msg;
  msg.points.resize(3);
  msg.points[0].x = msg.points[1].x = msg.points[2].x = 0.1f;
  msg.channels.resize(3);
  msg.channels[0].values = {std::numeric_limits<float>::quiet_NaN(), 1e30f, 7.0f};
  msg.channels[1].values = {0.2f, 0.2f, 0.2f};
  msg.channels[2].values = {0.3f, 0.3f, 0.3f};
  const PinholeCamera camera(500, 500, 320, 240, 640, 480);
  ExternalFeatures f;
  std::string error;
  ASSERT_TRUE(points_from_vins(msg, camera, &f, &error)) << error;
  ASSERT_EQ(f.point_ids.size(), 1u);
  EXPECT_EQ(f.point_ids[0], 7);
  ASSERT_TRUE(lines_from_vins(msg, camera, &f, &error)) << error;
  ASSERT_EQ(f.line_ids.size(), 1u);
  EXPECT_EQ(f.line_ids[0], 7);
}

}  // namespace
}  // namespace fuzz
}  // namespace hybrid_vo

int main(int argc, char** argv) {
  if (argc == 3 && std::string(argv[1]) == "--write-seeds") {
    namespace fs = std::filesystem;
    for (const hybrid_vo::fuzz::Target& t : hybrid_vo::fuzz::targets()) {
      const fs::path dir = fs::path(argv[2]) / t.name;
      fs::create_directories(dir);
      const std::vector<std::string> seeds = t.seeds();
      for (size_t i = 0; i < seeds.size(); ++i)
        std::ofstream(dir / ("seed_" + std::to_string(i)), std::ios::binary) << seeds[i];
    }
    return 0;
  }
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
