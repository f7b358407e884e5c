#pragma once

// Waiting for a rostest's topics to connect before its first message.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <ros/ros.h>

namespace hybrid_vo {
namespace testing {

// Whether every publisher has at least its count of subscribers and every subscriber a publisher,
// waiting up to `seconds`. rostest starts the nodes and the test together, and each topic connects
// on its own: a message sent before both ends of its topic are connected is lost, and a node that
// misses one part of a frame never answers it. A fixed pause after the first connection is not
// enough on a loaded machine (CI once lost a frame of the compressed test so).
inline ::testing::AssertionResult wait_connected(
    const std::vector<std::pair<ros::Publisher, uint32_t>>& publishers,
    const std::vector<ros::Subscriber>& subscribers, double seconds = 30.0) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  for (;;) {
    std::string missing;
    for (const auto& [publisher, wanted] : publishers)
      if (publisher.getNumSubscribers() < wanted)
        missing += " " + publisher.getTopic() + " (" +
                   std::to_string(publisher.getNumSubscribers()) + " of " +
                   std::to_string(wanted) + " subscribers)";
    for (const ros::Subscriber& subscriber : subscribers)
      if (subscriber.getNumPublishers() == 0)
        missing += " " + subscriber.getTopic() + " (no publisher)";
    if (missing.empty()) return ::testing::AssertionSuccess();
    if (!ros::ok() || ros::WallTime::now() >= end)
      return ::testing::AssertionFailure() << "not connected after " << seconds << " s:" << missing;
    ros::WallDuration(0.05).sleep();
  }
}

}  // namespace testing
}  // namespace hybrid_vo
