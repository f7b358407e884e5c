// The KITTI and LaMAR bag converters (hybrid_vo/conversion) on fixtures that this test writes
// from the synthetic renderer in each data set's own layout, read back with rosbag::View: images,
// camera_info, stamps, ground truth and static transforms must round-trip. Broken inputs must
// fail with the file and line and leave no bag behind; so must a damaged image in the middle of
// each kind of stream, and an undamaged one gives exactly one message per frame on every topic.
// Tests run the built executables too; the real KITTI excerpt is converted when ../shared/data
// is present.
#include <sys/wait.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <cv_bridge/cv_bridge.h>
#include <Eigen/Geometry>
#include <geometry_msgs/PoseStamped.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <tf2_msgs/TFMessage.h>

#include "converter_fixtures.h"
#include "file_test_utils.h"
#include "hybrid_vo/conversion/bag_writing.h"
#include "hybrid_vo/conversion/kitti_to_bag.h"
#include "hybrid_vo/conversion/lamar_to_bag.h"
#include "hybrid_vo/datasets/kitti.h"
#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/features/image_codec.h"
#include "hybrid_vo/render/sequence.h"

namespace hybrid_vo {
namespace conversion {
namespace {

namespace fs = std::filesystem;
using testing::contains;
using testing::isometry;
using testing::KittiFixture;
using testing::LamarWriter;
using testing::Rendered;
using testing::RigSession;
using testing::shared_data_dir;
using testing::TempDir;
using testing::write_file;

// ------------------------------------------------------------------------------------------------
// Reading bags back

struct BagData {
  std::map<std::string, std::vector<sensor_msgs::Image>> images;  // by topic
  std::map<std::string, std::vector<sensor_msgs::CompressedImage>> compressed;
  std::map<std::string, std::vector<sensor_msgs::CameraInfo>> infos;
  std::vector<geometry_msgs::PoseStamped> ground_truth;
  std::vector<geometry_msgs::TransformStamped> tf, tf_static;
  bool tf_static_latched = false;
};

BagData read_bag(const std::string& path) {
  BagData data;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    if (const auto image = m.instantiate<sensor_msgs::Image>()) {
      data.images[m.getTopic()].push_back(*image);
      EXPECT_EQ(m.getTime(), image->header.stamp) << m.getTopic();
    } else if (const auto image = m.instantiate<sensor_msgs::CompressedImage>()) {
      data.compressed[m.getTopic()].push_back(*image);
      EXPECT_EQ(m.getTime(), image->header.stamp) << m.getTopic();
    } else if (const auto info = m.instantiate<sensor_msgs::CameraInfo>()) {
      data.infos[m.getTopic()].push_back(*info);
    } else if (const auto pose = m.instantiate<geometry_msgs::PoseStamped>()) {
      EXPECT_EQ(m.getTopic(), "/ground_truth/pose");
      data.ground_truth.push_back(*pose);
    } else if (const auto tf = m.instantiate<tf2_msgs::TFMessage>()) {
      const bool is_static = m.getTopic() == "/tf_static";
      auto& target = is_static ? data.tf_static : data.tf;
      target.insert(target.end(), tf->transforms.begin(), tf->transforms.end());
      if (is_static) {
        const auto header = m.getConnectionHeader();
        data.tf_static_latched =
            header && header->count("latching") && header->at("latching") == "1";
      }
    } else {
      ADD_FAILURE() << "unexpected message on " << m.getTopic();
    }
  }
  return data;
}

cv::Mat mono8(const sensor_msgs::Image& image) {
  EXPECT_EQ(image.encoding, "mono8");
  return cv_bridge::toCvCopy(image, "mono8")->image;
}

bool same_image(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

Eigen::Matrix3d rotation_of(const geometry_msgs::Quaternion& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
}

void expect_pose(const geometry_msgs::Pose& actual, const render::CameraPose& expected,
                 double tolerance) {
  EXPECT_LT((rotation_of(actual.orientation) - expected.R_world_from_camera).norm(), tolerance);
  const Eigen::Vector3d c(actual.position.x, actual.position.y, actual.position.z);
  EXPECT_LT((c - expected.centre).norm(), tolerance);
}

void expect_transform(const geometry_msgs::TransformStamped& t, const std::string& parent,
                      const std::string& child, const Eigen::Matrix3d& R,
                      const Eigen::Vector3d& translation, double tolerance) {
  EXPECT_EQ(t.header.frame_id, parent);
  EXPECT_EQ(t.child_frame_id, child);
  EXPECT_LT((rotation_of(t.transform.rotation) - R).norm(), tolerance);
  const auto& v = t.transform.translation;
  EXPECT_LT((Eigen::Vector3d(v.x, v.y, v.z) - translation).norm(), tolerance);
}

void expect_intrinsics(const sensor_msgs::CameraInfo& info, const PinholeCamera& c,
                       double tolerance) {
  EXPECT_EQ(static_cast<int>(info.width), c.width);
  EXPECT_EQ(static_cast<int>(info.height), c.height);
  EXPECT_NEAR(info.K[0], c.fx, tolerance);
  EXPECT_NEAR(info.K[2], c.cx, tolerance);
  EXPECT_NEAR(info.K[4], c.fy, tolerance);
  EXPECT_NEAR(info.K[5], c.cy, tolerance);
  EXPECT_EQ(info.K[1], 0.0);
  EXPECT_EQ(info.K[8], 1.0);
  EXPECT_EQ(info.R, (boost::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  for (int k : {0, 1, 2, 4, 5, 6, 8, 9, 10}) EXPECT_EQ(info.P[k], info.K[k - k / 4]) << k;
}

// Runs a command; its exit status, and its output (stdout and stderr) in *output.
int run(const std::string& command, std::string* output) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  char buffer[512];
  output->clear();
  while (fgets(buffer, sizeof(buffer), pipe)) *output += buffer;
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool no_bag(const fs::path& bag) { return !fs::exists(bag) && !fs::exists(bag.string() + ".tmp"); }

// ------------------------------------------------------------------------------------------------
// KITTI

const Rendered& kitti_rendering() {
  static const Rendered rendered(5);
  return rendered;
}

TEST(KittiToBag, StereoSequenceRoundTrips) {
  TempDir dir("test_convert");
  KittiFixture fixture(dir.path(), kitti_rendering());
  fixture.write();
  KittiBagOptions options;
  options.sequence_dir = fixture.sequence_dir().string() + "/";
  options.out_bag = (dir.path() / "out.bag").string();
  options.stereo = true;
  std::string error;
  KittiBagSummary summary;
  ASSERT_TRUE(convert_kitti(options, &error, &summary)) << error;
  EXPECT_EQ(summary.frames, 5);
  EXPECT_EQ(fs::path(summary.poses_path).lexically_normal(), fixture.poses_path());
  EXPECT_FALSE(fs::exists(options.out_bag + ".tmp"));

  const Rendered& r = kitti_rendering();
  const BagData bag = read_bag(options.out_bag);
  for (const std::string side : {"left", "right"}) {
    SCOPED_TRACE(side);
    const std::string frame = "camera_" + side + "_optical";
    const auto& images = bag.images.at("/camera/" + side + "/image_raw");
    const auto& infos = bag.infos.at("/camera/" + side + "/camera_info");
    ASSERT_EQ(images.size(), 5u);
    ASSERT_EQ(infos.size(), 5u);
    for (int i = 0; i < 5; ++i) {
      const ros::Time stamp(1.0 + fixture.time(i));
      EXPECT_EQ(images[i].header.stamp, stamp);
      EXPECT_EQ(infos[i].header.stamp, stamp);
      EXPECT_EQ(images[i].header.frame_id, frame);
      EXPECT_EQ(infos[i].header.frame_id, frame);
      EXPECT_TRUE(
          same_image(mono8(images[i]), side == "left" ? r.left_images[i] : r.right_images[i]));
      expect_intrinsics(infos[i], r.seq.camera, 1e-12);
      EXPECT_EQ(infos[i].distortion_model, "plumb_bob");
      EXPECT_EQ(infos[i].D, std::vector<double>(5, 0.0));
      EXPECT_NEAR(infos[i].P[3], side == "left" ? 0.0 : -r.seq.camera.fx * r.baseline, 1e-9);
      EXPECT_EQ(infos[i].P[7], 0.0);
      EXPECT_EQ(infos[i].P[11], 0.0);
    }
  }

  // Ground truth: the left camera's camera-to-world pose, as a pose and as tf.
  ASSERT_EQ(bag.ground_truth.size(), 5u);
  ASSERT_EQ(bag.tf.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(bag.ground_truth[i].header.stamp, ros::Time(1.0 + fixture.time(i)));
    EXPECT_EQ(bag.ground_truth[i].header.frame_id, "world");
    expect_pose(bag.ground_truth[i].pose, r.left[i], 1e-9);
    expect_transform(bag.tf[i], "world", "gt_camera_left_optical", r.left[i].R_world_from_camera,
                     r.left[i].centre, 1e-9);
  }
  // Latched statics: the optical frames look along base x, the right one b to the base's right.
  ASSERT_TRUE(bag.tf_static_latched);
  ASSERT_EQ(bag.tf_static.size(), 2u);
  const Eigen::Matrix3d R_bo = render::base_from_optical();
  expect_transform(bag.tf_static[0], "base_link", "camera_left_optical", R_bo,
                   Eigen::Vector3d::Zero(), 1e-12);
  expect_transform(bag.tf_static[1], "base_link", "camera_right_optical", R_bo,
                   Eigen::Vector3d(0, -r.baseline, 0), 1e-12);
}

TEST(KittiToBag, MonoWithoutPosesAndWithAStartTime) {
  TempDir dir("test_convert");
  KittiFixture fixture(dir.path(), kitti_rendering());
  fixture.poses.clear();
  fixture.calib = {fixture.calib[0]};  // mono needs no P1
  fixture.write();
  KittiBagOptions options;
  options.sequence_dir = fixture.sequence_dir().string();
  options.out_bag = (dir.path() / "out.bag").string();
  options.start_time = 1000.0;
  std::string error;
  KittiBagSummary summary;
  ASSERT_TRUE(convert_kitti(options, &error, &summary)) << error;
  EXPECT_EQ(summary.poses_path, "");
  const BagData bag = read_bag(options.out_bag);
  EXPECT_EQ(bag.images.size(), 1u);
  EXPECT_TRUE(bag.ground_truth.empty());
  EXPECT_TRUE(bag.tf.empty());
  ASSERT_EQ(bag.tf_static.size(), 1u);
  ASSERT_EQ(bag.images.at("/camera/left/image_raw").size(), 5u);
  EXPECT_EQ(bag.images.at("/camera/left/image_raw")[3].header.stamp,
            ros::Time(1000.0 + fixture.time(3)));

  // --poses elsewhere brings the ground truth back.
  KittiFixture with_poses(dir.path() / "other", kitti_rendering());
  with_poses.write();
  options.poses = with_poses.poses_path().string();
  ASSERT_TRUE(convert_kitti(options, &error, &summary)) << error;
  EXPECT_EQ(summary.poses_path, options.poses);
  EXPECT_EQ(read_bag(options.out_bag).ground_truth.size(), 5u);
}

TEST(KittiToBag, BadInputFailsWithFileAndLineAndLeavesNoBag) {
  struct Case {
    std::string what;
    std::function<void(KittiFixture*)> damage;
    std::function<std::string(const KittiFixture&)> where;
    std::string message;
  };
  auto times_txt = [](const KittiFixture& f) { return (f.sequence_dir() / "times.txt").string(); };
  const std::vector<Case> cases = {
      {"NaN timestamp", [](KittiFixture* f) { f->times[2] = "nan"; },
       [&](const KittiFixture& f) { return times_txt(f) + ":3:"; }, "'nan' is not a finite number"},
      {"timestamps going back", [](KittiFixture* f) { f->times[3] = "0.1"; },
       [&](const KittiFixture& f) { return times_txt(f) + ":4:"; }, "does not increase"},
      {"pose with 11 numbers", [](KittiFixture* f) { f->poses[1] = "1 0 0 0 0 1 0 0 0 0 1"; },
       [](const KittiFixture& f) { return f.poses_path().string() + ":2:"; }, "expected 12 fields"},
      {"fewer poses than frames", [](KittiFixture* f) { f->poses.pop_back(); },
       [](const KittiFixture& f) { return f.poses_path().string() + ":"; }, "4 poses for 5 frames"},
      {"P1 without a baseline",
       [](KittiFixture* f) { f->calib[1] = "P1: 100 0 80 0 0 100 48 0 0 0 1 0"; },
       [](const KittiFixture& f) { return (f.sequence_dir() / "calib.txt").string() + ":2:"; },
       "no positive baseline"},
      {"no P1 for --stereo", [](KittiFixture* f) { f->calib.erase(f->calib.begin() + 1); },
       [](const KittiFixture& f) { return (f.sequence_dir() / "calib.txt").string() + ":"; },
       "no 'P1:' line"},
      {"more images than timestamps",
       [](KittiFixture* f) {
         f->times.pop_back();
         f->poses.pop_back();
       },
       [](const KittiFixture& f) { return (f.sequence_dir() / "image_0").string() + ":"; },
       "5 images for 4 timestamps"},
      {"unreadable image", [](KittiFixture* f) { write_file(f->image_path(1, 3), "not a png"); },
       [](const KittiFixture& f) { return f.image_path(1, 3).string() + ":"; },
       "cannot decode image"},
      {"image of another size",
       [](KittiFixture* f) {
         ASSERT_TRUE(cv::imwrite(f->image_path(0, 2).string(), cv::Mat(10, 10, CV_8U)));
       },
       [](const KittiFixture& f) { return f.image_path(0, 2).string() + ":"; },
       "image is 10x10, the first was 160x96"},
      {"misnamed image",
       [](KittiFixture* f) {
         fs::rename(f->image_path(0, 4), f->sequence_dir() / "image_0" / "4.png");
       },
       [](const KittiFixture& f) { return f.image_path(0, 4).string() + ":"; }, "no such image"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    TempDir dir("test_convert");
    KittiFixture fixture(dir.path(), kitti_rendering());
    fixture.write_images();
    c.damage(&fixture);
    fixture.write_text();
    KittiBagOptions options;
    options.sequence_dir = fixture.sequence_dir().string();
    options.out_bag = (dir.path() / "out.bag").string();
    options.stereo = true;
    std::string error;
    EXPECT_FALSE(convert_kitti(options, &error));
    EXPECT_TRUE(contains(error, c.where(fixture)));
    EXPECT_TRUE(contains(error, c.message));
    EXPECT_TRUE(no_bag(options.out_bag));
  }
  TempDir dir("test_convert");
  KittiBagOptions options;
  options.sequence_dir = (dir.path() / "missing").string();
  options.out_bag = (dir.path() / "out.bag").string();
  std::string error;
  EXPECT_FALSE(convert_kitti(options, &error));
  EXPECT_TRUE(contains(error, "missing: no such directory"));
  KittiFixture fixture(dir.path(), kitti_rendering());
  fixture.write();
  options.sequence_dir = fixture.sequence_dir().string();
  options.poses = (dir.path() / "nowhere.txt").string();
  EXPECT_FALSE(convert_kitti(options, &error));
  EXPECT_TRUE(contains(error, options.poses + ": no such file"));
  options.poses.clear();
  options.out_bag = (dir.path() / "no_folder" / "out.bag").string();
  EXPECT_FALSE(convert_kitti(options, &error));
  EXPECT_TRUE(contains(error, "missing or not writable"));
}

TEST(KittiToBag, Arguments) {
  KittiBagOptions o;
  EXPECT_EQ(parse_kitti_args({"--sequence", "s", "--out", "o.bag", "--stereo", "--start-time", "5",
                              "--poses", "p.txt"},
                             &o),
            "");
  EXPECT_TRUE(o.stereo);
  EXPECT_EQ(o.start_time, 5.0);
  EXPECT_EQ(o.poses, "p.txt");
  KittiBagOptions d;
  EXPECT_EQ(parse_kitti_args({"--sequence", "s", "--out", "o.bag"}, &d), "");
  EXPECT_EQ(d.start_time, 1.0);
  EXPECT_FALSE(d.stereo);
  auto problem = [](const std::vector<std::string>& args) {
    KittiBagOptions fresh;
    return parse_kitti_args(args, &fresh);
  };
  EXPECT_EQ(problem({"--sequence", "s"}), "--out OUT.bag is required");
  EXPECT_EQ(problem({"--out", "o.bag"}), "--sequence DIR is required");
  EXPECT_TRUE(contains(problem({"--sequence", "s", "--out", "o", "--start-time", "-1"}),
                       "bad value '-1' for --start-time"));
  EXPECT_EQ(problem({"--sequence", "s", "--out", "o", "--bogus"}), "unknown argument '--bogus'");
  EXPECT_EQ(problem({"--sequence"}), "--sequence needs a value");
}

TEST(KittiToBag, Executable) {
  TempDir dir("test_convert");
  KittiFixture fixture(dir.path(), kitti_rendering());
  fixture.times[1] = "0.1 0.2";
  fixture.write();
  const std::string tool = std::string(HYBRID_VO_BIN_DIR) + "/hybrid_vo_kitti_to_bag";
  const fs::path bag = dir.path() / "out.bag";
  const std::string command =
      tool + " --sequence " + fixture.sequence_dir().string() + " --out " + bag.string();
  std::string output;
  EXPECT_EQ(run(command, &output), 1);
  EXPECT_TRUE(contains(output, "error: " + (fixture.sequence_dir() / "times.txt").string() +
                                   ":2: expected 1 fields"));
  EXPECT_TRUE(no_bag(bag));

  fixture.times[1] = "1.000000e-01";
  fixture.write();
  EXPECT_EQ(run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "converted 5 frames (mono, 160x96, raw images), ground truth from"));
  EXPECT_EQ(read_bag(bag.string()).ground_truth.size(), 5u);
  EXPECT_EQ(run(command + " --compressed png", &output), 0) << output;
  EXPECT_TRUE(contains(output, "converted 5 frames (mono, 160x96, png images)"));
  EXPECT_EQ(read_bag(bag.string()).compressed.at("/camera/left/image_raw/compressed").size(), 5u);
  // A relative sequence folder still finds <root>/poses.
  const std::string relative = "cd " + (dir.path() / "sequences").string() + " && " + tool +
                               " --sequence 07 --out " + bag.string();
  EXPECT_EQ(run(relative, &output), 0) << output;
  EXPECT_TRUE(contains(output, "ground truth from ../poses/07.txt"));
  EXPECT_EQ(run(tool + " --sequence x", &output), 2);
  EXPECT_TRUE(contains(output, "--out OUT.bag is required"));
}

TEST(KittiToBag, RealData) {
  const fs::path sequence = shared_data_dir() / "kitti_seq0x_51" / "sequences" / "seq0x";
  if (!fs::exists(sequence)) GTEST_SKIP() << sequence << " not present";
  TempDir dir("test_convert");
  KittiBagOptions options;
  options.sequence_dir = sequence.string();
  options.out_bag = (dir.path() / "kitti.bag").string();
  std::string error;
  ASSERT_TRUE(convert_kitti(options, &error)) << error;
  const BagData bag = read_bag(options.out_bag);
  const auto& infos = bag.infos.at("/camera/left/camera_info");
  ASSERT_EQ(infos.size(), 51u);
  EXPECT_EQ(infos[0].width, 1241u);
  EXPECT_EQ(infos[0].height, 376u);
  EXPECT_DOUBLE_EQ(infos[0].K[0], 718.856);
  EXPECT_DOUBLE_EQ(infos[0].K[2], 607.1928);
  EXPECT_EQ(bag.images.at("/camera/left/image_raw").size(), 51u);
  ASSERT_EQ(bag.ground_truth.size(), 51u);
  EXPECT_EQ(bag.ground_truth[50].header.stamp, ros::Time(6.0));  // 1 s + 5 s at 10 Hz
  // --stereo fails: the excerpt has no right images.
  options.stereo = true;
  EXPECT_FALSE(convert_kitti(options, &error));
  EXPECT_TRUE(contains(error, "image_1: no such directory"));
}

// hybrid_vo_render_sequence --kitti-dir: the rendered sequence in the KITTI layout reads back
// through the KITTI readers as rendered (poses, intrinsics, baseline, times, images), and
// hybrid_vo_kitti_to_bag turns it into the bag the renderer writes itself (same stamps, images
// and ground truth).
TEST(RenderSequence, KittiDirRoundTripsThroughTheReadersAndTheConverter) {
  TempDir dir("test_convert");
  const std::vector<std::string> args = {
      "--kitti-dir", dir.path().string(), "--kitti-name", "lowtex", "--out",
      (dir.path() / "rendered.bag").string(), "--frames", "4", "--width", "96", "--height", "72",
      "--supersampling", "1", "--stereo", "--texture", "plain"};
  std::string command = std::string(HYBRID_VO_BIN_DIR) + "/hybrid_vo_render_sequence";
  for (const std::string& a : args) command += " " + a;
  std::string output;
  ASSERT_EQ(run(command, &output), 0) << output;
  EXPECT_TRUE(contains(output, "rendered 4 frames (stereo, 96x72, corridor, plain, 10 Hz)"));
  render::SequenceOptions options;
  ASSERT_EQ(render::parse_sequence_args(args, &options), "");
  const render::Sequence seq = render::make_sequence(options);

  const fs::path sequence_dir = dir.path() / "sequences" / "lowtex";
  datasets::Sequence read;
  std::string error;
  ASSERT_TRUE(datasets::read_kitti(sequence_dir.string(), &read, &error)) << error;
  ASSERT_EQ(read.size(), 4);
  datasets::KittiCalibration calibration;
  ASSERT_TRUE(datasets::read_kitti_calibration((sequence_dir / "calib.txt").string(),
                                               &calibration, &error))
      << error;
  EXPECT_NEAR(calibration.baseline(), options.baseline, 1e-12);
  for (int i = 0; i < 4; ++i) {
    const datasets::Frame& frame = read.frames[i];
    EXPECT_NEAR(frame.timestamp, 0.1 * i, 1e-12);
    EXPECT_LT((frame.R_wc - render::frame_pose(seq, i).R_world_from_camera).norm(), 1e-11);
    EXPECT_LT((frame.c_w - render::frame_pose(seq, i).centre).norm(), 1e-11);
    const PinholeCamera& camera = frame.camera.pinhole;
    EXPECT_NEAR(camera.fx, seq.camera.fx, 1e-9);
    EXPECT_NEAR(camera.fy, seq.camera.fy, 1e-9);
    EXPECT_NEAR(camera.cx, seq.camera.cx, 1e-9);
    EXPECT_NEAR(camera.cy, seq.camera.cy, 1e-9);
    EXPECT_EQ(camera.width, 96);
    EXPECT_EQ(camera.height, 72);
    EXPECT_TRUE(same_image(cv::imread(frame.image_path, cv::IMREAD_UNCHANGED),
                           render::render_frame(seq, i).image));
    EXPECT_TRUE(same_image(
        cv::imread(datasets::kitti_image_path(sequence_dir.string(), 1, i), cv::IMREAD_UNCHANGED),
        render::render_frame(seq, i, true).image));
  }

  KittiBagOptions convert;
  convert.sequence_dir = sequence_dir.string();
  convert.out_bag = (dir.path() / "converted.bag").string();
  convert.stereo = true;
  ASSERT_TRUE(convert_kitti(convert, &error)) << error;
  const BagData rendered = read_bag((dir.path() / "rendered.bag").string());
  const BagData converted = read_bag(convert.out_bag);
  for (const std::string topic : {"/camera/left/image_raw", "/camera/right/image_raw"}) {
    ASSERT_EQ(converted.images.at(topic).size(), 4u) << topic;
    for (int i = 0; i < 4; ++i) {
      const sensor_msgs::Image& a = rendered.images.at(topic)[i];
      const sensor_msgs::Image& b = converted.images.at(topic)[i];
      EXPECT_EQ(a.header.stamp, b.header.stamp) << topic << " " << i;
      EXPECT_TRUE(same_image(mono8(a), mono8(b))) << topic << " " << i;
    }
  }
  ASSERT_EQ(converted.ground_truth.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(converted.ground_truth[i].header.stamp, rendered.ground_truth[i].header.stamp);
    expect_pose(converted.ground_truth[i].pose, render::frame_pose(seq, i), 1e-9);
  }
  EXPECT_NEAR(converted.infos.at("/camera/right/camera_info")[0].P[3],
              rendered.infos.at("/camera/right/camera_info")[0].P[3], 1e-9);

  // A second run never mixes its frames into the first one's.
  EXPECT_EQ(run(command, &output), 1) << output;
  EXPECT_TRUE(contains(output, "already exists")) << output;
}

// --compressed: CompressedImage topics as compressed_image_transport publishes them, instead of
// the raw ones; PNG holds the images exactly, JPEG closely, and a lower quality makes it smaller.
TEST(KittiToBag, CompressedImagesOnTheCompressedTopics) {
  TempDir dir("test_convert");
  KittiFixture fixture(dir.path(), kitti_rendering());
  fixture.write();
  const Rendered& r = kitti_rendering();
  std::map<int, size_t> jpeg_bytes;  // by quality
  for (const auto& [codec, quality] : std::vector<std::pair<std::string, int>>{
           {"png", 95}, {"jpeg", 95}, {"jpeg", 50}}) {
    SCOPED_TRACE(codec + " " + std::to_string(quality));
    KittiBagOptions options;
    ASSERT_EQ(parse_kitti_args({"--sequence", fixture.sequence_dir().string(), "--out",
                                (dir.path() / "out.bag").string(), "--stereo", "--compressed",
                                codec, "--jpeg-quality", std::to_string(quality)},
                               &options),
              "");
    std::string error;
    ASSERT_TRUE(convert_kitti(options, &error)) << error;
    const BagData bag = read_bag(options.out_bag);
    EXPECT_TRUE(bag.images.empty()) << "no raw images beside the compressed ones";
    for (const std::string side : {"left", "right"}) {
      SCOPED_TRACE(side);
      const auto& images = bag.compressed.at("/camera/" + side + "/image_raw/compressed");
      ASSERT_EQ(images.size(), 5u);
      EXPECT_EQ(bag.infos.at("/camera/" + side + "/camera_info").size(), 5u);
      for (int i = 0; i < 5; ++i) {
        EXPECT_EQ(images[i].header.stamp, ros::Time(1.0 + fixture.time(i)));
        EXPECT_EQ(images[i].header.frame_id, "camera_" + side + "_optical");
        EXPECT_EQ(images[i].format, codec == "png" ? "mono8; png compressed "
                                                   : "mono8; jpeg compressed mono8");
        const cv::Mat& truth = side == "left" ? r.left_images[i] : r.right_images[i];
        cv::Mat decoded;
        ASSERT_TRUE(decode_gray8(images[i].data, &decoded, &error, truth.cols, truth.rows))
            << error;
        if (codec == "png") {
          EXPECT_TRUE(same_image(decoded, truth));
        } else {
          cv::Mat difference;
          cv::absdiff(decoded, truth, difference);
          EXPECT_LT(cv::mean(difference)[0], quality == 95 ? 1.5 : 4.0);
          jpeg_bytes[quality] += images[i].data.size();
        }
      }
    }
  }
  EXPECT_LT(jpeg_bytes[50], jpeg_bytes[95]);
}

TEST(KittiToBag, CompressedArguments) {
  auto problem = [](const std::vector<std::string>& extra) {
    KittiBagOptions fresh;
    std::vector<std::string> args = {"--sequence", "s", "--out", "o.bag"};
    args.insert(args.end(), extra.begin(), extra.end());
    return parse_kitti_args(args, &fresh);
  };
  EXPECT_EQ(problem({"--compressed", "gif"}), "bad value 'gif' for --compressed (png or jpeg)");
  EXPECT_EQ(problem({"--jpeg-quality", "0"}), "bad value '0' for --jpeg-quality (1..100)");
  EXPECT_EQ(problem({"--jpeg-quality", "9x"}), "bad value '9x' for --jpeg-quality (1..100)");
  KittiBagOptions o;
  EXPECT_EQ(parse_kitti_args({"--sequence", "s", "--out", "o", "--compressed", "jpeg"}, &o), "");
  EXPECT_EQ(o.images.kind, BagImageFormat::kJpeg);
  EXPECT_EQ(o.images.jpeg_quality, 95);
  LamarBagOptions l;
  EXPECT_EQ(parse_lamar_args({"--session", "s", "--out", "o", "--compressed", "png"}, &l), "");
  EXPECT_EQ(l.images.kind, BagImageFormat::kPng);
  EXPECT_EQ(parse_lamar_args({"--session", "s", "--out", "o", "--compressed", "raw"}, &l),
            "bad value 'raw' for --compressed (png or jpeg)");
}

// ------------------------------------------------------------------------------------------------
// LaMAR

TEST(LamarToBag, RigOfTwoCamerasRoundTrips) {
  TempDir dir("test_convert");
  const Rendered& r = kitti_rendering();
  RigSession session(dir.path() / "session", r);
  session.writer.write();
  LamarBagOptions options;
  options.session_dir = session.writer.dir.string();
  options.out_bag = (dir.path() / "out.bag").string();
  std::string error;
  LamarBagSummary summary;
  ASSERT_TRUE(convert_lamar(options, &error, &summary)) << error;
  EXPECT_EQ(summary.streams, (std::vector<std::string>{"cam-left", "cam_right"}));
  EXPECT_EQ(summary.topics, (std::vector<std::string>{"/camera/cam_left", "/camera/cam_right"}));
  EXPECT_EQ(summary.ground_truth, 5);
  EXPECT_EQ(summary.time_offset, 1.0);

  const BagData bag = read_bag(options.out_bag);
  for (const std::string name : {"cam_left", "cam_right"}) {
    SCOPED_TRACE(name);
    const auto& images = bag.images.at("/camera/" + name + "/image_raw");
    const auto& infos = bag.infos.at("/camera/" + name + "/camera_info");
    ASSERT_EQ(images.size(), 5u);
    ASSERT_EQ(infos.size(), 5u);
    for (int i = 0; i < 5; ++i) {
      const ros::Time stamp(1.0 + 0.1 * i);  // 0-based microseconds + 1 s
      EXPECT_EQ(images[i].header.stamp, stamp);
      EXPECT_EQ(infos[i].header.stamp, stamp);
      EXPECT_EQ(infos[i].header.frame_id, "camera_" + name + "_optical");
      EXPECT_TRUE(
          same_image(mono8(images[i]), name == "cam_left" ? r.left_images[i] : r.right_images[i]));
      expect_intrinsics(infos[i], r.seq.camera, 1e-12);
      EXPECT_EQ(infos[i].distortion_model, "plumb_bob");
      EXPECT_EQ(infos[i].D, name == "cam_left"
                                ? std::vector<double>(5, 0.0)
                                : std::vector<double>({0.01, -0.002, 0.0001, -0.0002, 0.0}));
    }
  }
  // The first camera's pose through the rig, and the rig's cameras relative to the base.
  ASSERT_EQ(bag.ground_truth.size(), 5u);
  ASSERT_EQ(bag.tf.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    expect_pose(bag.ground_truth[i].pose, r.left[i], 1e-9);
    EXPECT_EQ(bag.tf[i].child_frame_id, "gt_camera_cam_left_optical");
  }
  ASSERT_TRUE(bag.tf_static_latched);
  ASSERT_EQ(bag.tf_static.size(), 2u);
  const Eigen::Matrix3d R_bo = render::base_from_optical();
  expect_transform(bag.tf_static[0], "base_link", "camera_cam_left_optical", R_bo,
                   Eigen::Vector3d::Zero(), 1e-12);
  expect_transform(bag.tf_static[1], "base_link", "camera_cam_right_optical", R_bo,
                   Eigen::Vector3d(0, -r.baseline, 0), 1e-9);

  // The right camera alone: its ground truth is the rig pose times its camera-to-rig transform.
  options.cameras = {"cam_right"};
  ASSERT_TRUE(convert_lamar(options, &error, &summary)) << error;
  const BagData right = read_bag(options.out_bag);
  EXPECT_EQ(right.images.size(), 1u);
  ASSERT_EQ(right.ground_truth.size(), 5u);
  for (int i = 0; i < 5; ++i) expect_pose(right.ground_truth[i].pose, r.right[i], 1e-9);
  EXPECT_EQ(right.tf_static.size(), 1u);

  // --compressed png: the same images, on the compressed topic.
  options.images.kind = BagImageFormat::kPng;
  ASSERT_TRUE(convert_lamar(options, &error, &summary)) << error;
  const BagData compressed = read_bag(options.out_bag);
  EXPECT_TRUE(compressed.images.empty());
  const auto& images = compressed.compressed.at("/camera/cam_right/image_raw/compressed");
  ASSERT_EQ(images.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    cv::Mat decoded;
    ASSERT_TRUE(decode_gray8(images[i].data, &decoded, &error)) << error;
    EXPECT_TRUE(same_image(decoded, r.right_images[i]));
  }
}

// A phone session as run_phone_to_capture writes it: one camera per frame with its own focal
// length, frames 2.. turned upright by np.rot90 (the phone held in portrait) with K and the pose
// turned to match, colour images, absolute timestamps.
TEST(LamarToBag, PhoneSessionWithPerFrameIntrinsicsAndRotatedImages) {
  TempDir dir("test_convert");
  const Rendered& r = kitti_rendering();
  LamarWriter writer(dir.path() / "session");
  std::vector<PinholeCamera> cameras;
  std::vector<render::CameraPose> poses;
  std::vector<cv::Mat> grays;
  render::RenderOptions render_options;
  render_options.noise_sigma = 0.0;
  render_options.supersampling = 2;
  const int64_t t0 = 1600000000000000;
  for (int i = 0; i < 5; ++i) {
    PinholeCamera c = r.seq.camera;
    c.fx *= 1.0 + 0.03 * i;
    c.fy *= 1.0 + 0.03 * i;
    render::CameraPose pose = r.left[i];
    cv::Mat image = render::render_view(r.seq.scene, c, pose, render_options).image;
    if (i >= 2) {
      // np.rot90(image, 1) turns counterclockwise: pixel (x, y) moves to (y, w - 1 - x).
      cv::rotate(image, image, cv::ROTATE_90_COUNTERCLOCKWISE);
      c = PinholeCamera(c.fy, c.fx, c.cy, c.width - 1 - c.cx, c.height, c.width);
      Eigen::Matrix3d Rz;
      Rz << 0, -1, 0, 1, 0, 0, 0, 0, 1;
      pose.R_world_from_camera = pose.R_world_from_camera * Rz;
    }
    const int64_t us = t0 + 100000 * i;
    const std::string id = "cam_phone_" + std::to_string(us);
    writer.sensors.push_back(LamarWriter::camera(id, c));
    writer.trajectories.push_back(std::to_string(us) + ", " + id + ", " +
                                  LamarWriter::pose(isometry(pose)));
    cv::Mat colour;
    cv::cvtColor(image, colour, cv::COLOR_GRAY2BGR);
    writer.add_image(us, id, colour);
    cameras.push_back(c);
    poses.push_back(pose);
    grays.push_back(image);
  }
  writer.write();
  LamarBagOptions options;
  options.session_dir = writer.dir.string();
  options.out_bag = (dir.path() / "phone.bag").string();
  std::string error;
  LamarBagSummary summary;
  ASSERT_TRUE(convert_lamar(options, &error, &summary)) << error;
  EXPECT_EQ(summary.streams, std::vector<std::string>{"cam_phone"});
  EXPECT_EQ(summary.time_offset, 0.0);

  const BagData bag = read_bag(options.out_bag);
  const auto& images = bag.images.at("/camera/cam_phone/image_raw");
  const auto& infos = bag.infos.at("/camera/cam_phone/camera_info");
  ASSERT_EQ(images.size(), 5u);
  ASSERT_EQ(infos.size(), 5u);
  ASSERT_EQ(bag.ground_truth.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    SCOPED_TRACE(i);
    ros::Time stamp;
    stamp.fromNSec((t0 + 100000 * i) * 1000);
    EXPECT_EQ(images[i].header.stamp, stamp);
    const cv::Mat image = mono8(images[i]);
    EXPECT_TRUE(same_image(image, grays[i]));
    expect_intrinsics(infos[i], cameras[i], 1e-9);
    expect_pose(bag.ground_truth[i].pose, poses[i], 1e-9);

    // The bag's camera_info and pose describe its image: rendering them gives the same picture,
    // and the pose of the unturned camera (a converter that lost the rotation) does not.
    const auto& K = infos[i].K;
    const PinholeCamera camera(K[0], K[4], K[2], K[5], infos[i].width, infos[i].height);
    render::CameraPose pose;
    pose.R_world_from_camera = rotation_of(bag.ground_truth[i].pose.orientation);
    const auto& p = bag.ground_truth[i].pose.position;
    pose.centre = Eigen::Vector3d(p.x, p.y, p.z);
    const cv::Mat again = render::render_view(r.seq.scene, camera, pose, render_options).image;
    EXPECT_LT(cv::norm(again, image, cv::NORM_L1) / image.total(), 1.0);
    if (i >= 2) {
      const cv::Mat wrong =
          render::render_view(r.seq.scene, camera, r.left[i], render_options).image;
      EXPECT_GT(cv::norm(wrong, image, cv::NORM_L1) / image.total(), 10.0);
    }
  }
}

TEST(LamarToBag, BadInputFailsWithFileAndLineAndLeavesNoBag) {
  struct Case {
    std::string what;
    std::function<void(RigSession*)> damage;
    std::vector<std::string> cameras;
    std::string where;  // relative to the session, with the line
    std::string message;
  };
  const std::vector<Case> cases = {
      {"NaN in a rig pose",
       [](RigSession* s) { s->writer.trajectories[2] = "100000, rig, 1, 0, 0, 0, nan, 0, 0"; },
       {},
       "trajectories.txt:3: ",
       "'nan' is not a finite number"},
      {"image size unlike its camera's",
       [](RigSession* s) {
         s->writer.sensors[2] = LamarWriter::camera("cam_right", PinholeCamera(1, 1, 1, 1, 80, 48));
       },
       {},
       "images.txt:3: ",
       "is 160x96, but "},
      {"camera model without camera_info",
       [](RigSession* s) {
         s->writer.sensors[1] = "cam-left, , camera, FOV, 160, 96, 1, 1, 1, 1, 1";
       },
       {},
       "sensors.txt:2: ",
       "camera model FOV has no camera_info equivalent"},
      {"camera model the reader does not know",
       [](RigSession* s) {
         s->writer.sensors[2] = "cam_right, , camera, EQUIRECTANGULAR, 160, 96, 1, 2";
       },
       {},
       "sensors.txt:3: ",
       "unknown camera model 'EQUIRECTANGULAR'"},
      {"undecodable image",
       [](RigSession* s) {
         write_file(s->writer.dir / "raw_data/images/cam_right/200000.png", "not a png");
       },
       {},
       "raw_data/images/cam_right/200000.png: ",
       "cannot decode image"},
      {"unknown camera",
       [](RigSession*) {},
       {"cam-left", "nope"},
       "images.txt: ",
       "no images of camera 'nope' (cameras: cam-left, cam_right)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    TempDir dir("test_convert");
    RigSession session(dir.path() / "session", kitti_rendering());
    c.damage(&session);
    session.writer.write();
    LamarBagOptions options;
    options.session_dir = session.writer.dir.string();
    options.out_bag = (dir.path() / "out.bag").string();
    options.cameras = c.cameras;
    std::string error;
    EXPECT_FALSE(convert_lamar(options, &error));
    EXPECT_TRUE(contains(error, (session.writer.dir / c.where).string()));
    EXPECT_TRUE(contains(error, c.message));
    EXPECT_TRUE(no_bag(options.out_bag));
  }
}

TEST(LamarToBag, Executable) {
  TempDir dir("test_convert");
  RigSession session(dir.path() / "session", kitti_rendering());
  session.writer.images.push_back("700000, cam_right, images/missing.png");
  session.writer.write();
  const std::string tool = std::string(HYBRID_VO_BIN_DIR) + "/hybrid_vo_lamar_to_bag";
  const fs::path bag = dir.path() / "out.bag";
  const std::string command =
      tool + " --session " + session.writer.dir.string() + " --out " + bag.string();
  std::string output;
  EXPECT_EQ(run(command, &output), 1);
  EXPECT_TRUE(
      contains(output, (session.writer.dir / "images.txt").string() + ":12: no such image"));
  EXPECT_TRUE(no_bag(bag));

  session.writer.images.pop_back();
  session.writer.write();
  EXPECT_EQ(run(command + " --cameras cam_right,cam-left --time-offset 5", &output), 0) << output;
  EXPECT_TRUE(contains(output, "cam_right: 5 images on /camera/cam_right/image_raw"));
  EXPECT_TRUE(contains(output, "replay: roslaunch hybrid_vo lamar.launch bag:=" + bag.string() +
                                   " camera:=cam_right"));
  const BagData data = read_bag(bag.string());
  ASSERT_EQ(data.ground_truth.size(), 5u);
  EXPECT_EQ(data.ground_truth[0].header.stamp, ros::Time(5.0));
  EXPECT_EQ(run(tool + " --session x --out y --cameras ,", &output), 2);
}

// The real phone query frame (../shared/data/lamar_phone_query_1), through the executable as a
// user runs it, against values read by hand from the session's files.
TEST(LamarToBag, RealPhoneQueryFrame) {
  const fs::path session = shared_data_dir() / "lamar_phone_query_1" / "sessions" /
                           "ios_2022-01-12_16.32.48_000_14911412476";
  if (!fs::exists(session)) GTEST_SKIP() << session << " not present";
  TempDir dir("test_convert");
  const fs::path bag = dir.path() / "phone.bag";
  const std::string tool = std::string(HYBRID_VO_BIN_DIR) + "/hybrid_vo_lamar_to_bag";
  // The stream is the sub-session's per-frame cameras without their timestamps; its topic name
  // is that id made a valid ROS name, which is what lamar.launch camera:= takes.
  const std::string stream = "ios_2022-01-12_16.32.48_000/cam_phone";
  const std::string name = "ios_2022_01_12_16_32_48_000_cam_phone";
  std::string output;
  ASSERT_EQ(run(tool + " --session " + session.string() + " --out " + bag.string() +
                    " --cameras " + stream,
                &output),
            0)
      << output;
  EXPECT_TRUE(contains(output, stream + ": 1 images on /camera/" + name + "/image_raw"));
  EXPECT_TRUE(contains(output, "1 ground-truth poses of " + stream + " from " +
                                   (session / "trajectories.txt").string() +
                                   "; time offset 0 s"));
  EXPECT_TRUE(contains(output, "camera:=" + name + "\n"));

  const BagData data = read_bag(bag.string());
  // 14911412476 us from the start of the recording, kept as they are (not below 1 s).
  const ros::Time stamp(14911, 412476000);
  const auto& images = data.images.at("/camera/" + name + "/image_raw");
  ASSERT_EQ(images.size(), 1u);
  EXPECT_EQ(images[0].header.stamp, stamp);
  EXPECT_EQ(images[0].header.frame_id, "camera_" + name + "_optical");
  EXPECT_EQ(mono8(images[0]).size(), cv::Size(1440, 1920));  // portrait

  // sensors.txt: PINHOLE 1440 1920 fx fy 1590.657593, c (716.893005, 939.960144) - 0.5.
  const auto& infos = data.infos.at("/camera/" + name + "/camera_info");
  ASSERT_EQ(infos.size(), 1u);
  EXPECT_EQ(infos[0].header.stamp, stamp);
  const PinholeCamera camera(1590.657593, 1590.657593, 716.393005, 939.460144, 1440, 1920);
  expect_intrinsics(infos[0], camera, 1e-9);
  EXPECT_EQ(infos[0].distortion_model, "plumb_bob");
  EXPECT_EQ(infos[0].D, std::vector<double>(5, 0.0));

  // trajectories.txt: qw qx qy qz tx ty tz, camera-to-world; the bag writes qw >= 0.
  ASSERT_EQ(data.ground_truth.size(), 1u);
  const geometry_msgs::PoseStamped& gt = data.ground_truth[0];
  EXPECT_EQ(gt.header.stamp, stamp);
  EXPECT_NEAR(gt.pose.orientation.w, 0.13748284967929092, 1e-9);
  EXPECT_NEAR(gt.pose.orientation.x, 0.3193805157658011, 1e-9);
  EXPECT_NEAR(gt.pose.orientation.y, 0.39862177517258024, 1e-9);
  EXPECT_NEAR(gt.pose.orientation.z, -0.848643171510555, 1e-9);
  EXPECT_NEAR(gt.pose.position.x, -16.152784, 1e-9);
  EXPECT_NEAR(gt.pose.position.y, 3.622267, 1e-9);
  EXPECT_NEAR(gt.pose.position.z, 30.62104, 1e-9);
}

// ------------------------------------------------------------------------------------------------
// No data lost silently: a damaged frame in the middle of a stream stops the conversion, naming the
// file, with no bag left; an undamaged stream gives exactly one message per frame on every topic.

// A phone stream as LaMAR stores it: one camera per frame (cam_phone_<us>), colour images,
// absolute timestamps, a pose per frame.
struct PhoneSession {
  LamarWriter writer;
  int64_t t0 = 1600000000000000;

  PhoneSession(const fs::path& dir, const Rendered& r) : writer(dir) {
    for (size_t i = 0; i < r.left.size(); ++i) {
      const std::string id = "cam_phone_" + std::to_string(us(i));
      writer.sensors.push_back(LamarWriter::camera(id, r.seq.camera));
      writer.trajectories.push_back(std::to_string(us(i)) + ", " + id + ", " +
                                    LamarWriter::pose(isometry(r.left[i])));
      cv::Mat colour;
      cv::cvtColor(r.left_images[i], colour, cv::COLOR_GRAY2BGR);
      writer.add_image(us(i), id, colour);
    }
  }
  int64_t us(size_t i) const { return t0 + 100000 * static_cast<int64_t>(i); }
};

// Messages per topic by stamp; /tf_static (one latched message) left out.
using Stamps = std::map<std::string, std::vector<ros::Time>>;

Stamps stamps_by_topic(const std::string& path) {
  Stamps stamps;
  rosbag::Bag bag(path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag))
    if (m.getTopic() != "/tf_static") stamps[m.getTopic()].push_back(m.getTime());
  return stamps;
}

// One stream of a converter, written into a fresh folder: the command that converts it to `bag`,
// frame 3 of 5 (its file as stored, and for LaMAR its line in images.txt), and what a complete
// bag holds: every frame's stamp once on each topic.
struct StreamCase {
  std::string command;
  fs::path frame;
  cv::Mat stored;      // frame 3's image as written (grey, or colour for the phone)
  std::string listed;  // "<session>/images.txt:<line>: ", or "" where no list names the file
  Stamps complete;
};

const int kDamagedFrame = 3;
const std::string kBinDir = HYBRID_VO_BIN_DIR;

StreamCase kitti_stream(const fs::path& dir, const fs::path& bag, bool stereo) {
  const Rendered& r = kitti_rendering();
  KittiFixture fixture(dir, r);
  fixture.write();
  StreamCase s;
  s.command = kBinDir + "/hybrid_vo_kitti_to_bag --sequence " + fixture.sequence_dir().string() +
              " --out " + bag.string() + (stereo ? " --stereo" : "");
  // In stereo the right image alone is damaged: its left twin is already in the bag by then.
  s.frame = fixture.image_path(stereo ? 1 : 0, kDamagedFrame);
  s.stored = stereo ? r.right_images[kDamagedFrame] : r.left_images[kDamagedFrame];
  std::vector<ros::Time> stamps;
  for (size_t i = 0; i < r.left.size(); ++i) stamps.push_back(ros::Time(1.0 + fixture.time(i)));
  for (const std::string side : {"left", "right"}) {
    if (side == "right" && !stereo) continue;
    s.complete["/camera/" + side + "/image_raw"] = stamps;
    s.complete["/camera/" + side + "/camera_info"] = stamps;
  }
  s.complete["/ground_truth/pose"] = stamps;
  s.complete["/tf"] = stamps;
  return s;
}

std::string images_line(const LamarWriter& writer, const std::string& relative) {
  for (size_t k = 0; k < writer.images.size(); ++k)
    if (contains(writer.images[k], relative))
      return (writer.dir / "images.txt").string() + ":" + std::to_string(k + 1) + ": ";
  ADD_FAILURE() << relative << " not in images.txt";
  return "";
}

StreamCase lamar_rig_stream(const fs::path& dir, const fs::path& bag) {
  const Rendered& r = kitti_rendering();
  RigSession session(dir / "session", r);
  session.writer.write();
  StreamCase s;
  s.command = kBinDir + "/hybrid_vo_lamar_to_bag --session " + session.writer.dir.string() +
              " --out " + bag.string();
  const std::string relative =
      "images/cam_right/" + std::to_string(100000 * kDamagedFrame) + ".png";
  s.frame = session.writer.dir / "raw_data" / relative;
  s.stored = r.right_images[kDamagedFrame];
  s.listed = images_line(session.writer, relative);
  std::vector<ros::Time> stamps;
  for (size_t i = 0; i < r.left.size(); ++i) stamps.push_back(ros::Time(1.0 + 0.1 * i));
  for (const std::string name : {"cam_left", "cam_right"}) {
    s.complete["/camera/" + name + "/image_raw"] = stamps;
    s.complete["/camera/" + name + "/camera_info"] = stamps;
  }
  s.complete["/ground_truth/pose"] = stamps;
  s.complete["/tf"] = stamps;
  return s;
}

StreamCase lamar_phone_stream(const fs::path& dir, const fs::path& bag) {
  const Rendered& r = kitti_rendering();
  PhoneSession session(dir / "session", r);
  session.writer.write();
  StreamCase s;
  s.command = kBinDir + "/hybrid_vo_lamar_to_bag --session " + session.writer.dir.string() +
              " --out " + bag.string();
  const std::string id = "cam_phone_" + std::to_string(session.us(kDamagedFrame));
  const std::string relative =
      "images/" + id + "/" + std::to_string(session.us(kDamagedFrame)) + ".png";
  s.frame = session.writer.dir / "raw_data" / relative;
  cv::cvtColor(r.left_images[kDamagedFrame], s.stored, cv::COLOR_GRAY2BGR);
  s.listed = images_line(session.writer, relative);
  std::vector<ros::Time> stamps(r.left.size());
  for (size_t i = 0; i < stamps.size(); ++i) stamps[i].fromNSec(session.us(i) * 1000);
  s.complete["/camera/cam_phone/image_raw"] = stamps;
  s.complete["/camera/cam_phone/camera_info"] = stamps;
  s.complete["/ground_truth/pose"] = stamps;
  s.complete["/tf"] = stamps;
  return s;
}

struct StreamKind {
  std::string what;
  std::function<StreamCase(const fs::path& dir, const fs::path& bag)> make;
};

const std::vector<StreamKind>& streams() {
  static const std::vector<StreamKind> all = {
      {"KITTI mono", [](const fs::path& d, const fs::path& b) { return kitti_stream(d, b, false); }},
      {"KITTI stereo, right image",
       [](const fs::path& d, const fs::path& b) { return kitti_stream(d, b, true); }},
      {"LaMAR rig, second camera", lamar_rig_stream},
      {"LaMAR phone", lamar_phone_stream},
  };
  return all;
}

std::vector<unsigned char> encoded(const std::string& extension, const cv::Mat& image,
                                   const std::vector<int>& parameters = {}) {
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes, parameters));
  return bytes;
}

void write_bytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
  write_file(path, std::string(bytes.begin(), bytes.end()));
}

// An 8x8 BMP whose header claims 60000 x 60000 pixels, beyond OpenCV's limit: cv::imread throws.
std::vector<unsigned char> bmp_claiming_a_huge_size() {
  std::vector<unsigned char> bytes = encoded(".bmp", cv::Mat(8, 8, CV_8U, cv::Scalar(7)));
  for (size_t offset : {18u, 22u})  // BITMAPINFOHEADER width, height: int32 little-endian
    for (int k = 0; k < 4; ++k) bytes[offset + k] = (60000 >> (8 * k)) & 0xFF;
  return bytes;
}

struct Damage {
  std::string what;
  std::function<void(const fs::path& file, const cv::Mat& stored)> apply;
  std::string message;  // in the error, after the file's name
};

const std::vector<Damage>& damages() {
  static const std::vector<Damage> all = {
      {"truncated PNG",
       [](const fs::path& f, const cv::Mat& image) {
         std::vector<unsigned char> bytes = encoded(".png", image);
         bytes.resize(bytes.size() / 2);
         write_bytes(f, bytes);
       },
       "cannot decode image"},
      // libjpeg decodes a JPEG cut short with a warning only, the missing rows grey.
      {"truncated JPEG",
       [](const fs::path& f, const cv::Mat& image) {
         std::vector<unsigned char> bytes = encoded(".jpg", image);
         bytes.resize(bytes.size() * 2 / 3);
         write_bytes(f, bytes);
       },
       "JPEG cut short"},
      {"zero-byte file", [](const fs::path& f, const cv::Mat&) { write_file(f, ""); },
       "empty file"},
      {"a file that is not an image",
       [](const fs::path& f, const cv::Mat&) { write_file(f, "P5\nnot an image\n"); },
       "cannot decode image"},
      {"missing file", [](const fs::path& f, const cv::Mat&) { fs::remove(f); }, "no such image"},
      {"image of another size",
       [](const fs::path& f, const cv::Mat& image) {
         cv::Mat half;
         cv::resize(image, half, image.size() / 2);
         ASSERT_TRUE(cv::imwrite(f.string(), half));
       },
       "80x48"},
      {"image of another kind (colour among grey, grey among colour)",
       [](const fs::path& f, const cv::Mat& image) {
         cv::Mat other;
         cv::cvtColor(image, other,
                      image.channels() == 1 ? cv::COLOR_GRAY2BGR : cv::COLOR_BGR2GRAY);
         ASSERT_TRUE(cv::imwrite(f.string(), other));
       },
       "-channel image, the first"},
      // IMREAD_GRAYSCALE would scale it to 8 bits without a word.
      {"16-bit image",
       [](const fs::path& f, const cv::Mat& image) {
         cv::Mat deep;
         image.convertTo(deep, image.channels() == 1 ? CV_16UC1 : CV_16UC3, 257.0);
         ASSERT_TRUE(cv::imwrite(f.string(), deep));
       },
       "16-bit image, but a bag holds 8-bit mono8"},
      // cv::imread throws on it; uncaught, the converter aborted and left OUT.bag.tmp.
      {"header claiming 60000x60000 pixels",
       [](const fs::path& f, const cv::Mat&) { write_bytes(f, bmp_claiming_a_huge_size()); },
       "cannot decode image"},
  };
  return all;
}

TEST(Converters, CompleteStreamHasOneMessagePerFrameOnEveryTopic) {
  for (const StreamKind& kind : streams()) {
    SCOPED_TRACE(kind.what);
    TempDir dir("test_convert");
    const fs::path bag = dir.path() / "out.bag";
    const StreamCase stream = kind.make(dir.path(), bag);
    std::string output;
    ASSERT_EQ(run(stream.command, &output), 0) << output;
    EXPECT_FALSE(fs::exists(bag.string() + ".tmp"));
    EXPECT_EQ(stamps_by_topic(bag.string()), stream.complete);
  }
}

TEST(Converters, DamagedFrameInTheMiddleFailsNamingTheFileAndLeavesNoBag) {
  for (const StreamKind& kind : streams()) {
    for (const Damage& damage : damages()) {
      SCOPED_TRACE(kind.what + ": " + damage.what);
      TempDir dir("test_convert");
      const fs::path bag = dir.path() / "out.bag";
      const StreamCase stream = kind.make(dir.path(), bag);
      damage.apply(stream.frame, stream.stored);
      std::string output;
      EXPECT_EQ(run(stream.command, &output), 1) << output;
      // "error: <file>: <message>", or from LaMAR "error: <images.txt>:<line>: " and the file.
      EXPECT_TRUE(contains(
          output, "error: " + (stream.listed.empty() ? stream.frame.string() : stream.listed)));
      EXPECT_TRUE(contains(output, stream.frame.string()));
      EXPECT_TRUE(contains(output, damage.message));
      EXPECT_TRUE(no_bag(bag));
    }
  }
}

// The JPEG end test on the encodings a camera writes: every prefix of a file is refused, the whole
// file is taken (with bytes after its end too), and what is taken decodes as cv::imread does.
TEST(BagWriting, JpegCutShortIsRefused) {
  const cv::Mat grey = kitti_rendering().left_images[0];
  cv::Mat colour;
  cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
  colour.col(7).setTo(cv::Scalar(0, 0, 255));
  const std::vector<std::pair<std::string, std::vector<unsigned char>>> jpegs = {
      {"baseline grey", encoded(".jpg", grey)},
      {"baseline colour", encoded(".jpg", colour)},
      {"progressive", encoded(".jpg", colour, {cv::IMWRITE_JPEG_PROGRESSIVE, 1})},
      {"restart markers", encoded(".jpg", colour, {cv::IMWRITE_JPEG_RST_INTERVAL, 2})},
  };
  TempDir dir("test_convert");
  for (const auto& [what, bytes] : jpegs) {
    SCOPED_TRACE(what);
    EXPECT_TRUE(jpeg_reaches_end(bytes));
    std::vector<unsigned char> trailing = bytes;
    trailing.insert(trailing.end(), {0x00, 0x12, 0xFF});
    EXPECT_TRUE(jpeg_reaches_end(trailing));
    int taken = 0;
    for (size_t n = 0; n < bytes.size(); ++n)
      taken += jpeg_reaches_end(std::vector<unsigned char>(bytes.begin(), bytes.begin() + n));
    EXPECT_EQ(taken, 0);

    const fs::path file = dir.path() / "image.jpg";
    write_bytes(file, bytes);
    cv::Mat mono8;
    int channels = 0;
    std::string error;
    ASSERT_TRUE(read_mono8(file.string(), &mono8, &channels, &error)) << error;
    EXPECT_EQ(channels, what == "baseline grey" ? 1 : 3);
    EXPECT_TRUE(same_image(mono8, cv::imread(file.string(), cv::IMREAD_GRAYSCALE)));
    write_bytes(file, std::vector<unsigned char>(bytes.begin(), bytes.end() - 2));  // no EOI
    EXPECT_FALSE(read_mono8(file.string(), &mono8, &channels, &error));
    EXPECT_TRUE(contains(error, file.string() + ": JPEG cut short"));
  }
}

}  // namespace
}  // namespace conversion
}  // namespace hybrid_vo
