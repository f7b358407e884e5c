#pragma once

// Data set fixtures written from the synthetic renderer in each data set's own layout, shared by
// the converter tests and the replay rostest: a rendered stereo walk, a KITTI odometry sequence
// folder, and LaMAR Capture session folders.

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "file_test_utils.h"
#include "hybrid_vo/render/sequence.h"

namespace hybrid_vo {
namespace testing {

namespace fs = std::filesystem;

inline std::string number(double v) {
  char buffer[40];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

// A few frames of the renderer's corridor walk, noiseless, with both cameras of a stereo pair.
struct Rendered {
  render::Sequence seq;
  std::vector<render::CameraPose> left, right;
  std::vector<cv::Mat> left_images, right_images;
  double baseline = 0.3;

  explicit Rendered(int frames, int width = 160, int height = 96) {
    render::SequenceOptions o;
    o.out_bag = "unused";
    o.frames = frames;
    o.width = width;
    o.height = height;
    o.noise = 0.0;
    o.supersampling = 2;
    o.stereo = true;
    o.baseline = baseline;
    o.speed = 3.0;
    seq = render::make_sequence(o);
    for (int i = 0; i < frames; ++i) {
      left.push_back(render::frame_pose(seq, i));
      right.push_back(render::frame_pose(seq, i, true));
      left_images.push_back(render::render_frame(seq, i).image);
      right_images.push_back(render::render_frame(seq, i, true).image);
    }
  }
};

// root/sequences/07/{calib.txt, times.txt, image_0/, image_1/} and root/poses/07.txt from the
// rendering; edit the lines, then write().
struct KittiFixture {
  fs::path root;
  const Rendered& r;
  std::vector<std::string> calib, times, poses;

  KittiFixture(const fs::path& root_, const Rendered& rendered) : root(root_), r(rendered) {
    const PinholeCamera& c = r.seq.camera;
    auto P = [&](double tx) {
      return number(c.fx) + " 0 " + number(c.cx) + " " + number(tx) + " 0 " + number(c.fy) + " " +
             number(c.cy) + " 0 0 0 1 0";
    };
    calib = {"P0: " + P(0.0), "P1: " + P(-c.fx * r.baseline), "P2: " + P(46.0), "P3: " + P(-3.0),
             "Tr: 1 0 0 0 0 1 0 0 0 0 1 0"};
    for (size_t i = 0; i < r.left.size(); ++i) {
      char t[32];
      std::snprintf(t, sizeof(t), "%e", 0.103625 * i);  // KITTI's own format
      times.push_back(t);
      const Eigen::Matrix3d& R = r.left[i].R_world_from_camera;
      const Eigen::Vector3d& c_w = r.left[i].centre;
      std::string line;
      for (int row = 0; row < 3; ++row)
        line += number(R(row, 0)) + " " + number(R(row, 1)) + " " + number(R(row, 2)) + " " +
                number(c_w(row)) + (row < 2 ? " " : "");
      poses.push_back(line);
    }
  }
  fs::path sequence_dir() const { return root / "sequences" / "07"; }
  fs::path poses_path() const { return root / "poses" / "07.txt"; }
  fs::path image_path(int camera, int frame) const {
    char name[32];
    std::snprintf(name, sizeof(name), "image_%d/%06d.png", camera, frame);
    return sequence_dir() / name;
  }
  double time(int i) const { return std::stod(times[i]); }
  void write() const {
    write_images();
    write_text();
  }
  void write_images() const {
    fs::create_directories(sequence_dir() / "image_0");
    fs::create_directories(sequence_dir() / "image_1");
    for (size_t i = 0; i < r.left.size(); ++i) {
      ASSERT_TRUE(cv::imwrite(image_path(0, i).string(), r.left_images[i]));
      ASSERT_TRUE(cv::imwrite(image_path(1, i).string(), r.right_images[i]));
    }
  }
  void write_text() const {
    auto lines = [](const std::vector<std::string>& v) {
      std::string text;
      for (const std::string& line : v) text += line + "\n";
      return text;
    };
    write_file(sequence_dir() / "calib.txt", lines(calib));
    write_file(sequence_dir() / "times.txt", lines(times));
    if (!poses.empty()) write_file(poses_path(), lines(poses));
  }
};

// A session folder in LaMAR's format; images are written as PNG files under raw_data/.
struct LamarWriter {
  fs::path dir;
  std::vector<std::string> sensors = {"# sensor_id, name, sensor_type, [sensor_params]+"};
  std::vector<std::string> rigs = {"# rig_id, sensor_id, qw, qx, qy, qz, tx, ty, tz"};
  std::vector<std::string> trajectories = {
      "# timestamp, device_id, qw, qx, qy, qz, tx, ty, tz, *covar"};
  std::vector<std::string> images = {"# timestamp, sensor_id, image_path"};

  explicit LamarWriter(const fs::path& d) : dir(d) {}

  static std::string pose(const Eigen::Isometry3d& T) {
    const Eigen::Quaterniond q(T.linear());
    const Eigen::Vector3d& t = T.translation();
    return number(q.w()) + ", " + number(q.x()) + ", " + number(q.y()) + ", " + number(q.z()) +
           ", " + number(t.x()) + ", " + number(t.y()) + ", " + number(t.z());
  }
  // COLMAP's principal point is ours + 0.5.
  static std::string camera(const std::string& id, const PinholeCamera& c,
                            const std::string& model = "PINHOLE",
                            const std::string& distortion = "") {
    return id + ", , camera, " + model + ", " + std::to_string(c.width) + ", " +
           std::to_string(c.height) + ", " + number(c.fx) + ", " + number(c.fy) + ", " +
           number(c.cx + 0.5) + ", " + number(c.cy + 0.5) + distortion;
  }
  void add_image(int64_t us, const std::string& sensor, const cv::Mat& image) {
    const std::string relative = "images/" + sensor + "/" + std::to_string(us) + ".png";
    fs::create_directories(dir / "raw_data" / "images" / sensor);
    ASSERT_TRUE(cv::imwrite((dir / "raw_data" / relative).string(), image));
    images.push_back(std::to_string(us) + ", " + sensor + ", " + relative);
  }
  void write() const {
    auto lines = [](const std::vector<std::string>& v) {
      std::string text;
      for (const std::string& line : v) text += line + "\n";
      return text;
    };
    write_file(dir / "sensors.txt", lines(sensors));
    if (rigs.size() > 1) write_file(dir / "rigs.txt", lines(rigs));
    if (trajectories.size() > 1) write_file(dir / "trajectories.txt", lines(trajectories));
    write_file(dir / "images.txt", lines(images));
  }
};

inline Eigen::Isometry3d isometry(const render::CameraPose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = p.R_world_from_camera;
  T.translation() = p.centre;
  return T;
}

// A HoloLens-like rig of the two rendered cameras: "cam-left" (a name that is no valid ROS name)
// and "cam_right" with OpenCV distortion coefficients, the rig frame neither camera's, the rig
// posed in trajectories.txt, 0-based timestamps.
struct RigSession {
  const Rendered& r;
  LamarWriter writer;
  Eigen::Isometry3d T_rig_left = Eigen::Isometry3d::Identity();

  RigSession(const fs::path& dir, const Rendered& rendered) : r(rendered), writer(dir) {
    T_rig_left.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).matrix();
    T_rig_left.translation() = Eigen::Vector3d(0.05, -0.02, 0.1);
    Eigen::Isometry3d T_left_right = Eigen::Isometry3d::Identity();
    T_left_right.translation() = Eigen::Vector3d(r.baseline, 0, 0);
    writer.sensors.push_back(LamarWriter::camera("cam-left", r.seq.camera));
    writer.sensors.push_back(LamarWriter::camera("cam_right", r.seq.camera, "OPENCV",
                                                 ", 0.01, -0.002, 0.0001, -0.0002"));
    writer.sensors.push_back("wifi, wifi sensor, wifi");
    writer.rigs.push_back("rig, cam-left, " + LamarWriter::pose(T_rig_left));
    writer.rigs.push_back("rig, cam_right, " + LamarWriter::pose(T_rig_left * T_left_right));
    for (size_t i = 0; i < r.left.size(); ++i) {
      const int64_t us = 100000 * i;
      const Eigen::Isometry3d T_world_rig = isometry(r.left[i]) * T_rig_left.inverse();
      writer.trajectories.push_back(std::to_string(us) + ", rig, " +
                                    LamarWriter::pose(T_world_rig));
      writer.add_image(us, "cam-left", r.left_images[i]);
      writer.add_image(us, "cam_right", r.right_images[i]);
    }
  }
};

}  // namespace testing
}  // namespace hybrid_vo
