// The data set readers (hybrid_vo/datasets) on fixtures written here into a temporary folder, so
// that every convention (camera-to-world poses, quaternion order, K from P0, the SuperGlue line
// layout) and every error path is checked without the real data. The RealData tests run on
// ../shared/data when it exists (or $HYBRID_VO_DATA) and skip otherwise.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "file_test_utils.h"
#include "hybrid_vo/datasets/kitti.h"
#include "hybrid_vo/datasets/kitti_writer.h"
#include "hybrid_vo/datasets/point_subset.h"
#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/datasets/sequence.h"
#include "hybrid_vo/datasets/text_file.h"
#include "hybrid_vo/datasets/undistorted_kitti.h"
#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;
using testing::contains;
using testing::shared_data_dir;
using testing::TempDir;
using testing::write_file;

// ------------------------------------------------------------------------------------------------
// Helpers

std::string join_lines(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

std::string numbers(std::initializer_list<double> values) {
  std::string text;
  char buffer[40];
  for (double v : values) {
    std::snprintf(buffer, sizeof(buffer), "%.17g", v);
    text += (text.empty() ? "" : " ") + std::string(buffer);
  }
  return text;
}

void expect_pose_near(const RelativePose& actual, const Eigen::Matrix3d& R,
                      const Eigen::Vector3d& t, double tolerance) {
  EXPECT_LT((actual.R - R).norm(), tolerance) << "R =\n" << actual.R << "\nexpected\n" << R;
  EXPECT_LT((actual.t - t).norm(), tolerance)
      << "t = " << actual.t.transpose() << ", expected " << t.transpose();
}

// A camera-to-world chain with a constant, known relative pose between consecutive frames:
// X_{k+1} = Rr X_k + tr.
struct PoseChain {
  Eigen::Matrix3d Rr = rotation_about(Eigen::Vector3d(0.2, 1.0, 0.1).normalized(), 0.05);
  Eigen::Vector3d tr = Eigen::Vector3d(0.01, -0.02, -1.0);
  std::vector<Eigen::Matrix3d> R_wc;
  std::vector<Eigen::Vector3d> c_w;

  explicit PoseChain(int n) {
    R_wc.push_back(rotation_about(Eigen::Vector3d(1, 2, 3).normalized(), 0.3));
    c_w.push_back(Eigen::Vector3d(1.0, -2.0, 0.5));
    for (int k = 1; k < n; ++k) {
      // T_{k+1} = T_k inv([Rr tr]): R_{k+1} = R_k Rrᵀ, c_{k+1} = c_k - R_{k+1} tr.
      R_wc.push_back(R_wc.back() * Rr.transpose());
      c_w.push_back(c_w.back() - R_wc.back() * tr);
    }
  }
};

// ------------------------------------------------------------------------------------------------
// Sequence, relative poses, pairs and scaling

TEST(RelativePose, IsInverseOfTjTimesTi) {
  Frame a, b;
  a.R_wc = rotation_about(Eigen::Vector3d(0.3, -1, 0.2).normalized(), 0.7);
  a.c_w = Eigen::Vector3d(1, 2, 3);
  b.R_wc = rotation_about(Eigen::Vector3d(1, 0.1, -0.4).normalized(), -1.1);
  b.c_w = Eigen::Vector3d(-2, 0.5, 4);
  Eigen::Matrix4d Ta = Eigen::Matrix4d::Identity(), Tb = Eigen::Matrix4d::Identity();
  Ta.topLeftCorner<3, 3>() = a.R_wc;
  Ta.topRightCorner<3, 1>() = a.c_w;
  Tb.topLeftCorner<3, 3>() = b.R_wc;
  Tb.topRightCorner<3, 1>() = b.c_w;
  const Eigen::Matrix4d expected = Tb.inverse() * Ta;
  const RelativePose pose = relative_pose(a, b);
  expect_pose_near(pose, expected.topLeftCorner<3, 3>(), expected.topRightCorner<3, 1>(), 1e-12);

  // A world point seen from both cameras: X_b = R X_a + t.
  const Eigen::Vector3d X(0.4, -1.3, 7.0);
  const Eigen::Vector3d X_a = a.R_wc.transpose() * (X - a.c_w);
  const Eigen::Vector3d X_b = b.R_wc.transpose() * (X - b.c_w);
  EXPECT_LT((pose.apply(X_a) - X_b).norm(), 1e-12);
}

TEST(RelativePose, ByIndexChecksRange) {
  Sequence sequence;
  sequence.frames.resize(2);
  EXPECT_NO_THROW(relative_pose(sequence, 0, 1));
  EXPECT_THROW(relative_pose(sequence, 0, 2), std::out_of_range);
  EXPECT_THROW(relative_pose(sequence, -1, 1), std::out_of_range);
}

TEST(MakePairs, StepsThroughTheSequence) {
  const PoseChain chain(5);
  Sequence sequence;
  for (int k = 0; k < 5; ++k) {
    Frame frame;
    frame.image_path = "image" + std::to_string(k);
    frame.R_wc = chain.R_wc[k];
    frame.c_w = chain.c_w[k];
    frame.camera.pinhole.fx = 100 + k;
    sequence.frames.push_back(frame);
  }
  const std::vector<PairWithGt> pairs = make_pairs(sequence, 2);
  ASSERT_EQ(pairs.size(), 3u);
  EXPECT_EQ(pairs[2].index0, 2);
  EXPECT_EQ(pairs[2].index1, 4);
  EXPECT_EQ(pairs[2].image_path0, "image2");
  EXPECT_EQ(pairs[2].image_path1, "image4");
  EXPECT_EQ(pairs[2].camera0.pinhole.fx, 102);
  EXPECT_EQ(pairs[2].camera1.pinhole.fx, 104);
  expect_pose_near(pairs[1].pose, chain.Rr * chain.Rr, chain.Rr * chain.tr + chain.tr, 1e-12);
  EXPECT_EQ(make_pairs(sequence, 1).size(), 4u);
  EXPECT_TRUE(make_pairs(sequence, 5).empty());
  EXPECT_TRUE(make_pairs(sequence, 0).empty());
}

CameraModel test_camera() {
  CameraModel camera;
  camera.pinhole = PinholeCamera(517.3, 516.5, 318.6, 255.3, 640, 480);
  camera.distortion = {0.26, -0.95, -0.005, 0.0026, 1.16};
  return camera;
}

TEST(Scaling, MovesThePrincipalPointByPixelCentres) {
  const CameraModel camera = test_camera();
  const CameraModel half = scaled(camera, 0.5);
  EXPECT_DOUBLE_EQ(half.pinhole.fx, 517.3 * 0.5);
  EXPECT_DOUBLE_EQ(half.pinhole.fy, 516.5 * 0.5);
  EXPECT_DOUBLE_EQ(half.pinhole.cx, (318.6 + 0.5) * 0.5 - 0.5);
  EXPECT_DOUBLE_EQ(half.pinhole.cy, (255.3 + 0.5) * 0.5 - 0.5);
  EXPECT_EQ(half.pinhole.width, 320);
  EXPECT_EQ(half.pinhole.height, 240);
  EXPECT_EQ(half.distortion, camera.distortion);
  // The image centre stays the image centre.
  CameraModel centred = camera;
  centred.pinhole.cx = (640 - 1) / 2.0;
  centred.pinhole.cy = (480 - 1) / 2.0;
  const CameraModel small = scaled(centred, 0.3);
  EXPECT_NEAR(small.pinhole.cx, (small.pinhole.width - 1) / 2.0, 1e-12);
  EXPECT_NEAR(small.pinhole.cy, (small.pinhole.height - 1) / 2.0, 1e-12);
}

TEST(Scaling, RoundTrips) {
  const CameraModel camera = test_camera();
  for (double s : {0.5, 0.25, 0.37, 2.0, 1.0 / 3.0}) {
    const CameraModel back = scaled(scaled(camera, s), 1.0 / s);
    EXPECT_NEAR(back.pinhole.fx, camera.pinhole.fx, 1e-9) << s;
    EXPECT_NEAR(back.pinhole.fy, camera.pinhole.fy, 1e-9) << s;
    EXPECT_NEAR(back.pinhole.cx, camera.pinhole.cx, 1e-9) << s;
    EXPECT_NEAR(back.pinhole.cy, camera.pinhole.cy, 1e-9) << s;
  }
  // Sizes round-trip when the factor divides them.
  const CameraModel back = scaled(scaled(camera, 0.25), 4.0);
  EXPECT_EQ(back.pinhole.width, 640);
  EXPECT_EQ(back.pinhole.height, 480);
  // resized() to an exact size and back.
  const CameraModel to_size = resized(camera, 1241, 376);
  EXPECT_EQ(to_size.pinhole.width, 1241);
  EXPECT_EQ(to_size.pinhole.height, 376);
  EXPECT_DOUBLE_EQ(to_size.pinhole.fx, 517.3 * 1241 / 640.0);
  const CameraModel again = resized(to_size, 640, 480);
  EXPECT_NEAR(again.pinhole.cx, camera.pinhole.cx, 1e-9);
  EXPECT_NEAR(again.pinhole.cy, camera.pinhole.cy, 1e-9);
  // An unknown size stays unknown.
  CameraModel unknown = camera;
  unknown.pinhole.width = unknown.pinhole.height = 0;
  EXPECT_EQ(scaled(unknown, 0.5).pinhole.width, 0);
  EXPECT_EQ(resized(unknown, 320, 240).pinhole.fx, camera.pinhole.fx);
}

// The scaled K must describe the image cv::resize produces: on an image whose value is its own x
// (or y) coordinate, pixel x' of the resized image shows source position x, and both must be the
// same ray: (x' - c') / f' = (x - c) / f.
TEST(Scaling, MatchesCvResize) {
  CameraModel camera;
  camera.pinhole = PinholeCamera(50.0, 40.0, 15.3, 10.7, 32, 24);
  cv::Mat ramp_x(24, 32, CV_32F), ramp_y(24, 32, CV_32F);
  for (int y = 0; y < 24; ++y)
    for (int x = 0; x < 32; ++x) ramp_x.at<float>(y, x) = x, ramp_y.at<float>(y, x) = y;
  struct Case {
    double s;
    int interpolation;
  };
  for (const Case& c : {Case{2.0, cv::INTER_LINEAR}, Case{0.5, cv::INTER_AREA},
                        Case{0.5, cv::INTER_LINEAR}, Case{1.5, cv::INTER_LINEAR}}) {
    cv::Mat out_x, out_y;
    cv::resize(ramp_x, out_x, cv::Size(), c.s, c.s, c.interpolation);
    cv::resize(ramp_y, out_y, cv::Size(), c.s, c.s, c.interpolation);
    const CameraModel small = scaled(camera, c.s);
    EXPECT_EQ(small.pinhole.width, out_x.cols) << c.s;
    EXPECT_EQ(small.pinhole.height, out_x.rows) << c.s;
    const PinholeCamera& p = camera.pinhole;
    const PinholeCamera& q = small.pinhole;
    // Interior pixels only: the border replicates.
    for (int y = 2; y + 2 < out_x.rows; ++y)
      for (int x = 2; x + 2 < out_x.cols; ++x) {
        EXPECT_NEAR((x - q.cx) / q.fx, (out_x.at<float>(y, x) - p.cx) / p.fx, 1e-5)
            << "s " << c.s << " x " << x;
        EXPECT_NEAR((y - q.cy) / q.fy, (out_y.at<float>(y, x) - p.cy) / p.fy, 1e-5)
            << "s " << c.s << " y " << y;
      }
  }
}

// Distortion acts on normalised coordinates, so the coefficients stay while K scales: projecting
// with the scaled model equals scaling the projected pixels.
TEST(Scaling, KeepsDistortionConsistent) {
  const CameraModel camera = test_camera();
  const double s = 0.4;
  const CameraModel small = scaled(camera, s);
  auto project = [](const CameraModel& c, const std::vector<cv::Point3d>& points) {
    const cv::Mat K = (cv::Mat_<double>(3, 3) << c.pinhole.fx, 0, c.pinhole.cx, 0, c.pinhole.fy,
                       c.pinhole.cy, 0, 0, 1);
    const cv::Mat D(1, 5, CV_64F, const_cast<double*>(c.distortion.data()));
    std::vector<cv::Point2d> pixels;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, pixels);
    return pixels;
  };
  const std::vector<cv::Point3d> points = {{0.1, 0.2, 1.0}, {-0.4, 0.3, 1.5}, {0.5, -0.35, 1.2}};
  const std::vector<cv::Point2d> full = project(camera, points), reduced = project(small, points);
  for (size_t k = 0; k < points.size(); ++k) {
    EXPECT_NEAR(reduced[k].x, (full[k].x + 0.5) * s - 0.5, 1e-9);
    EXPECT_NEAR(reduced[k].y, (full[k].y + 0.5) * s - 0.5, 1e-9);
  }
}

// ------------------------------------------------------------------------------------------------
// KITTI

// root/sequences/00/{calib.txt, times.txt, image_0/*.png} and root/poses/00.txt; edit the lines
// and write() again to break it.
struct KittiFixture {
  fs::path root;
  PoseChain chain{4};
  std::vector<std::string> calib, times, poses;

  explicit KittiFixture(const fs::path& root_) : root(root_) {
    calib = {"P0: 7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 0.000000000000e+00 "
             "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 "
             "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00",
             "P1: 7.188560000000e+02 0 6.071928000000e+02 -3.861448000000e+02 0 "
             "7.188560000000e+02 1.852157000000e+02 0 0 0 1 0"};
    for (int k = 0; k < 4; ++k) {
      times.push_back(numbers({0.1 * k}));
      const Eigen::Matrix3d& R = chain.R_wc[k];
      const Eigen::Vector3d& c = chain.c_w[k];
      poses.push_back(numbers({R(0, 0), R(0, 1), R(0, 2), c(0), R(1, 0), R(1, 1), R(1, 2), c(1),
                               R(2, 0), R(2, 1), R(2, 2), c(2)}));
    }
  }
  fs::path sequence_dir() const { return root / "sequences" / "00"; }
  std::string calib_path() const { return (sequence_dir() / "calib.txt").string(); }
  std::string times_path() const { return (sequence_dir() / "times.txt").string(); }
  std::string poses_path() const { return (root / "poses" / "00.txt").string(); }
  std::string image_path(int k) const {
    char name[16];
    std::snprintf(name, sizeof(name), "%06d.png", k);
    return (sequence_dir() / "image_0" / name).string();
  }
  void write() const {
    write_file(calib_path(), join_lines(calib));
    write_file(times_path(), join_lines(times));
    write_file(poses_path(), join_lines(poses));
    fs::create_directories(sequence_dir() / "image_0");
    for (int k = 0; k < 4; ++k)
      ASSERT_TRUE(cv::imwrite(image_path(k), cv::Mat(7, 12, CV_8U, cv::Scalar(k))));
  }
};

TEST(Kitti, ReadsTheLayoutAndRecoversTheRelativePose) {
  TempDir dir;
  KittiFixture fixture(dir.path());
  fixture.write();
  const std::string sequence_dir = fixture.sequence_dir().string();
  for (const std::string& path : {dir.path().string(), sequence_dir, sequence_dir + "/"}) {
    Sequence sequence;
    std::string error;
    ASSERT_TRUE(read_kitti(path, &sequence, &error)) << path << ": " << error;
    EXPECT_EQ(sequence.name, "00");
    EXPECT_EQ(sequence.format, "kitti");
    ASSERT_EQ(sequence.size(), 4);
    const PinholeCamera& p = sequence.frames[3].camera.pinhole;
    EXPECT_DOUBLE_EQ(p.fx, 718.856);
    EXPECT_DOUBLE_EQ(p.fy, 718.856);
    EXPECT_DOUBLE_EQ(p.cx, 607.1928);
    EXPECT_DOUBLE_EQ(p.cy, 185.2157);
    EXPECT_EQ(p.width, 12);
    EXPECT_EQ(p.height, 7);
    EXPECT_EQ(sequence.frames[3].camera.distortion, (std::array<double, 5>{0, 0, 0, 0, 0}));
    EXPECT_DOUBLE_EQ(sequence.frames[2].timestamp, 0.2);
    EXPECT_EQ(fs::path(sequence.frames[2].image_path), fs::path(fixture.image_path(2)));
    expect_pose_near(relative_pose(sequence, 0, 1), fixture.chain.Rr, fixture.chain.tr, 1e-12);
    expect_pose_near(relative_pose(sequence, 2, 3), fixture.chain.Rr, fixture.chain.tr, 1e-12);
    expect_pose_near(relative_pose(sequence, 1, 0), fixture.chain.Rr.transpose(),
                     -fixture.chain.Rr.transpose() * fixture.chain.tr, 1e-12);
  }
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_sequence("kitti", dir.path().string(), &sequence, &error)) << error;
  EXPECT_EQ(sequence.size(), 4);
}

TEST(Kitti, TrailingBlankLinesAreFine) {
  TempDir dir;
  KittiFixture fixture(dir.path());
  fixture.poses.push_back("");
  fixture.times.push_back("  ");
  fixture.write();
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_kitti(dir.path().string(), &sequence, &error)) << error;
  EXPECT_EQ(sequence.size(), 4);
}

struct BrokenCase {
  std::string what;
  std::function<void()> damage;  // edits the fixture
  std::function<std::string()> expected_location;
  std::string expected_message;
};

TEST(Kitti, ReportsMissingFilesAndMalformedLines) {
  TempDir dir;
  KittiFixture* f = nullptr;
  const std::vector<BrokenCase> cases = {
      {"pose with 11 fields", [&] { f->poses[1] = numbers({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}); },
       [&] { return f->poses_path() + ":2:"; }, "expected 12 fields"},
      {"NaN in a pose", [&] { f->poses[2] = "1 0 0 0 0 1 0 0 0 0 1 nan"; },
       [&] { return f->poses_path() + ":3:"; }, "'nan' is not a finite number"},
      {"word in a pose", [&] { f->poses[0] = "1 0 0 0 0 1 0 0 0 0 1 abc"; },
       [&] { return f->poses_path() + ":1:"; }, "'abc' is not a finite number"},
      {"scaled rotation", [&] { f->poses[1] = "2 0 0 0 0 2 0 0 0 0 2 0"; },
       [&] { return f->poses_path() + ":2:"; }, "not a rotation"},
      {"reflection", [&] { f->poses[1] = "-1 0 0 0 0 1 0 0 0 0 1 0"; },
       [&] { return f->poses_path() + ":2:"; }, "not a rotation"},
      {"blank line inside", [&] { f->poses.insert(f->poses.begin() + 1, ""); },
       [&] { return f->poses_path() + ":2:"; }, "empty line"},
      {"timestamp not a number", [&] { f->times[3] = "0.3s"; },
       [&] { return f->times_path() + ":4:"; }, "'0.3s' is not a finite number"},
      {"two timestamps on a line", [&] { f->times[1] = "0.1 0.2"; },
       [&] { return f->times_path() + ":2:"; }, "expected 1 fields"},
      {"fewer poses than frames", [&] { f->poses.pop_back(); },
       [&] { return f->poses_path() + ":"; }, "3 poses for 4 frames"},
      {"P0 with 11 numbers", [&] { f->calib[0] = "P0: 1 0 1 0 0 1 1 0 0 0 1"; },
       [&] { return f->calib_path() + ":1:"; }, "expected 13 fields"},
      {"P0 with inf", [&] { f->calib[0] = "P0: 1 0 1 0 0 inf 1 0 0 0 1 0"; },
       [&] { return f->calib_path() + ":1:"; }, "'inf' is not a finite number"},
      {"P0 with skew", [&] { f->calib[0] = "P0: 700 3 600 0 0 700 180 0 0 0 1 0"; },
       [&] { return f->calib_path() + ":1:"; }, "skew"},
      {"no P0", [&] { f->calib.erase(f->calib.begin()); },
       [&] { return f->calib_path() + ":"; }, "no 'P0:' line"},
      {"missing calib.txt", [&] { f->calib.clear(); },
       [&] { return f->calib_path() + ":"; }, "no such file"},
      {"missing poses", [&] { f->poses.clear(); },
       [&] { return f->poses_path() + ":"; }, "no such file"},
      {"missing image", [&] { f->times.push_back("0.4"); f->poses.push_back(f->poses[0]); },
       [&] { return (f->sequence_dir() / "image_0" / "000004.png").string(); }, "no such image"},
  };
  for (const BrokenCase& c : cases) {
    SCOPED_TRACE(c.what);
    fs::remove_all(dir.path() / "case");
    KittiFixture fixture(dir.path() / "case");
    f = &fixture;
    c.damage();
    fixture.write();
    if (fixture.calib.empty()) fs::remove(fixture.calib_path());
    if (fixture.poses.empty()) fs::remove(fixture.poses_path());
    Sequence sequence;
    std::string error;
    EXPECT_FALSE(read_kitti(fixture.root.string(), &sequence, &error));
    EXPECT_TRUE(contains(error, c.expected_location()));
    EXPECT_TRUE(contains(error, c.expected_message));
  }
}

TEST(Kitti, RootWithSeveralSequencesIsAmbiguous) {
  TempDir dir;
  KittiFixture fixture(dir.path());
  fixture.write();
  fs::create_directories(dir.path() / "sequences" / "01");
  Sequence sequence;
  std::string error;
  EXPECT_FALSE(read_kitti(dir.path().string(), &sequence, &error));
  EXPECT_TRUE(contains(error, "2 sequences"));
  EXPECT_TRUE(read_kitti(fixture.sequence_dir().string(), &sequence, &error)) << error;
  EXPECT_FALSE(read_kitti((dir.path() / "nowhere").string(), &sequence, &error));
  EXPECT_TRUE(contains(error, "no such directory"));
}

// A stereo sequence written by KittiWriter reads back through read_kitti and the file readers:
// intrinsics, baseline, times, poses and the images themselves.
TEST(KittiWriter, RoundTripsThroughTheReaders) {
  TempDir dir;
  const PinholeCamera camera(420.5, 421.25, 159.5, 119.25);
  const double baseline = 0.12;
  const PoseChain chain(5);
  std::vector<cv::Mat> left, right;
  KittiWriter writer;
  std::string error;
  ASSERT_TRUE(writer.open(dir.path().string(), "lowtex", camera, baseline, &error)) << error;
  for (int k = 0; k < 5; ++k) {
    left.emplace_back(24, 32, CV_8U);
    right.emplace_back(24, 32, CV_8U);
    cv::randu(left.back(), 0, 256);
    cv::randu(right.back(), 0, 256);
    ASSERT_TRUE(writer.add_frame(0.1 * k, left[k], right[k], chain.R_wc[k], chain.c_w[k], &error))
        << error;
  }
  ASSERT_TRUE(writer.close(&error)) << error;
  EXPECT_EQ(writer.frames(), 5);
  EXPECT_EQ(fs::path(writer.sequence_dir()), dir.path() / "sequences" / "lowtex");
  EXPECT_EQ(fs::path(writer.poses_path()), dir.path() / "poses" / "lowtex.txt");

  KittiCalibration calibration;
  ASSERT_TRUE(read_kitti_calibration(writer.sequence_dir() + "/calib.txt", &calibration, &error))
      << error;
  for (const KittiProjection* P : {&calibration.P0, &calibration.P1}) {
    EXPECT_NEAR(P->camera.fx, camera.fx, 1e-9);
    EXPECT_NEAR(P->camera.fy, camera.fy, 1e-9);
    EXPECT_NEAR(P->camera.cx, camera.cx, 1e-9);
    EXPECT_NEAR(P->camera.cy, camera.cy, 1e-9);
  }
  EXPECT_NEAR(calibration.baseline(), baseline, 1e-12);
  EXPECT_EQ(count_kitti_images(writer.sequence_dir(), 0), 5);
  EXPECT_EQ(count_kitti_images(writer.sequence_dir(), 1), 5);

  Sequence sequence;
  ASSERT_TRUE(read_kitti(dir.path().string(), &sequence, &error)) << error;
  EXPECT_EQ(sequence.name, "lowtex");
  ASSERT_EQ(sequence.size(), 5);
  for (int k = 0; k < 5; ++k) {
    const Frame& frame = sequence.frames[k];
    EXPECT_NEAR(frame.timestamp, 0.1 * k, 1e-12);
    EXPECT_LT((frame.R_wc - chain.R_wc[k]).norm(), 1e-11);
    EXPECT_LT((frame.c_w - chain.c_w[k]).norm(), 1e-11);
    EXPECT_EQ(frame.camera.pinhole.width, 32);
    EXPECT_EQ(frame.camera.pinhole.height, 24);
    EXPECT_EQ(cv::norm(cv::imread(frame.image_path, cv::IMREAD_UNCHANGED), left[k], cv::NORM_INF),
              0.0);
    EXPECT_EQ(cv::norm(cv::imread(kitti_image_path(writer.sequence_dir(), 1, k),
                                  cv::IMREAD_UNCHANGED),
                       right[k], cv::NORM_INF),
              0.0);
  }
  expect_pose_near(relative_pose(sequence, 1, 2), chain.Rr, chain.tr, 1e-10);

  // Mono: P0 only, no image_1.
  KittiWriter mono;
  ASSERT_TRUE(mono.open(dir.path().string(), "mono", camera, 0.0, &error)) << error;
  ASSERT_TRUE(mono.add_frame(0.0, left[0], cv::Mat(), chain.R_wc[0], chain.c_w[0], &error))
      << error;
  ASSERT_TRUE(mono.close(&error)) << error;
  ASSERT_TRUE(read_kitti_calibration(mono.sequence_dir() + "/calib.txt", &calibration, &error));
  EXPECT_FALSE(calibration.P1.present());
  EXPECT_EQ(count_kitti_images(mono.sequence_dir(), 1), -1);
}

TEST(KittiWriter, RefusesBadInputWithTheReason) {
  TempDir dir;
  const std::string root = dir.path().string();
  const PinholeCamera camera(400, 400, 15.5, 11.5);
  const cv::Mat image(24, 32, CV_8U, cv::Scalar(7));
  const Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d c = Eigen::Vector3d::Zero();
  std::string error;
  KittiWriter w;
  EXPECT_FALSE(w.open(root, "a", PinholeCamera(0, 400, 15.5, 11.5), 0.0, &error));
  EXPECT_TRUE(contains(error, "invalid camera"));
  EXPECT_FALSE(w.open(root, "a", camera, -0.1, &error));
  EXPECT_TRUE(contains(error, "baseline"));
  EXPECT_FALSE(w.open(root, "a/b", camera, 0.0, &error));
  EXPECT_TRUE(contains(error, "not a sequence name"));
  EXPECT_FALSE(w.open("/proc/no_such_root", "a", camera, 0.0, &error));
  EXPECT_TRUE(contains(error, "cannot create"));
  EXPECT_FALSE(w.add_frame(0.0, image, image, R, c, &error));
  EXPECT_TRUE(contains(error, "not open"));

  ASSERT_TRUE(w.open(root, "a", camera, 0.1, &error)) << error;
  EXPECT_FALSE(w.add_frame(0.0, image, cv::Mat(), R, c, &error));
  EXPECT_TRUE(contains(error, "frame 0: right image is not 8-bit grey"));
  EXPECT_FALSE(w.add_frame(0.0, cv::Mat(24, 32, CV_16U), image, R, c, &error));
  EXPECT_TRUE(contains(error, "left image is not 8-bit grey"));
  EXPECT_FALSE(w.add_frame(0.0, image, image, R * std::nan(""), c, &error));
  EXPECT_TRUE(contains(error, "the pose is not finite"));
  ASSERT_TRUE(w.add_frame(0.0, image, image, R, c, &error)) << error;
  EXPECT_FALSE(w.add_frame(0.0, image, image, R, c, &error));
  EXPECT_TRUE(contains(error, "frame 1: time 0.000000000000e+00 does not increase"));
  EXPECT_FALSE(w.add_frame(0.1, cv::Mat(12, 16, CV_8U), cv::Mat(12, 16, CV_8U), R, c, &error));
  EXPECT_TRUE(contains(error, "left image is 16x12, not 32x24 as before"));
  ASSERT_TRUE(w.close(&error)) << error;
  EXPECT_FALSE(w.add_frame(0.2, image, image, R, c, &error));
  EXPECT_TRUE(contains(error, "not open"));
  KittiWriter empty;
  ASSERT_TRUE(empty.open(root, "empty", camera, 0.0, &error)) << error;
  EXPECT_FALSE(empty.close(&error));
  EXPECT_TRUE(contains(error, "no frames"));
  // An existing sequence is never mixed with a new one.
  KittiWriter again;
  EXPECT_FALSE(again.open(root, "a", camera, 0.0, &error));
  EXPECT_TRUE(contains(error, "already exists"));
}

// A distorted sequence in the KITTI layout: a spot at a distorted pixel lands at its undistorted
// pixel, times start at zero, the poses read back as they were, and what the layout cannot hold
// is refused.
TEST(UndistortedKitti, UndistortsTheImagesAndKeepsTimesAndPoses) {
  TempDir dir;
  CameraModel camera;
  camera.pinhole = PinholeCamera(517.3, 516.5, 318.6, 255.3, 640, 480);
  camera.distortion = {0.2624, -0.9531, -0.0054, 0.0026, 1.1633};  // TUM fr1's lens
  const Eigen::Vector2d undistorted(520.0, 400.0);
  const Eigen::Vector2d distorted = camera.distort(undistorted);
  ASSERT_GT((distorted - undistorted).norm(), 5.0);
  PoseChain chain(3);
  Sequence sequence;
  for (int i = 0; i < 3; ++i) {
    cv::Mat image(480, 640, CV_8UC3, cv::Scalar::all(0));
    cv::circle(image, cv::Point(cvRound(distorted.x()), cvRound(distorted.y())), 3,
               cv::Scalar::all(255), cv::FILLED);
    Frame frame;
    frame.image_path = (dir.path() / ("in" + std::to_string(i) + ".png")).string();
    ASSERT_TRUE(cv::imwrite(frame.image_path, image));
    frame.timestamp = 1305031102.175304 + 0.033 * i;
    frame.R_wc = chain.R_wc[i];
    frame.c_w = chain.c_w[i];
    frame.camera = camera;
    sequence.frames.push_back(frame);
  }
  UndistortedKittiSummary summary;
  std::string error;
  ASSERT_TRUE(write_undistorted_kitti(sequence, (dir.path() / "out").string(), "00", &summary,
                                      &error))
      << error;
  EXPECT_EQ(summary.frames, 3);
  EXPECT_TRUE(summary.undistorted);
  Sequence back;
  ASSERT_TRUE(read_kitti((dir.path() / "out" / "sequences" / "00").string(), &back, &error))
      << error;
  ASSERT_EQ(back.size(), 3);
  EXPECT_NEAR(back.frames[0].timestamp, 0.0, 1e-9);
  EXPECT_NEAR(back.frames[2].timestamp, 0.066, 1e-6);
  EXPECT_FALSE(back.frames[0].camera.has_distortion());
  EXPECT_DOUBLE_EQ(back.frames[0].camera.pinhole.fx, 517.3);
  expect_pose_near(relative_pose(back, 0, 1), chain.Rr, chain.tr, 1e-6);
  const cv::Mat out = cv::imread(back.frames[1].image_path, cv::IMREAD_UNCHANGED);
  ASSERT_EQ(out.type(), CV_8UC1);
  const cv::Moments m = cv::moments(out > 128, true);
  ASSERT_GT(m.m00, 5.0);
  EXPECT_NEAR(m.m10 / m.m00, undistorted.x(), 1.0);
  EXPECT_NEAR(m.m01 / m.m00, undistorted.y(), 1.0);

  // Refused: nothing to write, a fisheye, a second camera, an existing sequence.
  EXPECT_FALSE(write_undistorted_kitti(Sequence(), (dir.path() / "e").string(), "00", &summary,
                                       &error));
  Sequence fisheye = sequence;
  for (Frame& f : fisheye.frames) f.camera.model = LensModel::kEquidistant;
  EXPECT_FALSE(write_undistorted_kitti(fisheye, (dir.path() / "f").string(), "00", &summary,
                                       &error));
  EXPECT_TRUE(contains(error, "fisheye")) << error;
  Sequence two = sequence;
  two.frames[2].camera.pinhole.fx = 500.0;
  EXPECT_FALSE(write_undistorted_kitti(two, (dir.path() / "t").string(), "00", &summary, &error));
  EXPECT_TRUE(contains(error, "camera other")) << error;
  EXPECT_FALSE(write_undistorted_kitti(sequence, (dir.path() / "out").string(), "00", &summary,
                                       &error));
  EXPECT_TRUE(contains(error, "already exists")) << error;
}

// ------------------------------------------------------------------------------------------------
// TUM

std::string tum_pose_line(double time, const Eigen::Matrix3d& R_wc, const Eigen::Vector3d& c_w,
                          bool flip_sign = false) {
  Eigen::Quaterniond q(R_wc);
  if (flip_sign) q.coeffs() *= -1.0;
  return numbers({time, c_w.x(), c_w.y(), c_w.z(), q.x(), q.y(), q.z(), q.w()});
}

// Ground truth: s0 at 1.000 and s1 at 1.100 one chain step apart; s2 at 1.200 and s3 at 1.210
// (quaternion sign flipped) for interpolation; s4 at 1.380, the last. Images at 1.000 and 1.100
// (exact samples), 1.204 (between s2 and s3: nearest s2, interpolated at 0.4), 1.350 (30 ms from
// s4: no ground truth) and 1.395 (15 ms after s4, nothing later: nearest).
struct TumFixture {
  fs::path dir;
  PoseChain chain{2};
  Eigen::Matrix3d R_base = rotation_about(Eigen::Vector3d(0.5, -0.2, 1).normalized(), 1.0);
  double a2 = 0.2, a3 = 0.3;  // rotation angles about z of s2 and s3 after R_base
  Eigen::Vector3d c2{0.5, 0.6, 0.7}, c3{0.6, 0.4, 0.9}, c4{2.0, 2.0, 2.0};
  std::vector<std::string> rgb, groundtruth, camera;

  explicit TumFixture(const fs::path& dir_) : dir(dir_) {
    rgb = {"# color images", "# file: 'fixture'", "# timestamp filename", "1.000 rgb/1.000.png",
           "1.100 rgb/1.100.png", "1.204 rgb/1.204.png", "1.350 rgb/1.350.png",
           "1.395 rgb/1.395.png"};
    // Out of order, with leading spaces and a blank line, as real files may be.
    groundtruth = {"# ground truth trajectory",
                   "# timestamp tx ty tz qx qy qz qw",
                   "   " + tum_pose_line(1.38, R_base, c4),
                   tum_pose_line(1.21, R_base * rotation_about(Eigen::Vector3d::UnitZ(), a3), c3,
                                 true),
                   "",
                   tum_pose_line(1.0, chain.R_wc[0], chain.c_w[0]),
                   tum_pose_line(1.1, chain.R_wc[1], chain.c_w[1]),
                   tum_pose_line(1.2, R_base * rotation_about(Eigen::Vector3d::UnitZ(), a2), c2)};
    camera = {"# fixture camera", "fx 517.306408", "fy 516.469215", "cx 318.643040",
              "cy 255.313989", "k1 0.262383", "k2 -0.953104", "p1 -0.005358", "p2 0.002628",
              "k3 1.163314", "width 640", "height 480"};
  }
  std::string rgb_path() const { return (dir / "rgb.txt").string(); }
  std::string gt_path() const { return (dir / "groundtruth.txt").string(); }
  std::string camera_path() const { return (dir / "camera.txt").string(); }
  void write() const {
    write_file(rgb_path(), join_lines(rgb));
    write_file(gt_path(), join_lines(groundtruth));
    write_file(camera_path(), join_lines(camera));
    for (const char* name : {"1.000", "1.100", "1.204", "1.350", "1.395"})
      write_file(dir / "rgb" / (std::string(name) + ".png"), "");
  }
};

TEST(Tum, ReadsCameraAndRecoversTheRelativePose) {
  TempDir dir;
  TumFixture fixture(dir.path() / "fr1_fixture");
  fixture.write();
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_tum(fixture.dir.string(), &sequence, &error)) << error;
  EXPECT_EQ(sequence.name, "fr1_fixture");
  EXPECT_EQ(sequence.format, "tum");
  ASSERT_EQ(sequence.size(), 4);
  EXPECT_EQ(sequence.skipped_frames, 1);
  const CameraModel& camera = sequence.frames[0].camera;
  EXPECT_DOUBLE_EQ(camera.pinhole.fx, 517.306408);
  EXPECT_DOUBLE_EQ(camera.pinhole.fy, 516.469215);
  EXPECT_DOUBLE_EQ(camera.pinhole.cx, 318.643040);
  EXPECT_DOUBLE_EQ(camera.pinhole.cy, 255.313989);
  EXPECT_EQ(camera.pinhole.width, 640);
  EXPECT_EQ(camera.pinhole.height, 480);
  EXPECT_EQ(camera.distortion,
            (std::array<double, 5>{0.262383, -0.953104, -0.005358, 0.002628, 1.163314}));
  EXPECT_EQ(fs::path(sequence.frames[1].image_path), fixture.dir / "rgb" / "1.100.png");
  EXPECT_DOUBLE_EQ(sequence.frames[1].timestamp, 1.1);
  expect_pose_near(relative_pose(sequence, 0, 1), fixture.chain.Rr, fixture.chain.tr, 1e-12);
  Sequence via_dispatch;
  ASSERT_TRUE(read_sequence("tum", fixture.dir.string(), &via_dispatch, &error)) << error;
  EXPECT_EQ(via_dispatch.size(), 4);
}

TEST(Tum, AssociatesNearestSampleAndSkipsFramesWithoutGt) {
  TempDir dir;
  TumFixture fixture(dir.path());
  fixture.write();
  TumOptions options;
  options.interpolate = false;
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_tum(dir.path().string(), &sequence, &error, options)) << error;
  ASSERT_EQ(sequence.size(), 4);
  EXPECT_EQ(sequence.skipped_frames, 1);
  const std::vector<double> times = {1.0, 1.1, 1.204, 1.395};  // 1.350 is skipped
  for (int k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(sequence.frames[k].timestamp, times[k]);
  // 1.204 takes s2 (4 ms away), not s3 (6 ms away).
  const Frame& between = sequence.frames[2];
  EXPECT_LT((between.c_w - fixture.c2).norm(), 1e-12);
  EXPECT_LT((between.R_wc -
             fixture.R_base * rotation_about(Eigen::Vector3d::UnitZ(), fixture.a2)).norm(),
            1e-12);
  // 1.395 takes s4, the last sample, 15 ms before it.
  EXPECT_LT((sequence.frames[3].c_w - fixture.c4).norm(), 1e-12);

  // A tighter tolerance drops 1.204 (4 ms) and 1.395 (15 ms) as well.
  options.max_time_difference = 0.003;
  ASSERT_TRUE(read_tum(dir.path().string(), &sequence, &error, options)) << error;
  EXPECT_EQ(sequence.size(), 2);
  EXPECT_EQ(sequence.skipped_frames, 3);
}

TEST(Tum, InterpolatesBetweenBracketingSamples) {
  TempDir dir;
  TumFixture fixture(dir.path());
  fixture.write();
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_tum(dir.path().string(), &sequence, &error)) << error;
  ASSERT_EQ(sequence.size(), 4);
  const double alpha = 0.4;  // (1.204 - 1.200) / (1.210 - 1.200)
  const Frame& between = sequence.frames[2];
  EXPECT_LT((between.c_w - ((1 - alpha) * fixture.c2 + alpha * fixture.c3)).norm(), 1e-9);
  // Slerp along the shorter arc even though s3's quaternion has the opposite sign.
  const Eigen::Matrix3d expected =
      fixture.R_base *
      rotation_about(Eigen::Vector3d::UnitZ(), fixture.a2 + alpha * (fixture.a3 - fixture.a2));
  EXPECT_LT((between.R_wc - expected).norm(), 1e-9) << between.R_wc << "\n" << expected;
  // Nothing after the last sample: nearest.
  EXPECT_LT((sequence.frames[3].c_w - fixture.c4).norm(), 1e-12);

  // A bracket wider than max_interpolation_gap falls back to the nearest sample.
  TumOptions options;
  options.max_interpolation_gap = 0.005;
  ASSERT_TRUE(read_tum(dir.path().string(), &sequence, &error, options)) << error;
  EXPECT_LT((sequence.frames[2].c_w - fixture.c2).norm(), 1e-12);
}

TEST(Tum, ReportsMissingFilesAndMalformedLines) {
  TempDir dir;
  TumFixture* f = nullptr;
  const std::vector<BrokenCase> cases = {
      {"ground truth with 7 fields", [&] { f->groundtruth[5] = "1.0 0 0 0 0 0 1"; },
       [&] { return f->gt_path() + ":6:"; }, "expected 8 fields"},
      {"NaN in ground truth", [&] { f->groundtruth[6] = "1.1 0 nan 0 0 0 0 1"; },
       [&] { return f->gt_path() + ":7:"; }, "'nan' is not a finite number"},
      {"word in ground truth", [&] { f->groundtruth[2] = "1.38 0 0 0 0 0 0 one"; },
       [&] { return f->gt_path() + ":3:"; }, "'one' is not a finite number"},
      {"zero quaternion", [&] { f->groundtruth[2] = "1.38 0 0 0 0 0 0 0"; },
       [&] { return f->gt_path() + ":3:"; }, "quaternion"},
      {"rgb timestamp not a number", [&] { f->rgb[4] = "1.1x rgb/1.100.png"; },
       [&] { return f->rgb_path() + ":5:"; }, "'1.1x' is not a finite number"},
      {"rgb line with 3 fields", [&] { f->rgb[3] = "1.000 rgb/1.000.png extra"; },
       [&] { return f->rgb_path() + ":4:"; }, "expected 2 fields"},
      {"missing image", [&] { f->rgb[4] = "1.100 rgb/gone.png"; },
       [&] { return f->rgb_path() + ":5:"; }, "no such image"},
      {"camera: unknown key", [&] { f->camera[5] = "k4 0.1"; },
       [&] { return f->camera_path() + ":6:"; }, "unknown key 'k4'"},
      {"camera: repeated key", [&] { f->camera[5] = "fx 1"; },
       [&] { return f->camera_path() + ":6:"; }, "repeated key 'fx'"},
      {"camera: not a number", [&] { f->camera[2] = "fy abc"; },
       [&] { return f->camera_path() + ":3:"; }, "'abc' is not a finite number"},
      {"camera: no value", [&] { f->camera[3] = "cx"; },
       [&] { return f->camera_path() + ":4:"; }, "expected 2 fields"},
      {"camera: no fx", [&] { f->camera.erase(f->camera.begin() + 1); },
       [&] { return f->camera_path() + ":"; }, "no 'fx'"},
      {"no frame with ground truth", [&] { f->rgb = {"1.350 rgb/1.350.png"}; },
       [&] { return f->rgb_path() + ":"; }, "no image has ground truth"},
      {"missing camera.txt", [&] { f->camera.clear(); },
       [&] { return f->camera_path() + ":"; }, "no such file"},
      {"missing groundtruth.txt", [&] { f->groundtruth.clear(); },
       [&] { return f->gt_path() + ":"; }, "no such file"},
      {"missing rgb.txt", [&] { f->rgb.clear(); },
       [&] { return f->rgb_path() + ":"; }, "no such file"},
  };
  for (const BrokenCase& c : cases) {
    SCOPED_TRACE(c.what);
    fs::remove_all(dir.path() / "case");
    TumFixture fixture(dir.path() / "case");
    f = &fixture;
    c.damage();
    fixture.write();
    if (fixture.camera.empty()) fs::remove(fixture.camera_path());
    if (fixture.groundtruth.empty()) fs::remove(fixture.gt_path());
    if (fixture.rgb.empty()) fs::remove(fixture.rgb_path());
    Sequence sequence;
    std::string error;
    EXPECT_FALSE(read_tum(fixture.dir.string(), &sequence, &error));
    EXPECT_TRUE(contains(error, c.expected_location()));
    EXPECT_TRUE(contains(error, c.expected_message));
  }
}

// ------------------------------------------------------------------------------------------------
// Strecha

// scene/images/000k.jpg and scene/gt_dense_cameras/000k.jpg.camera, a different K per image.
struct StrechaFixture {
  fs::path dir;
  PoseChain chain{3};
  std::vector<std::vector<std::string>> cameras;

  explicit StrechaFixture(const fs::path& dir_) : dir(dir_) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Matrix3d& R = chain.R_wc[k];
      const Eigen::Vector3d& C = chain.c_w[k];
      cameras.push_back({numbers({2759.48 + k, 0, 1520.69}) + " ",
                         numbers({0, 2764.16 + k, 1006.81}) + " ", "0 0 1 ", "0 0 0",
                         numbers({R(0, 0), R(0, 1), R(0, 2)}) + " ",
                         numbers({R(1, 0), R(1, 1), R(1, 2)}) + " ",
                         numbers({R(2, 0), R(2, 1), R(2, 2)}) + " ",
                         numbers({C(0), C(1), C(2)}) + " ", "3072 2048"});
    }
  }
  std::string image_name(int k) const { return "000" + std::to_string(k) + ".jpg"; }
  std::string camera_path(int k) const {
    return (dir / "gt_dense_cameras" / (image_name(k) + ".camera")).string();
  }
  void write() const {
    for (int k = 0; k < 3; ++k) {
      write_file(camera_path(k), join_lines(cameras[k]));
      write_file(dir / "images" / image_name(k), "");
    }
    write_file(dir / "images" / "K.txt", "2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n");
  }
};

TEST(Strecha, ReadsPerImageCamerasAndRecoversTheRelativePose) {
  TempDir dir;
  StrechaFixture fixture(dir.path() / "fountain-P3");
  fixture.write();
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_strecha(fixture.dir.string(), &sequence, &error)) << error;
  EXPECT_EQ(sequence.name, "fountain-P3");
  EXPECT_EQ(sequence.format, "strecha");
  ASSERT_EQ(sequence.size(), 3);
  for (int k = 0; k < 3; ++k) {
    const PinholeCamera& p = sequence.frames[k].camera.pinhole;
    EXPECT_DOUBLE_EQ(p.fx, 2759.48 + k);
    EXPECT_DOUBLE_EQ(p.fy, 2764.16 + k);
    EXPECT_DOUBLE_EQ(p.cx, 1520.69);
    EXPECT_DOUBLE_EQ(p.cy, 1006.81);
    EXPECT_EQ(p.width, 3072);
    EXPECT_EQ(p.height, 2048);
    EXPECT_DOUBLE_EQ(sequence.frames[k].timestamp, k);
    EXPECT_EQ(fs::path(sequence.frames[k].image_path),
              fixture.dir / "images" / fixture.image_name(k));
  }
  expect_pose_near(relative_pose(sequence, 0, 1), fixture.chain.Rr, fixture.chain.tr, 1e-12);
  expect_pose_near(relative_pose(sequence, 0, 2), fixture.chain.Rr * fixture.chain.Rr,
                   fixture.chain.Rr * fixture.chain.tr + fixture.chain.tr, 1e-12);
  const std::vector<PairWithGt> pairs = make_pairs(sequence, 1);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_DOUBLE_EQ(pairs[1].camera0.pinhole.fx, 2760.48);
  EXPECT_DOUBLE_EQ(pairs[1].camera1.pinhole.fx, 2761.48);
  Sequence via_dispatch;
  ASSERT_TRUE(read_sequence("strecha", fixture.dir.string(), &via_dispatch, &error)) << error;
  EXPECT_EQ(via_dispatch.size(), 3);
  EXPECT_FALSE(read_sequence("eth3d", fixture.dir.string(), &via_dispatch, &error));
  EXPECT_TRUE(contains(error, "unknown data set format 'eth3d'"));
}

// One image's camera, found from the image's path (hybrid_vo_render_pan's default).
TEST(Strecha, ReadsOneCameraFoundBesideItsImage) {
  TempDir dir;
  StrechaFixture fixture(dir.path() / "fountain-P3");
  fixture.write();
  const std::string image = (fixture.dir / "images" / fixture.image_name(1)).string();
  const std::string found = strecha_camera_of_image(image);
  EXPECT_EQ(fs::path(found), fs::path(fixture.camera_path(1)).lexically_normal());
  Frame frame;
  std::string error;
  ASSERT_TRUE(read_strecha_camera(found, &frame, &error)) << error;
  EXPECT_DOUBLE_EQ(frame.camera.pinhole.fx, 2760.48);
  EXPECT_EQ(frame.camera.pinhole.width, 3072);
  EXPECT_LT((frame.R_wc - fixture.chain.R_wc[1]).norm(), 1e-12);
  EXPECT_LT((frame.c_w - fixture.chain.c_w[1]).norm(), 1e-12);
  // Without the layout: FILE.camera beside the image, or nothing.
  write_file(dir.path() / "loose.jpg", "");
  EXPECT_EQ(strecha_camera_of_image((dir.path() / "loose.jpg").string()), "");
  write_file(dir.path() / "loose.jpg.camera", join_lines(fixture.cameras[0]));
  EXPECT_EQ(fs::path(strecha_camera_of_image((dir.path() / "loose.jpg").string())),
            dir.path() / "loose.jpg.camera");
  EXPECT_FALSE(read_strecha_camera((dir.path() / "none.camera").string(), &frame, &error));
  EXPECT_TRUE(contains(error, "none.camera"));
  write_file(dir.path() / "short.camera", "1 2 3\n");
  EXPECT_FALSE(read_strecha_camera((dir.path() / "short.camera").string(), &frame, &error));
  EXPECT_TRUE(contains(error, "expected 26 numbers"));
}

TEST(Strecha, ReportsMissingFilesAndMalformedLines) {
  TempDir dir;
  StrechaFixture* f = nullptr;
  const std::vector<BrokenCase> cases = {
      {"25 numbers", [&] { f->cameras[1][8] = "3072"; },
       [&] { return f->camera_path(1) + ":9:"; }, "expected 26 numbers"},
      {"27 numbers", [&] { f->cameras[2][3] = "0 0 0 0"; },
       [&] { return f->camera_path(2) + ":9:"; }, "expected 26 numbers"},
      {"NaN in R", [&] { f->cameras[0][5] = "0 nan 0"; },
       [&] { return f->camera_path(0) + ":6:"; }, "'nan' is not a finite number"},
      {"word in C", [&] { f->cameras[2][7] = "1 2 three"; },
       [&] { return f->camera_path(2) + ":8:"; }, "'three' is not a finite number"},
      {"distortion", [&] { f->cameras[1][3] = "0.1 0 0"; },
       [&] { return f->camera_path(1) + ":4:"; }, "distortion"},
      {"R not a rotation", [&] { f->cameras[0][4] = "1 1 0"; },
       [&] { return f->camera_path(0) + ":5:"; }, "not a rotation"},
      {"K with skew", [&] { f->cameras[0][0] = "2759.48 5 1520.69"; },
       [&] { return f->camera_path(0) + ":1:"; }, "skew"},
      {"K bottom row", [&] { f->cameras[0][2] = "0 0 2"; },
       [&] { return f->camera_path(0) + ":1:"; }, "K(2,2) = 1"},
      {"fractional width", [&] { f->cameras[1][8] = "3072.5 2048"; },
       [&] { return f->camera_path(1) + ":9:"; }, "positive integers"},
      {"missing image", [&] { f->cameras.push_back(f->cameras[0]); },
       [&] { return (f->dir / "images" / "0003.jpg").string(); }, "no such image"},
  };
  for (const BrokenCase& c : cases) {
    SCOPED_TRACE(c.what);
    fs::remove_all(dir.path() / "case");
    StrechaFixture fixture(dir.path() / "case");
    f = &fixture;
    c.damage();
    fixture.write();
    if (fixture.cameras.size() > 3)
      write_file(fixture.camera_path(3), join_lines(fixture.cameras[3]));
    Sequence sequence;
    std::string error;
    EXPECT_FALSE(read_strecha(fixture.dir.string(), &sequence, &error));
    EXPECT_TRUE(contains(error, c.expected_location()));
    EXPECT_TRUE(contains(error, c.expected_message));
  }

  Sequence sequence;
  std::string error;
  fs::create_directories(dir.path() / "empty" / "images");
  EXPECT_FALSE(read_strecha((dir.path() / "empty").string(), &sequence, &error));
  EXPECT_TRUE(contains(error, "gt_dense_cameras"));
  EXPECT_TRUE(contains(error, "no such directory"));
}

// ------------------------------------------------------------------------------------------------
// SuperGlue pairs with ground truth

// One line in SuperGlue's layout: name0 name1 rot0 rot1 K0(9) K1(9) T_0to1(16), all row-major.
std::string superglue_line(const std::string& name0, const std::string& name1, int rot0, int rot1,
                           const Eigen::Matrix3d& K0, const Eigen::Matrix3d& K1,
                           const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  std::string line = name0 + " " + name1 + " " + std::to_string(rot0) + " " + std::to_string(rot1);
  for (const Eigen::Matrix3d* K : {&K0, &K1})
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) line += " " + numbers({(*K)(r, c)});
  for (int r = 0; r < 3; ++r) line += " " + numbers({R(r, 0), R(r, 1), R(r, 2), t(r)});
  return line + " 0. 0. 0. 1.";
}

struct SuperGlueFixture {
  fs::path dir;
  PoseChain chain{2};
  Eigen::Matrix3d K0, K1;
  std::vector<std::string> lines;

  explicit SuperGlueFixture(const fs::path& dir_) : dir(dir_) {
    K0 << 1163.45, 0, 653.626, 0, 1164.79, 481.6, 0, 0, 1;
    K1 << 1161.75, 0, 658.042, 0, 1159.11, 486.467, 0, 0, 1;
    lines = {"# pairs with ground truth",
             superglue_line("scene0/a.jpg", "scene0/b.jpg", 0, 0, K0, K1, chain.Rr, chain.tr),
             "",
             superglue_line("scene1/c.jpg", "scene1/d.jpg", 1, 3, K1, K0,
                            chain.Rr.transpose(), -chain.Rr.transpose() * chain.tr)};
  }
  std::string pairs_path() const { return (dir / "pairs_with_gt.txt").string(); }
  void write() const {
    write_file(pairs_path(), join_lines(lines));
    for (const char* name : {"scene0/a.jpg", "scene0/b.jpg", "scene1/c.jpg", "scene1/d.jpg"})
      write_file(dir / "images" / name, "");
  }
};

TEST(SuperGlue, ReadsPairsWithGroundTruth) {
  TempDir dir;
  SuperGlueFixture fixture(dir.path());
  fixture.write();
  std::vector<PairWithGt> pairs;
  std::string error;
  ASSERT_TRUE(read_superglue(fixture.pairs_path(), (dir.path() / "images").string(), &pairs,
                             &error))
      << error;
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(fs::path(pairs[0].image_path0), dir.path() / "images" / "scene0" / "a.jpg");
  EXPECT_EQ(fs::path(pairs[1].image_path1), dir.path() / "images" / "scene1" / "d.jpg");
  EXPECT_DOUBLE_EQ(pairs[0].camera0.pinhole.fx, 1163.45);
  EXPECT_DOUBLE_EQ(pairs[0].camera0.pinhole.cy, 481.6);
  EXPECT_DOUBLE_EQ(pairs[0].camera1.pinhole.fy, 1159.11);
  EXPECT_DOUBLE_EQ(pairs[0].camera1.pinhole.cx, 658.042);
  EXPECT_EQ(pairs[0].camera0.pinhole.width, 0);  // unknown
  EXPECT_EQ(pairs[1].rotation0, 1);
  EXPECT_EQ(pairs[1].rotation1, 3);
  EXPECT_EQ(pairs[0].index0, -1);
  expect_pose_near(pairs[0].pose, fixture.chain.Rr, fixture.chain.tr, 1e-12);
  expect_pose_near(pairs[1].pose, fixture.chain.Rr.transpose(),
                   -fixture.chain.Rr.transpose() * fixture.chain.tr, 1e-12);

  // Without an image folder the names are kept and not checked.
  ASSERT_TRUE(read_superglue(fixture.pairs_path(), "", &pairs, &error)) << error;
  EXPECT_EQ(pairs[1].image_path0, "scene1/c.jpg");
}

// The published files round R to 5 digits: still accepted, and made an exact rotation.
TEST(SuperGlue, AcceptsRotationsRoundedToFiveDigits) {
  TempDir dir;
  const std::string line =
      "s_frame-000100.jpg s_frame-000400.jpg 0 0 1000.5     0.     640.25    0.    1001.25   "
      "480.75     0.       0.       1.    1000.5     0.     640.25    0.    1001.25   480.75     "
      "0.       0.       1.     0.86603 -0.5      0.       0.25    0.5      0.86603  0.      "
      "-0.125   0.       0.       1.       1.5      0.       0.       0.       1.";
  write_file(dir.path() / "pairs.txt", line + "\n");
  std::vector<PairWithGt> pairs;
  std::string error;
  ASSERT_TRUE(read_superglue((dir.path() / "pairs.txt").string(), "", &pairs, &error)) << error;
  ASSERT_EQ(pairs.size(), 1u);
  const Eigen::Matrix3d R = rotation_about(Eigen::Vector3d::UnitZ(), M_PI / 6);
  EXPECT_LT((pairs[0].pose.R - R).norm(), 1e-5);
  EXPECT_LT((pairs[0].pose.R.transpose() * pairs[0].pose.R - Eigen::Matrix3d::Identity()).norm(),
            1e-14);
  EXPECT_LT((pairs[0].pose.t - Eigen::Vector3d(0.25, -0.125, 1.5)).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(pairs[0].camera0.pinhole.fy, 1001.25);
}

TEST(SuperGlue, ReportsMissingFilesAndMalformedLines) {
  TempDir dir;
  SuperGlueFixture* f = nullptr;
  auto replace_field = [&](int line, int field, const std::string& value) {
    std::vector<std::string> fields = split_fields(f->lines[line]);
    fields[field] = value;
    std::string text;
    for (const std::string& s : fields) text += (text.empty() ? "" : " ") + s;
    f->lines[line] = text;
  };
  const std::vector<BrokenCase> cases = {
      {"37 fields", [&] { f->lines[1] = f->lines[1].substr(0, f->lines[1].rfind(' ')); },
       [&] { return f->pairs_path() + ":2:"; }, "expected 38 fields"},
      {"no ground truth", [&] { f->lines[3] = "scene1/c.jpg scene1/d.jpg"; },
       [&] { return f->pairs_path() + ":4:"; }, "found 2"},
      {"rotation 4", [&] { replace_field(1, 3, "4"); },
       [&] { return f->pairs_path() + ":2:"; }, "field 4 '4' is not a rotation count"},
      {"NaN in K1", [&] { replace_field(3, 14, "nan"); },
       [&] { return f->pairs_path() + ":4:"; }, "field 15 'nan' is not a finite number"},
      {"word in T", [&] { replace_field(1, 25, "x"); },
       [&] { return f->pairs_path() + ":2:"; }, "field 26 'x' is not a finite number"},
      {"T's last row", [&] { replace_field(1, 37, "2."); },
       [&] { return f->pairs_path() + ":2:"; }, "last row"},
      {"R not a rotation", [&] { replace_field(1, 22, "3"); },
       [&] { return f->pairs_path() + ":2:"; }, "not a rotation"},
      {"K with skew", [&] { replace_field(1, 5, "2"); },
       [&] { return f->pairs_path() + ":2:"; }, "skew"},
      {"missing image", [&] { replace_field(3, 1, "scene1/gone.jpg"); },
       [&] { return f->pairs_path() + ":4:"; }, "no such image"},
      {"only comments", [&] { f->lines = {"# nothing"}; },
       [&] { return f->pairs_path() + ":"; }, "no pairs"},
  };
  for (const BrokenCase& c : cases) {
    SCOPED_TRACE(c.what);
    fs::remove_all(dir.path() / "case");
    SuperGlueFixture fixture(dir.path() / "case");
    f = &fixture;
    c.damage();
    fixture.write();
    std::vector<PairWithGt> pairs;
    std::string error;
    EXPECT_FALSE(read_superglue(fixture.pairs_path(), (fixture.dir / "images").string(), &pairs,
                                &error));
    EXPECT_TRUE(contains(error, c.expected_location()));
    EXPECT_TRUE(contains(error, c.expected_message));
  }
  std::vector<PairWithGt> pairs;
  std::string error;
  const std::string missing = (dir.path() / "missing.txt").string();
  EXPECT_FALSE(read_superglue(missing, "", &pairs, &error));
  EXPECT_TRUE(contains(error, missing + ": no such file"));
}

// ------------------------------------------------------------------------------------------------
// The few-points regime of the pair evaluation (hybrid_vo_eval_pairs --max-points)

std::vector<PointMatch> grid_matches(int n) {
  std::vector<PointMatch> points(n);
  for (int i = 0; i < n; ++i) {
    points[i].x1 = Eigen::Vector2d(37.0 * (i % 17), 23.0 * (i / 17));
    points[i].x2 = points[i].x1 + Eigen::Vector2d(1.0, 0.5);
  }
  return points;
}

TEST(PointSubset, KeepsExactlyNDistinctMatches) {
  const std::vector<PointMatch> points = grid_matches(300);
  for (const PointSelection selection : {PointSelection::kRandom, PointSelection::kClustered}) {
    for (const int n : {1, 20, 40, 80, 299}) {
      for (uint64_t seed = 0; seed < 5; ++seed) {
        const std::vector<int> kept = select_point_matches(points, n, selection, seed);
        ASSERT_EQ(static_cast<int>(kept.size()), n) << to_string(selection);
        EXPECT_TRUE(std::is_sorted(kept.begin(), kept.end()));
        EXPECT_EQ(std::adjacent_find(kept.begin(), kept.end()), kept.end()) << "duplicates";
        EXPECT_GE(kept.front(), 0);
        EXPECT_LT(kept.back(), 300);
      }
    }
    // Asking for more than there are, or for all, keeps everything.
    EXPECT_EQ(select_point_matches(points, 300, selection, 1).size(), 300u);
    EXPECT_EQ(select_point_matches(points, 5000, selection, 1).size(), 300u);
    EXPECT_EQ(select_point_matches(points, -1, selection, 1).size(), 300u);
    EXPECT_TRUE(select_point_matches({}, 40, selection, 1).empty());
  }
}

TEST(PointSubset, SeededNestedAndDifferentPerSeed) {
  const std::vector<PointMatch> points = grid_matches(300);
  for (const PointSelection selection : {PointSelection::kRandom, PointSelection::kClustered}) {
    const std::vector<int> a = select_point_matches(points, 40, selection, 7);
    EXPECT_EQ(a, select_point_matches(points, 40, selection, 7));
    EXPECT_NE(a, select_point_matches(points, 40, selection, 8));
    // A smaller N keeps a subset of a larger N's matches (same seed).
    const std::vector<int> small = select_point_matches(points, 20, selection, 7);
    EXPECT_TRUE(std::includes(a.begin(), a.end(), small.begin(), small.end()));
  }
}

TEST(PointSubset, ClusteredKeepsOnePatchRandomSpreadsOut) {
  const std::vector<PointMatch> points = grid_matches(289);  // 17 x 17, 37 x 23 px cells
  auto spread = [&](const std::vector<int>& kept) {
    Eigen::Vector2d lo = points[kept[0]].x1, hi = lo;
    for (int i : kept) {
      lo = lo.cwiseMin(points[i].x1);
      hi = hi.cwiseMax(points[i].x1);
    }
    return (hi - lo).norm();
  };
  double clustered = 0.0, random = 0.0;
  for (uint64_t seed = 0; seed < 20; ++seed) {
    clustered += spread(select_point_matches(points, 20, PointSelection::kClustered, seed));
    random += spread(select_point_matches(points, 20, PointSelection::kRandom, seed));
  }
  // 20 nearest neighbours of a grid point lie within about 2.5 cells of it.
  EXPECT_LT(clustered / 20, 250.0);
  EXPECT_GT(random / 20, 2.0 * clustered / 20);
}

TEST(PointSubset, ParsesSelectionNames) {
  PointSelection s = PointSelection::kRandom;
  EXPECT_TRUE(parse_point_selection("clustered", &s));
  EXPECT_EQ(s, PointSelection::kClustered);
  EXPECT_TRUE(parse_point_selection("random", &s));
  EXPECT_EQ(s, PointSelection::kRandom);
  EXPECT_FALSE(parse_point_selection("uniform", &s));
  EXPECT_STREQ(to_string(PointSelection::kClustered), "clustered");
}

// ------------------------------------------------------------------------------------------------
// The real data sets, when present

double rotation_angle_deg(const Eigen::Matrix3d& R) {
  return std::acos(std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / M_PI;
}

TEST(RealData, Kitti) {
  const fs::path path = shared_data_dir() / "kitti_seq0x_51";
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_kitti(path.string(), &sequence, &error)) << error;
  ASSERT_EQ(sequence.size(), 51);
  EXPECT_EQ(sequence.frames[0].camera.pinhole.width, 1241);
  EXPECT_EQ(sequence.frames[0].camera.pinhole.height, 376);
  EXPECT_DOUBLE_EQ(sequence.frames[0].camera.pinhole.fx, 718.856);
  for (int i = 0; i + 1 < sequence.size(); ++i) {
    // About a metre per frame, driving forward (+z of camera i), turning gently.
    const RelativePose pose = relative_pose(sequence, i, i + 1);
    const Eigen::Vector3d centre = pose.centre2();
    EXPECT_GT(centre.norm(), 0.8) << i;
    EXPECT_LT(centre.norm(), 1.4) << i;
    EXPECT_GT(centre.z() / centre.norm(), 0.99) << i;
    EXPECT_LT(rotation_angle_deg(pose.R), 5.0) << i;
  }
}

TEST(RealData, Tum) {
  const fs::path path = shared_data_dir() / "tum_fr1_plant_19";
  if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
  Sequence sequence;
  std::string error;
  ASSERT_TRUE(read_tum(path.string(), &sequence, &error)) << error;
  EXPECT_EQ(sequence.size(), 19);  // every image within 20 ms of a sample
  EXPECT_EQ(sequence.skipped_frames, 0);
  EXPECT_DOUBLE_EQ(sequence.frames[0].camera.distortion[0], 0.262383);
  for (int i = 0; i + 1 < sequence.size(); ++i) {
    // Every third frame of a 30 Hz stream, so 67-133 ms apart.
    const double dt = sequence.frames[i + 1].timestamp - sequence.frames[i].timestamp;
    EXPECT_GT(dt, 0.05) << i;
    EXPECT_LT(dt, 0.15) << i;
    const RelativePose pose = relative_pose(sequence, i, i + 1);
    EXPECT_LT(pose.t.norm(), 0.1) << i;  // a few centimetres per 0.1 s
    EXPECT_LT(rotation_angle_deg(pose.R), 10.0) << i;
  }
}

TEST(RealData, Strecha) {
  for (const char* scene : {"fountain-P11", "Herz-Jesus-P8"}) {
    const fs::path path = shared_data_dir() / "strecha_fountain_herzjesu" / scene;
    if (!fs::exists(path)) GTEST_SKIP() << path << " not present";
    Sequence sequence;
    std::string error;
    ASSERT_TRUE(read_strecha(path.string(), &sequence, &error)) << error;
    EXPECT_EQ(sequence.size(), std::string(scene) == "fountain-P11" ? 11 : 8);
    for (int i = 0; i + 1 < sequence.size(); ++i) {
      const Frame& a = sequence.frames[i];
      const Frame& b = sequence.frames[i + 1];
      const RelativePose pose = relative_pose(sequence, i, i + 1);
      EXPECT_GT(pose.t.norm(), 1.0) << scene << " " << i;
      EXPECT_LT(pose.t.norm(), 4.0) << scene << " " << i;
      EXPECT_LT(rotation_angle_deg(pose.R), 20.0) << scene << " " << i;
      // Camera-to-world R: the optical axes (third columns) of neighbours converge on the facade
      // in front of both cameras, 5-40 m away.
      const Eigen::Vector3d da = a.R_wc.col(2), db = b.R_wc.col(2), w = a.c_w - b.c_w;
      const double B = da.dot(db), D = da.dot(w), E = db.dot(w), den = 1.0 - B * B;
      const double sa = (B * E - D) / den, sb = (E - B * D) / den;
      EXPECT_GT(sa, 5.0) << scene << " " << i;
      EXPECT_LT(sa, 40.0) << scene << " " << i;
      EXPECT_GT(sb, 5.0) << scene << " " << i;
    }
  }
}

}  // namespace
}  // namespace datasets
}  // namespace hybrid_vo
