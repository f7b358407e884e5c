// rostest of the data set launch files (test/kitti_replay.test, test/lamar_replay.test): a
// rendered walk written in KITTI's (LaMAR's) own layout is converted to a bag by the converter
// library, and the bag's frames are published as rosbag play would, one at a time and waiting
// for each answer, to the node that kitti.launch (lamar.launch) started with play:=false. The
// node must publish odometry, and its motions must agree with the bag's ground truth.
#include <algorithm>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <hybrid_vo/MotionEstimate.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include "converter_fixtures.h"
#include "hybrid_vo/conversion/kitti_to_bag.h"
#include "hybrid_vo/conversion/lamar_to_bag.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "ros_connections.h"

namespace hybrid_vo {
namespace {

constexpr double kDeg = 180.0 / M_PI;

struct Frame {
  sensor_msgs::Image image;
  sensor_msgs::CameraInfo info;
};

struct Pose {
  Eigen::Matrix3d R;  // camera-to-world
  Eigen::Vector3d c;
};

class Replay {
 public:
  // Reads the camera `camera` (a /camera/<name> prefix), /tf_static and the ground truth.
  Replay(const std::string& bag_path, const std::string& camera) {
    rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
    std::map<ros::Time, Frame> frames;
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      if (m.getTopic() == camera + "/image_raw")
        frames[m.getTime()].image = *m.instantiate<sensor_msgs::Image>();
      else if (m.getTopic() == camera + "/camera_info")
        frames[m.getTime()].info = *m.instantiate<sensor_msgs::CameraInfo>();
      else if (m.getTopic() == "/tf_static")
        statics_ = *m.instantiate<tf2_msgs::TFMessage>();
      else if (const auto gt = m.instantiate<geometry_msgs::PoseStamped>()) {
        const auto& q = gt->pose.orientation;
        const auto& p = gt->pose.position;
        truth_[gt->header.stamp] = {Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix(),
                                    Eigen::Vector3d(p.x, p.y, p.z)};
      }
    }
    for (const auto& [stamp, frame] : frames) frames_.push_back(frame);
    ros::NodeHandle nh;
    image_pub_ = nh.advertise<sensor_msgs::Image>(camera + "/image_raw", 5);
    info_pub_ = nh.advertise<sensor_msgs::CameraInfo>(camera + "/camera_info", 5);
    static_pub_ = nh.advertise<tf2_msgs::TFMessage>("/tf_static", 1, /*latch=*/true);
    motion_sub_ = nh.subscribe("hybrid_vo/relative_pose", 100, &Replay::on_motion, this);
    odometry_sub_ = nh.subscribe("hybrid_vo/odometry", 100, &Replay::on_odometry, this);
  }

  // Publishes every frame after the node subscribed; false when the node does not answer.
  ::testing::AssertionResult run() {
    if (frames_.size() < 5)
      return ::testing::AssertionFailure() << "only " << frames_.size() << " frames";
    const ::testing::AssertionResult connected =
        testing::wait_connected({{image_pub_, 1}, {info_pub_, 1}}, {motion_sub_, odometry_sub_});
    if (!connected) return connected;
    static_pub_.publish(statics_);
    spin_for(0.5);
    for (const Frame& frame : frames_) {
      info_pub_.publish(frame.info);
      image_pub_.publish(frame.image);
      const ros::Time stamp = frame.image.header.stamp;
      if (!wait([&] { return motions_.count(stamp) > 0; }))
        return ::testing::AssertionFailure() << "no ~relative_pose for the frame at " << stamp;
    }
    spin_for(0.5);
    return ::testing::AssertionSuccess();
  }

  // The node's motions against the ground truth: OK count and median errors in degrees.
  void check(double max_rotation_deg, double max_direction_deg) const {
    std::vector<double> rotation, direction;
    for (const auto& [stamp, m] : motions_) {
      if (m.status != MotionEstimate::STATUS_OK) continue;
      const auto a = truth_.find(m.reference_stamp), b = truth_.find(stamp);
      if (a == truth_.end() || b == truth_.end()) continue;
      const Eigen::Matrix3d R_gt = b->second.R.transpose() * a->second.R;
      const Eigen::Vector3d t_gt = b->second.R.transpose() * (a->second.c - b->second.c);
      const auto& q = m.transform.rotation;
      const auto& t = m.transform.translation;
      rotation.push_back(
          rotation_error(Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix(), R_gt) * kDeg);
      direction.push_back(translation_error(Eigen::Vector3d(t.x, t.y, t.z), t_gt) * kDeg);
    }
    EXPECT_EQ(motions_.size(), frames_.size());
    EXPECT_GE(rotation.size(), (frames_.size() - 1) * 2 / 3)
        << "too few OK motions with ground truth";
    ASSERT_FALSE(rotation.empty());
    EXPECT_LT(median(rotation), max_rotation_deg);
    EXPECT_LT(median(direction), max_direction_deg);
    EXPECT_GE(odometry_, rotation.size()) << "the node published too little odometry";
    ::testing::Test::RecordProperty("median_rotation_error_deg", std::to_string(median(rotation)));
    ::testing::Test::RecordProperty("median_direction_error_deg", std::to_string(median(direction)));
  }

 private:
  template <typename Done>
  bool wait(Done done, double seconds = 30.0) {
    const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && ros::WallTime::now() < end) {
      ros::spinOnce();
      if (done()) return true;
      ros::WallDuration(0.005).sleep();
    }
    return false;
  }
  void spin_for(double seconds) {
    wait([] { return false; }, seconds);
  }
  static double median(std::vector<double> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  }
  void on_motion(const MotionEstimate::ConstPtr& m) { motions_[m->header.stamp] = *m; }
  void on_odometry(const nav_msgs::Odometry::ConstPtr&) { ++odometry_; }

  std::vector<Frame> frames_;
  tf2_msgs::TFMessage statics_;
  std::map<ros::Time, Pose> truth_;
  std::map<ros::Time, MotionEstimate> motions_;
  size_t odometry_ = 0;
  ros::Publisher image_pub_, info_pub_, static_pub_;
  ros::Subscriber motion_sub_, odometry_sub_;
};

// KITTI's proportions (2:1) and a car-like speed.
const testing::Rendered& rendering() {
  static const testing::Rendered rendered(12, 640, 320);
  return rendered;
}

TEST(KittiReplay, ConvertedSequenceThroughKittiLaunch) {
  testing::TempDir dir("kitti_replay");
  testing::KittiFixture fixture(dir.path(), rendering());
  fixture.write();
  conversion::KittiBagOptions options;
  options.sequence_dir = fixture.sequence_dir().string();
  options.out_bag = (dir.path() / "kitti.bag").string();
  std::string error;
  ASSERT_TRUE(conversion::convert_kitti(options, &error)) << error;
  Replay replay(options.out_bag, "/camera/left");
  ASSERT_TRUE(replay.run());
  replay.check(1.0, 10.0);
}

TEST(LamarReplay, ConvertedRigSessionThroughLamarLaunch) {
  testing::TempDir dir("lamar_replay");
  testing::RigSession session(dir.path() / "session", rendering());
  session.writer.write();
  conversion::LamarBagOptions options;
  options.session_dir = session.writer.dir.string();
  options.out_bag = (dir.path() / "lamar.bag").string();
  std::string error;
  ASSERT_TRUE(conversion::convert_lamar(options, &error)) << error;
  Replay replay(options.out_bag, "/camera/cam_left");  // lamar_replay.test: camera:=cam_left
  ASSERT_TRUE(replay.run());
  replay.check(1.0, 10.0);
}

}  // namespace
}  // namespace hybrid_vo

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "hybrid_vo_replay_rostest");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
