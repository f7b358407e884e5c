// hybrid_vo_node: frame-to-frame visual odometry from points, lines and vanishing points.
#include <ros/ros.h>

#include "hybrid_vo/node/vo_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "hybrid_vo");
  hybrid_vo::VoNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  ros::spin();
  return 0;
}
