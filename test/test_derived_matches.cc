#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "hybrid_vo/estimation/derived_matches.h"

namespace hybrid_vo {
namespace {

LineMatch match(Eigen::Vector2d a, Eigen::Vector2d b, Eigen::Vector2d shift = {5.0, -3.0}) {
  return {LineSegment(a, b), LineSegment(a + shift, b + shift)};
}

TEST(Junctions, CrossingSegmentsMeetOnBoth) {
  const std::vector<LineMatch> lines = {match({0, 0}, {100, 0}), match({50, -40}, {50, 60})};
  const auto junctions = find_junctions(lines);
  ASSERT_EQ(junctions.size(), 1u);
  EXPECT_EQ(junctions[0].source, PointSource::kJunction);
  EXPECT_EQ(junctions[0].first, 0);
  EXPECT_EQ(junctions[0].second, 1);
  EXPECT_LT((junctions[0].match.x1 - Eigen::Vector2d(50, 0)).norm(), 1e-12);
  EXPECT_LT((junctions[0].match.x2 - Eigen::Vector2d(55, -3)).norm(), 1e-12);
}

TEST(Junctions, ToleranceBeyondTheEnds) {
  // The second segment stops 2 px short of the first (an L corner with a detector gap).
  const std::vector<LineMatch> lines = {match({0, 0}, {100, 0}), match({102, 2}, {102, 80})};
  JunctionOptions options;
  options.tolerance_px = 3.0;
  EXPECT_EQ(find_junctions(lines, options).size(), 1u);
  options.tolerance_px = 1.0;
  EXPECT_EQ(find_junctions(lines, options).size(), 0u);
}

// Issue 30: a faint corner breaks its edges off short of it. With length_fraction 0.15, a
// 100 px segment meeting another at a right angle may stop up to 15 px short, a 40 px one 6 px
// (the 3 px floor below that), never more than max_tolerance_px, and less at shallow angles.
TEST(Junctions, LongSegmentsThatStopShortOfACornerStillMeetIt) {
  JunctionOptions options;
  options.tolerance_px = 3.0;
  options.length_fraction = 0.15;
  options.max_tolerance_px = 20.0;
  EXPECT_DOUBLE_EQ(junction_tolerance_px(100.0, 1.0, options), 15.0);
  EXPECT_DOUBLE_EQ(junction_tolerance_px(40.0, 1.0, options), 6.0);
  EXPECT_DOUBLE_EQ(junction_tolerance_px(10.0, 1.0, options), 3.0);
  EXPECT_DOUBLE_EQ(junction_tolerance_px(400.0, 1.0, options), 20.0);
  EXPECT_DOUBLE_EQ(junction_tolerance_px(100.0, 0.5, options), 7.5);
  // An L corner on the floor: both edges 100 px long, each stopping 12 px short of it.
  auto corner = [](double gap, double length) {
    return std::vector<LineMatch>{match({0, 0}, {length, 0}),
                                  match({length + gap, gap}, {length + gap, gap + length})};
  };
  EXPECT_EQ(find_junctions(corner(12.0, 100.0), options).size(), 1u);
  EXPECT_EQ(find_junctions(corner(16.0, 100.0), options).size(), 0u);
  // Short edges must reach closer: 40 px ones meet 5 px short, not 8.
  EXPECT_EQ(find_junctions(corner(5.0, 40.0), options).size(), 1u);
  EXPECT_EQ(find_junctions(corner(8.0, 40.0), options).size(), 0u);
  // The default (length_fraction 0) keeps the fixed 3 px.
  EXPECT_EQ(find_junctions(corner(12.0, 100.0)).size(), 0u);
  EXPECT_EQ(find_junctions(corner(2.0, 100.0)).size(), 1u);
}

TEST(Junctions, MustHoldInBothImages) {
  std::vector<LineMatch> lines = {match({0, 0}, {100, 0}), match({50, -40}, {50, 60})};
  lines[1].s2 = LineSegment({200, 10}, {200, 90});  // far from the other segment in image 2
  EXPECT_TRUE(find_junctions(lines).empty());
}

TEST(Junctions, ParallelShallowAndInvalidSegmentsFormNone) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<LineMatch> lines = {
      match({0, 0}, {100, 0}), match({0, 10}, {100, 10}),        // parallel
      match({0, 1}, {100, 6}),                                    // ~3 degrees: too shallow
      match({50, -40}, {50, -40}),                                // zero length
      match({nan, 0}, {50, 60})};                                 // not finite
  EXPECT_TRUE(find_junctions(lines).empty());
}

TEST(Endpoints, PairedSoThatSegmentsPointTheSameWay) {
  std::vector<LineMatch> lines = {match({0, 0}, {100, 0})};
  lines[0].s2 = LineSegment({105, -3}, {5, -3});  // stored the other way round in image 2
  const auto ends = segment_endpoints(lines);
  ASSERT_EQ(ends.size(), 2u);
  EXPECT_EQ(ends[0].source, PointSource::kEndpoint);
  EXPECT_LT((ends[0].match.x2 - Eigen::Vector2d(5, -3)).norm(), 1e-12);
  EXPECT_LT((ends[1].match.x2 - Eigen::Vector2d(105, -3)).norm(), 1e-12);
  lines.push_back(match({1, 1}, {1, 1}));  // zero length: no endpoints
  EXPECT_EQ(segment_endpoints(lines).size(), 2u);
}

DerivedPoint junction_at(Eigen::Vector2d x1, Eigen::Vector2d x2) {
  DerivedPoint d;
  d.match = {x1, x2};
  d.source = PointSource::kJunction;
  return d;
}

// One image position has one correspondence: a junction repeating an earlier one in either image
// (a segment matched twice) counts once; the first is kept, distinct ones all stay.
TEST(Junctions, DistinctDropsRepeatsInEitherImage) {
  const std::vector<DerivedPoint> junctions = {
      junction_at({100, 100}, {90, 105}),
      junction_at({100.5, 100}, {120, 140}),  // image 1 repeats junction 0
      junction_at({300, 50}, {291.5, 55}),
      junction_at({302, 70}, {290, 55}),      // image 2 repeats junction 2
      junction_at({103, 100}, {93, 105}),     // 3 px from junction 0 in both: distinct
  };
  EXPECT_EQ(distinct_junctions(junctions, 2.0), (std::vector<int>{0, 2, 4}));
  EXPECT_EQ(distinct_junctions(junctions, 5.0), (std::vector<int>{0, 2}));
  const std::vector<int> all = {0, 1, 2, 3, 4};
  EXPECT_EQ(distinct_junctions(junctions, 0.0), all);
  EXPECT_EQ(distinct_junctions(junctions, std::numeric_limits<double>::quiet_NaN()), all);
  EXPECT_TRUE(distinct_junctions({}, 2.0).empty());
}

}  // namespace
}  // namespace hybrid_vo
