// The LaMAR Capture session reader (hybrid_vo/datasets/lamar.h) on sessions written here as text:
// pose directions and composition checked against hand-computed points, quaternion order, the
// COLMAP principal point, camera models, phone streams, and every error with its file and line;
// and on the real phone query frame of ../shared/data/lamar_phone_query_1 when it is present.
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "file_test_utils.h"
#include "hybrid_vo/datasets/lamar.h"

namespace hybrid_vo {
namespace datasets {
namespace {

namespace fs = std::filesystem;
using testing::contains;
using testing::shared_data_dir;
using testing::TempDir;
using testing::write_file;

const double kS = std::sqrt(0.5);

// A session folder; edit the lines, then write().
struct SessionText {
  fs::path dir;
  std::vector<std::string> sensors = {
      "# sensor_id, name, sensor_type, [sensor_params]+",
      "cam0, left camera, camera, PINHOLE, 640, 480, 500, 510, 320.5, 240.5",
      "cam1, , camera, OPENCV, 640, 480, 400, 401, 300.5, 200.5, 0.1, -0.02, 0.001, -0.002",
      "wifi0, phone wifi, wifi",
  };
  // cam0 is the rig frame; cam1 is turned 90 deg about y and 0.1 m along x.
  std::vector<std::string> rigs = {
      "# rig_id, sensor_id, qw, qx, qy, qz, tx, ty, tz",
      "rig, cam0, 1, 0, 0, 0, 0, 0, 0",
      "rig, cam1, " + std::to_string(kS) + ", 0, " + std::to_string(kS) + ", 0, 0.1, 0, 0",
  };
  // At 1000 us the rig is turned 90 deg about z and at (1, 2, 3).
  std::vector<std::string> trajectories = {
      "# timestamp, device_id, qw, qx, qy, qz, tx, ty, tz, *covar",
      "1000, rig, " + std::to_string(kS) + ", 0, 0, " + std::to_string(kS) + ", 1, 2, 3",
      "2000, rig, 1, 0, 0, 0, 0, 0, 0",
  };
  std::vector<std::string> images = {
      "# timestamp, sensor_id, image_path",
      "2000, cam0, images/cam0/2000.png",
      "1000, cam0, images/cam0/1000.png",
      "1000, cam1, images/cam1/1000.png",
  };
  std::vector<std::string> alignment;  // proc/alignment_trajectories.txt when not empty

  explicit SessionText(const fs::path& d) : dir(d) {}

  std::string path(const std::string& name) const { return (dir / name).string(); }
  void write() const {
    auto lines = [](const std::vector<std::string>& v) {
      std::string text;
      for (const std::string& line : v) text += line + "\n";
      return text;
    };
    if (!sensors.empty()) write_file(dir / "sensors.txt", lines(sensors));
    if (!rigs.empty()) write_file(dir / "rigs.txt", lines(rigs));
    if (!trajectories.empty()) write_file(dir / "trajectories.txt", lines(trajectories));
    if (!images.empty()) write_file(dir / "images.txt", lines(images));
    if (!alignment.empty())
      write_file(dir / "proc" / "alignment_trajectories.txt", lines(alignment));
    for (const char* image :
         {"images/cam0/1000.png", "images/cam0/2000.png", "images/cam1/1000.png"})
      write_file(dir / "raw_data" / image, "not decoded by the reader");
  }
};

TEST(Lamar, ReadsARigSessionInItsConventions) {
  TempDir dir("test_lamar");
  SessionText text(dir.path());
  text.write();
  LamarSession session;
  std::string error;
  ASSERT_TRUE(read_lamar_session(dir.path().string(), &session, &error)) << error;
  ASSERT_EQ(session.sensors.size(), 3u);
  EXPECT_EQ(session.sensors[0].name, "left camera");
  EXPECT_EQ(session.sensors[1].name, "");
  EXPECT_FALSE(session.sensors[2].is_camera());
  EXPECT_EQ(session.poses_path, text.path("trajectories.txt"));

  // Images by time, paths under raw_data/.
  ASSERT_EQ(session.images.size(), 3u);
  EXPECT_EQ(session.images[0].timestamp_us, 1000);
  EXPECT_EQ(session.images[0].sensor_id, "cam0");
  EXPECT_EQ(session.images[1].sensor_id, "cam1");
  EXPECT_EQ(session.images[2].timestamp_us, 2000);
  EXPECT_EQ(fs::path(session.images[1].path), dir.path() / "raw_data/images/cam1/1000.png");
  EXPECT_EQ(session.images[2].line, 2);

  // Principal points move from COLMAP's pixel corners to ROS's pixel centres.
  const CameraIntrinsics& c0 = session.sensors[0].intrinsics;
  EXPECT_EQ(c0.width, 640);
  EXPECT_EQ(c0.height, 480);
  EXPECT_DOUBLE_EQ(c0.fx, 500);
  EXPECT_DOUBLE_EQ(c0.fy, 510);
  EXPECT_DOUBLE_EQ(c0.cx, 320);
  EXPECT_DOUBLE_EQ(c0.cy, 240);
  EXPECT_EQ(c0.distortion_model, "plumb_bob");
  EXPECT_EQ(c0.D, std::vector<double>(5, 0.0));
  const CameraIntrinsics& c1 = session.sensors[1].intrinsics;
  EXPECT_DOUBLE_EQ(c1.cx, 300);
  EXPECT_EQ(c1.D, (std::vector<double>{0.1, -0.02, 0.001, -0.002, 0.0}));

  // cam1's optical axis point (0, 0, 1): in the rig (1.1, 0, 0), in the world (1, 3.1, 3).
  Eigen::Isometry3d T;
  ASSERT_TRUE(session.camera_pose(1000, "cam1", &T));
  EXPECT_LT((T * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(1, 3.1, 3)).norm(), 1e-5);
  ASSERT_TRUE(session.camera_pose(1000, "cam0", &T));
  EXPECT_LT((T * Eigen::Vector3d(0, 0, 1) - Eigen::Vector3d(1, 2, 4)).norm(), 1e-5);
  EXPECT_LT((T * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(1, 3, 3)).norm(), 1e-5);
  EXPECT_FALSE(session.camera_pose(1500, "cam0", &T));
  std::string rig;
  EXPECT_TRUE(session.rig_of("cam1", &rig, &T));
  EXPECT_EQ(rig, "rig");
  EXPECT_FALSE(session.rig_of("wifi0", &rig, &T));

  const std::vector<LamarStream> streams = lamar_camera_streams(session);
  ASSERT_EQ(streams.size(), 2u);
  EXPECT_EQ(streams[0].id, "cam0");
  EXPECT_EQ(streams[0].images, (std::vector<size_t>{0, 2}));
  EXPECT_EQ(streams[1].id, "cam1");
}

TEST(Lamar, SensorPosesCovariancesAndTheAlignmentTrajectories) {
  TempDir dir("test_lamar");
  SessionText text(dir.path());
  text.rigs.clear();
  // A sensor posed by itself, with a covariance; the alignment file wins over trajectories.txt.
  std::string covariance;
  for (int k = 0; k < 36; ++k) covariance += ", 0";
  text.trajectories = {"1000, cam0, 1, 0, 0, 0, 5, 5, 5" + covariance};
  text.alignment = {"# timestamp, device_id, qw, qx, qy, qz, tx, ty, tz, *covar", "",
                    "1000, cam0, 0, 1, 0, 0, 1, 2, 3"};
  text.images.pop_back();
  text.write();
  LamarSession session;
  std::string error;
  ASSERT_TRUE(read_lamar_session(dir.path().string(), &session, &error)) << error;
  EXPECT_EQ(session.poses_path, text.path("proc/alignment_trajectories.txt"));
  Eigen::Isometry3d T;
  ASSERT_TRUE(session.camera_pose(1000, "cam0", &T));
  // qw = 0, qx = 1: 180 deg about x.
  EXPECT_LT((T * Eigen::Vector3d(0, 1, 1) - Eigen::Vector3d(1, 1, 2)).norm(), 1e-12);

  fs::remove(dir.path() / "proc" / "alignment_trajectories.txt");
  ASSERT_TRUE(read_lamar_session(dir.path().string(), &session, &error)) << error;
  ASSERT_TRUE(session.camera_pose(1000, "cam0", &T));
  EXPECT_LT((T.translation() - Eigen::Vector3d(5, 5, 5)).norm(), 1e-12);

  fs::remove(dir.path() / "trajectories.txt");  // a query session: images without poses
  ASSERT_TRUE(read_lamar_session(dir.path().string(), &session, &error)) << error;
  EXPECT_TRUE(session.poses.empty());
  EXPECT_EQ(session.poses_path, "");
}

TEST(Lamar, CameraModels) {
  TempDir dir("test_lamar");
  SessionText text(dir.path());
  text.rigs.clear();
  text.trajectories.clear();
  text.images = {"1000, cam0, images/cam0/1000.png"};
  text.sensors = {
      "cam0, , camera, SIMPLE_PINHOLE, 100, 50, 80, 50.5, 25.5",
      "a, , camera, SIMPLE_RADIAL, 100, 50, 80, 50.5, 25.5, 0.1",
      "b, , camera, RADIAL, 100, 50, 80, 50.5, 25.5, 0.1, 0.2",
      "c, , camera, FULL_OPENCV, 100, 50, 80, 81, 50.5, 25.5, 1, 2, 3, 4, 5, 6, 7, 8",
      "d, , camera, OPENCV_FISHEYE, 100, 50, 80, 81, 50.5, 25.5, 1, 2, 3, 4",
      "e, , camera, FOV, 100, 50, 80, 81, 50.5, 25.5, 0.9",
      "f, , camera, NEW_MODEL, 100, 50, 1, 2, 3",
      "g, , depth, PINHOLE, 100, 50, 80, 81, 50.5, 25.5",
  };
  text.write();
  LamarSession session;
  std::string error;
  ASSERT_TRUE(read_lamar_session(dir.path().string(), &session, &error)) << error;
  auto intrinsics = [&](const std::string& id) { return session.sensor(id)->intrinsics; };
  EXPECT_DOUBLE_EQ(intrinsics("cam0").fy, 80);
  EXPECT_DOUBLE_EQ(intrinsics("cam0").cx, 50);
  EXPECT_DOUBLE_EQ(intrinsics("cam0").cy, 25);
  EXPECT_EQ(intrinsics("a").D, (std::vector<double>{0.1, 0, 0, 0, 0}));
  EXPECT_EQ(intrinsics("b").D, (std::vector<double>{0.1, 0.2, 0, 0, 0}));
  EXPECT_EQ(intrinsics("c").distortion_model, "rational_polynomial");
  EXPECT_EQ(intrinsics("c").D, (std::vector<double>{1, 2, 3, 4, 5, 6, 7, 8}));
  EXPECT_EQ(intrinsics("d").distortion_model, "equidistant");
  EXPECT_EQ(intrinsics("d").D, (std::vector<double>{1, 2, 3, 4}));
  EXPECT_DOUBLE_EQ(intrinsics("d").fy, 81);
  EXPECT_TRUE(contains(session.sensor("e")->unsupported, "FOV"));
  EXPECT_TRUE(contains(session.sensor("f")->unsupported, "unknown camera model 'NEW_MODEL'"));
  EXPECT_TRUE(session.sensor("cam0")->unsupported.empty());
  EXPECT_FALSE(session.sensor("g")->is_camera());
}

TEST(Lamar, PhoneCamerasPerFrameFormOneStream) {
  TempDir dir("test_lamar");
  SessionText text(dir.path());
  text.rigs.clear();
  text.sensors = {
      "cam_phone_1000, phone camera for timestamp 1000, camera, PINHOLE, 40, 30, "
      "50, 50, 20, 15",
      "cam_phone_2000, phone camera for timestamp 2000, camera, PINHOLE, 30, 40, "
      "51, 51, 15, 20",
      "cam0, , camera, PINHOLE, 40, 30, 50, 50, 20, 15"};
  text.trajectories = {"1000, cam_phone_1000, 1, 0, 0, 0, 0, 0, 0",
                       "2000, cam_phone_2000, 1, 0, 0, 0, 1, 0, 0"};
  text.images = {"2000, cam_phone_2000, images/cam0/2000.png",
                 "1000, cam_phone_1000, images/cam0/1000.png", "1000, cam0, images/cam1/1000.png"};
  text.write();
  LamarSession session;
  std::string error;
  ASSERT_TRUE(read_lamar_session(dir.path().string(), &session, &error)) << error;
  const std::vector<LamarStream> streams = lamar_camera_streams(session);
  ASSERT_EQ(streams.size(), 2u);
  EXPECT_EQ(streams[0].id, "cam_phone");
  ASSERT_EQ(streams[0].images.size(), 2u);
  EXPECT_EQ(session.images[streams[0].images[0]].sensor_id, "cam_phone_1000");
  EXPECT_EQ(session.images[streams[0].images[1]].sensor_id, "cam_phone_2000");
  EXPECT_EQ(streams[1].id, "cam0");
  Eigen::Isometry3d T;
  EXPECT_TRUE(session.camera_pose(2000, "cam_phone_2000", &T));
  EXPECT_DOUBLE_EQ(T.translation().x(), 1.0);
}

struct BrokenCase {
  std::string what;
  std::function<void(SessionText*)> damage;
  std::string file;  // relative to the session
  int line;          // 0: no line
  std::string message;
};

TEST(Lamar, ReportsMissingFilesAndMalformedLines) {
  const std::vector<BrokenCase> cases = {
      {"no sensors.txt", [](SessionText* t) { t->sensors.clear(); }, "sensors.txt", 0,
       "no such file"},
      {"no images.txt", [](SessionText* t) { t->images.clear(); }, "images.txt", 0, "no such file"},
      {"only comments in images.txt", [](SessionText* t) { t->images = {"# nothing"}; },
       "images.txt", 0, "no images"},
      {"PINHOLE with 3 parameters",
       [](SessionText* t) { t->sensors[1] = "cam0, , camera, PINHOLE, 640, 480, 500, 510, 320"; },
       "sensors.txt", 2, "takes 4 parameters, found 3"},
      {"NaN focal length",
       [](SessionText* t) {
         t->sensors[1] = "cam0, , camera, PINHOLE, 640, 480, nan, 510, 320, 240";
       },
       "sensors.txt", 2, "'nan' is not a finite number"},
      {"image size not a number",
       [](SessionText* t) { t->sensors[1] = "cam0, , camera, PINHOLE, 640.5, 480, 1, 1, 1, 1"; },
       "sensors.txt", 2, "not two positive integers"},
      {"duplicate sensor", [](SessionText* t) { t->sensors[2] = t->sensors[1]; }, "sensors.txt", 3,
       "duplicate sensor 'cam0'"},
      {"sensor line too short", [](SessionText* t) { t->sensors.push_back("x, y"); }, "sensors.txt",
       5, "found 2 fields"},
      {"rig of an unknown sensor",
       [](SessionText* t) { t->rigs.push_back("rig, cam9, 1, 0, 0, 0, 0, 0, 0"); }, "rigs.txt", 4,
       "unknown sensor 'cam9'"},
      {"rig line with 8 fields", [](SessionText* t) { t->rigs[1] = "rig, cam0, 1, 0, 0, 0, 0, 0"; },
       "rigs.txt", 2, "expected 9 fields"},
      {"trajectory with NaN",
       [](SessionText* t) { t->trajectories[2] = "2000, rig, 1, 0, 0, 0, 0, nan, 0"; },
       "trajectories.txt", 3, "'nan' is not a finite number"},
      {"trajectory with 8 fields",
       [](SessionText* t) { t->trajectories[2] = "2000, rig, 1, 0, 0, 0, 0, 0"; },
       "trajectories.txt", 3, "expected 9 fields"},
      {"quaternion of norm 2",
       [](SessionText* t) { t->trajectories[2] = "2000, rig, 2, 0, 0, 0, 0, 0, 0"; },
       "trajectories.txt", 3, "norm 2"},
      {"timestamp with a fraction",
       [](SessionText* t) { t->trajectories[2] = "2000.5, rig, 1, 0, 0, 0, 0, 0, 0"; },
       "trajectories.txt", 3, "timestamp '2000.5' is not a non-negative integer"},
      {"unknown device",
       [](SessionText* t) { t->trajectories[2] = "2000, headset, 1, 0, 0, 0, 0, 0, 0"; },
       "trajectories.txt", 3, "unknown device 'headset'"},
      {"second pose at a time",
       [](SessionText* t) { t->trajectories.push_back(t->trajectories[1]); }, "trajectories.txt", 4,
       "second pose of 'rig' at 1000"},
      {"bad alignment file", [](SessionText* t) { t->alignment = {"1000, rig, 1, 0, 0, 0, 0, 0"}; },
       "proc/alignment_trajectories.txt", 1, "expected 9 fields"},
      {"image of an unknown sensor",
       [](SessionText* t) { t->images.push_back("3000, cam7, images/cam0/1000.png"); },
       "images.txt", 5, "unknown sensor 'cam7'"},
      {"image of a wifi sensor",
       [](SessionText* t) { t->images.push_back("3000, wifi0, images/cam0/1000.png"); },
       "images.txt", 5, "is a wifi, not a camera"},
      {"missing image file",
       [](SessionText* t) { t->images.push_back("3000, cam0, images/cam0/3000.png"); },
       "images.txt", 5, "no such image"},
      {"image line with 2 fields", [](SessionText* t) { t->images[1] = "2000, cam0"; },
       "images.txt", 2, "expected 3 fields"},
      {"second image at a time", [](SessionText* t) { t->images.push_back(t->images[1]); },
       "images.txt", 5, "second image of 'cam0' at 2000"},
  };
  for (const BrokenCase& c : cases) {
    SCOPED_TRACE(c.what);
    TempDir dir("test_lamar");
    SessionText text(dir.path());
    c.damage(&text);
    text.write();
    LamarSession session;
    std::string error;
    EXPECT_FALSE(read_lamar_session(dir.path().string(), &session, &error));
    const std::string where =
        text.path(c.file) + (c.line > 0 ? ":" + std::to_string(c.line) : "") + ": ";
    EXPECT_TRUE(contains(error, where));
    EXPECT_TRUE(contains(error, c.message));
  }
  LamarSession session;
  std::string error;
  EXPECT_FALSE(read_lamar_session("/nonexistent/session", &session, &error));
  EXPECT_TRUE(contains(error, "/nonexistent/session: no such directory"));
}

// The real session, checked against values read by hand from its files (MANIFEST.md there).
TEST(Lamar, RealPhoneQueryFrame) {
  const fs::path dir = shared_data_dir() / "lamar_phone_query_1" / "sessions" /
                       "ios_2022-01-12_16.32.48_000_14911412476";
  if (!fs::exists(dir)) GTEST_SKIP() << dir << " not present";
  LamarSession session;
  std::string error;
  ASSERT_TRUE(read_lamar_session(dir.string(), &session, &error)) << error;

  // sensors.txt: the camera of this frame, and a bluetooth sensor without parameters.
  const std::string camera = "ios_2022-01-12_16.32.48_000/cam_phone_14911412476";
  ASSERT_EQ(session.sensors.size(), 2u);
  EXPECT_EQ(session.sensors[0].id, camera);
  EXPECT_EQ(session.sensors[0].name, "phone camera for timestamp 14911412476");
  EXPECT_EQ(session.sensors[1].id, "ios_2022-01-12_16.32.48_000/bt_sensor");
  EXPECT_EQ(session.sensors[1].type, "bluetooth");
  EXPECT_FALSE(session.sensors[1].is_camera());
  EXPECT_TRUE(session.rigs.empty());  // no rigs.txt

  // PINHOLE 1440 1920 1590.657593 1590.657593 716.893005 939.960144, principal point moved to
  // pixel centres at integers.
  const LamarSensor& sensor = session.sensors[0];
  EXPECT_EQ(sensor.model, "PINHOLE");
  EXPECT_TRUE(sensor.unsupported.empty()) << sensor.unsupported;
  const CameraIntrinsics& c = sensor.intrinsics;
  EXPECT_EQ(c.width, 1440);
  EXPECT_EQ(c.height, 1920);
  EXPECT_DOUBLE_EQ(c.fx, 1590.657593);
  EXPECT_DOUBLE_EQ(c.fy, 1590.657593);
  EXPECT_NEAR(c.cx, 716.393005, 1e-9);
  EXPECT_NEAR(c.cy, 939.460144, 1e-9);
  EXPECT_EQ(c.distortion_model, "plumb_bob");
  EXPECT_EQ(c.D, std::vector<double>(5, 0.0));

  // images.txt: microseconds since the start of the recording, the JPEG under raw_data/.
  ASSERT_EQ(session.images.size(), 1u);
  const LamarImage& image = session.images[0];
  EXPECT_EQ(image.timestamp_us, 14911412476);
  EXPECT_EQ(image.sensor_id, camera);
  EXPECT_EQ(image.line, 2);
  EXPECT_EQ(fs::path(image.path),
            dir / "raw_data" / "ios_2022-01-12_16.32.48_000" /
                "ios_2022-01-12_16.32.48_000_14911412476" / "14911412476.jpg");

  // trajectories.txt: qw qx qy qz tx ty tz of the camera itself, camera-to-world.
  EXPECT_EQ(session.poses_path, (dir / "trajectories.txt").string());
  Eigen::Isometry3d T_world_camera;
  ASSERT_TRUE(session.camera_pose(14911412476, camera, &T_world_camera));
  const Eigen::Quaterniond q(-0.13748284967929092, -0.3193805157658011, -0.39862177517258024,
                             0.848643171510555);
  EXPECT_TRUE(T_world_camera.linear().isApprox(q.normalized().toRotationMatrix(), 1e-12));
  EXPECT_TRUE(T_world_camera.translation().isApprox(
      Eigen::Vector3d(-16.152784, 3.622267, 30.62104), 1e-12));

  // One stream per phone: the sub-session's per-frame cameras without their timestamps.
  const std::vector<LamarStream> streams = lamar_camera_streams(session);
  ASSERT_EQ(streams.size(), 1u);
  EXPECT_EQ(streams[0].id, "ios_2022-01-12_16.32.48_000/cam_phone");
  EXPECT_EQ(streams[0].images, std::vector<size_t>{0});
}

}  // namespace
}  // namespace datasets
}  // namespace hybrid_vo
