#include "fuzz_targets.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

#include <Eigen/Geometry>
#include <boost/make_shared.hpp>
#include <hybrid_vo/FeatureLines.h>
#include <hybrid_vo/FeaturePoints.h>
#include <opencv2/imgcodecs.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud.h>

#include "hybrid_vo/datasets/kitti.h"
#include "hybrid_vo/datasets/lamar.h"
#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/node/compressed_image.h"
#include "hybrid_vo/node/conversions.h"

namespace hybrid_vo {
namespace fuzz {

const char kPartSeparator[] = "\n~~~\n";

namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------------------------------------------
// Files

// One scratch folder per process (in memory when /dev/shm is there), removed at exit.
const fs::path& scratch() {
  static const fs::path dir = [] {
    std::error_code ec;
    const fs::path base = fs::is_directory("/dev/shm", ec) && ::access("/dev/shm", W_OK) == 0
                              ? fs::path("/dev/shm")
                              : fs::temp_directory_path();
    std::string pattern = (base / "hybrid_vo_fuzz_XXXXXX").string();
    if (!mkdtemp(pattern.data())) std::abort();
    std::atexit([] {
      std::error_code ignored;
      fs::remove_all(scratch(), ignored);
    });
    return fs::path(pattern);
  }();
  return dir;
}

void write(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary).write(text.data(), static_cast<std::streamsize>(text.size()));
}

std::vector<std::string> split_parts(const uint8_t* data, size_t size) {
  const std::string all(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> parts;
  size_t begin = 0;
  while (true) {
    const size_t end = all.find(kPartSeparator, begin);
    parts.push_back(all.substr(begin, end == std::string::npos ? end : end - begin));
    if (end == std::string::npos) return parts;
    begin = end + std::strlen(kPartSeparator);
  }
}

// A fresh folder `name` in the scratch folder holding `files` (path -> content) and empty files
// at `images`; parts beyond the input's are absent.
fs::path folder(const std::string& name, const std::vector<std::pair<std::string, std::string>>& files,
                const std::vector<std::string>& images) {
  const fs::path dir = scratch() / name;
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  for (const auto& [path, text] : files) write(dir / path, text);
  for (const std::string& image : images) write(dir / image, "");
  return dir;
}

std::string joined(const std::vector<std::string>& parts) {
  std::string s;
  for (size_t i = 0; i < parts.size(); ++i) s += (i ? kPartSeparator : "") + parts[i];
  return s;
}

// ------------------------------------------------------------------------------------------------
// Promises

bool finite(double v) { return std::isfinite(v); }

template <typename Derived>
bool finite(const Eigen::MatrixBase<Derived>& m) {
  return m.allFinite();
}

bool rotation(const Eigen::Matrix3d& R) {
  return R.allFinite() && (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() < 1e-6 &&
         std::abs(R.determinant() - 1.0) < 1e-6;
}

// A rejection must say why, naming the file (under `dir`) it is about.
Outcome file_outcome(bool accepted, const std::string& error, const fs::path& dir) {
  Outcome o;
  o.accepted = accepted;
  o.error = error;
  if (!accepted) {
    const std::string prefix = dir.string();
    if (error.rfind(prefix, 0) != 0 || error.find(": ", prefix.size()) == std::string::npos ||
        error.size() < error.find(": ", prefix.size()) + 4)
      o.violation = "rejected without an error naming a file: '" + error + "'";
  }
  return o;
}

Outcome message_outcome(bool accepted, const std::string& error) {
  Outcome o;
  o.accepted = accepted;
  o.error = error;
  if (!accepted && error.size() < 5) o.violation = "rejected without a reason: '" + error + "'";
  return o;
}

void expect(Outcome* o, bool condition, const std::string& what) {
  if (o->accepted && !condition && o->violation.empty()) o->violation = "accepted, but " + what;
}

bool valid_pinhole(const PinholeCamera& c) {
  return c.valid() && finite(c.cx) && finite(c.cy);
}

// ------------------------------------------------------------------------------------------------
// Binary inputs for the messages: values straight from the bytes (NaN, inf and huge values come
// naturally), array lengths chosen independently so that they may disagree.

class ByteReader {
 public:
  ByteReader(const uint8_t* data, size_t size) : p_(data), end_(data + size) {}
  size_t left() const { return static_cast<size_t>(end_ - p_); }
  uint8_t u8() { return p_ < end_ ? *p_++ : 0; }
  template <typename T>
  T value() {
    T v{};
    const size_t n = std::min(sizeof(T), left());
    std::memcpy(&v, p_, n);
    p_ += n;
    return v;
  }
  // An array length: one byte, at most what the remaining bytes can fill. (The byte is read
  // before left() is asked: the order of evaluation of function arguments is unspecified.)
  size_t count(size_t element_size) {
    const size_t wanted = u8();
    return std::min<size_t>(wanted, left() / element_size + 1);
  }
  std::string text(size_t max) {
    const size_t wanted = u8() % (max + 1);
    const size_t n = std::min<size_t>(wanted, left());
    std::string s(reinterpret_cast<const char*>(p_), n);
    p_ += n;
    return s;
  }
  std::string rest() {
    std::string s(reinterpret_cast<const char*>(p_), left());
    p_ = end_;
    return s;
  }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
};

class ByteWriter {
 public:
  template <typename T>
  ByteWriter& value(T v) {
    out_.append(reinterpret_cast<const char*>(&v), sizeof(T));
    return *this;
  }
  ByteWriter& u8(uint8_t v) { return value(v); }
  template <typename T>
  ByteWriter& array(const std::vector<T>& v) {
    u8(static_cast<uint8_t>(v.size()));
    for (const T& x : v) value(x);
    return *this;
  }
  ByteWriter& text(const std::string& s) {
    u8(static_cast<uint8_t>(s.size()));
    out_ += s;
    return *this;
  }
  const std::string& bytes() const { return out_; }

 private:
  std::string out_;
};

template <typename T>
std::vector<T> array(ByteReader* r) {
  std::vector<T> v(r->count(sizeof(T)));
  for (T& x : v) x = r->value<T>();
  return v;
}

const PinholeCamera& vins_camera() {
  static const PinholeCamera camera(458.7, 457.3, 367.2, 248.4, 752, 480);
  return camera;
}

// The encodings a camera driver may send, and whatever else the bytes say.
std::string encoding(ByteReader* r) {
  static const char* kKnown[] = {"mono8", "mono16", "bgr8",  "rgb8",        "bgra8",
                                 "rgba8", "8UC1",   "32FC1", "bayer_rggb8", "16UC3"};
  const uint8_t pick = r->u8();
  if (pick < 2 * std::size(kKnown)) return kKnown[pick % std::size(kKnown)];
  return r->text(12);
}

std::string distortion_model(ByteReader* r) {
  static const char* kModels[] = {"plumb_bob", "rational_polynomial", "equidistant", ""};
  const uint8_t pick = r->u8();
  return pick < 8 ? kModels[pick % 4] : r->text(20);
}

void check_external(Outcome* o, const ExternalFeatures& f, bool lines) {
  if (lines) {
    expect(o, f.has_lines && f.lines.size() == f.line_ids.size(), "lines and ids differ in count");
    for (const LineSegment& s : f.lines)
      expect(o, finite(s.p1) && finite(s.p2) && s.length() > 0.0, "a degenerate or non-finite segment");
  } else {
    expect(o, f.has_points && f.points.size() == f.point_ids.size(), "points and ids differ in count");
    for (const Eigen::Vector2d& p : f.points) expect(o, finite(p), "a non-finite point");
  }
}

// ------------------------------------------------------------------------------------------------
// Targets

Outcome kitti_calib(const uint8_t* data, size_t size) {
  const fs::path dir = folder("kitti_calib", {{"calib.txt", std::string(reinterpret_cast<const char*>(data), size)}}, {});
  datasets::KittiCalibration c;
  std::string error;
  const bool ok = datasets::read_kitti_calibration((dir / "calib.txt").string(), &c, &error);
  Outcome o = file_outcome(ok, error, dir);
  expect(&o, c.P0.present() && finite(c.P0.P) && valid_pinhole(c.P0.camera), "P0 is not usable");
  if (c.P1.present())
    expect(&o, finite(c.P1.P) && valid_pinhole(c.P1.camera) && c.baseline() > 0.0 &&
                   finite(c.baseline()),
           "P1 gives no finite positive baseline");
  return o;
}

Outcome kitti_times(const uint8_t* data, size_t size) {
  const fs::path dir = folder("kitti_times", {{"times.txt", std::string(reinterpret_cast<const char*>(data), size)}}, {});
  std::vector<double> times;
  std::string error;
  const bool ok = datasets::read_kitti_times((dir / "times.txt").string(), &times, &error);
  Outcome o = file_outcome(ok, error, dir);
  expect(&o, !times.empty(), "no timestamps");
  for (size_t k = 0; k < times.size(); ++k)
    expect(&o, finite(times[k]) && (k == 0 || times[k] > times[k - 1]),
           "timestamps are not finite and increasing");
  return o;
}

Outcome kitti_poses(const uint8_t* data, size_t size) {
  const fs::path dir = folder("kitti_poses", {{"00.txt", std::string(reinterpret_cast<const char*>(data), size)}}, {});
  std::vector<datasets::KittiPose> poses;
  std::string error;
  const bool ok = datasets::read_kitti_poses((dir / "00.txt").string(), &poses, &error);
  Outcome o = file_outcome(ok, error, dir);
  expect(&o, !poses.empty(), "no poses");
  for (const datasets::KittiPose& p : poses)
    expect(&o, rotation(p.R_wc) && finite(p.c_w), "a pose is not a finite rigid motion");
  return o;
}

void check_sequence(Outcome* o, const datasets::Sequence& s) {
  expect(o, !s.frames.empty(), "no frames");
  for (const datasets::Frame& f : s.frames) {
    expect(o, rotation(f.R_wc) && finite(f.c_w) && finite(f.timestamp), "a frame's pose is not finite");
    expect(o, f.camera.valid() && finite(f.camera.pinhole.cx) && finite(f.camera.pinhole.cy),
           "a frame's camera is not valid");
    std::error_code ec;
    expect(o, fs::is_regular_file(f.image_path, ec), "a frame's image does not exist");
  }
}

// Parts: rgb.txt, groundtruth.txt, camera.txt; the folder holds rgb/1.png and rgb/2.png.
Outcome tum(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = split_parts(data, size);
  static const char* kFiles[] = {"rgb.txt", "groundtruth.txt", "camera.txt"};
  std::vector<std::pair<std::string, std::string>> files;
  for (size_t i = 0; i < parts.size() && i < 3; ++i) files.emplace_back(kFiles[i], parts[i]);
  const fs::path dir = folder("tum", files, {"rgb/1.png", "rgb/2.png"});
  datasets::Sequence s;
  std::string error;
  const bool ok = datasets::read_tum(dir.string(), &s, &error);
  Outcome o = file_outcome(ok, error, dir);
  check_sequence(&o, s);
  return o;
}

// Parts: gt_dense_cameras/a.png.camera and b.png.camera; the folder holds images/a.png, b.png.
Outcome strecha(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = split_parts(data, size);
  static const char* kFiles[] = {"gt_dense_cameras/a.png.camera", "gt_dense_cameras/b.png.camera"};
  std::vector<std::pair<std::string, std::string>> files;
  for (size_t i = 0; i < parts.size() && i < 2; ++i) files.emplace_back(kFiles[i], parts[i]);
  const fs::path dir = folder("strecha", files, {"images/a.png", "images/b.png"});
  fs::create_directories(dir / "gt_dense_cameras");
  datasets::Sequence s;
  std::string error;
  const bool ok = datasets::read_strecha(dir.string(), &s, &error);
  Outcome o = file_outcome(ok, error, dir);
  check_sequence(&o, s);
  for (const datasets::Frame& f : s.frames)
    expect(&o, f.camera.pinhole.width >= 1 && f.camera.pinhole.height >= 1, "an image size < 1");
  return o;
}

Outcome superglue(const uint8_t* data, size_t size) {
  const fs::path dir = folder("superglue", {{"pairs.txt", std::string(reinterpret_cast<const char*>(data), size)}}, {});
  std::vector<datasets::PairWithGt> pairs;
  std::string error;
  const bool ok = datasets::read_superglue((dir / "pairs.txt").string(), "", &pairs, &error);
  Outcome o = file_outcome(ok, error, dir);
  expect(&o, !pairs.empty(), "no pairs");
  for (const datasets::PairWithGt& p : pairs) {
    expect(&o, rotation(p.pose.R) && finite(p.pose.t), "a pose is not a finite rigid motion");
    expect(&o, valid_pinhole(p.camera0.pinhole) && valid_pinhole(p.camera1.pinhole),
           "a camera is not valid");
    expect(&o, p.rotation0 >= 0 && p.rotation0 <= 3 && p.rotation1 >= 0 && p.rotation1 <= 3,
           "a rotation count outside 0..3");
  }
  return o;
}

// Parts: sensors.txt, rigs.txt, trajectories.txt, images.txt; raw_data/img/1.png exists.
Outcome lamar(const uint8_t* data, size_t size) {
  const std::vector<std::string> parts = split_parts(data, size);
  static const char* kFiles[] = {"sensors.txt", "rigs.txt", "trajectories.txt", "images.txt"};
  std::vector<std::pair<std::string, std::string>> files;
  for (size_t i = 0; i < parts.size() && i < 4; ++i) files.emplace_back(kFiles[i], parts[i]);
  const fs::path dir = folder("lamar", files, {"raw_data/img/1.png", "raw_data/img/2.png"});
  datasets::LamarSession s;
  std::string error;
  const bool ok = datasets::read_lamar_session(dir.string(), &s, &error);
  Outcome o = file_outcome(ok, error, dir);
  if (!ok) return o;
  expect(&o, !s.images.empty(), "no images");
  for (const datasets::LamarImage& image : s.images) {
    const datasets::LamarSensor* sensor = s.sensor(image.sensor_id);
    expect(&o, sensor && sensor->is_camera(), "an image of no camera");
    if (sensor && sensor->unsupported.empty()) {
      const datasets::CameraIntrinsics& c = sensor->intrinsics;
      expect(&o, c.width > 0 && c.height > 0 && c.fx > 0 && c.fy > 0 && finite(c.fx) &&
                     finite(c.fy) && finite(c.cx) && finite(c.cy),
             "a supported camera without valid intrinsics");
      for (double d : c.D) expect(&o, finite(d), "a non-finite distortion coefficient");
    }
  }
  for (const auto& [key, T] : s.poses)
    expect(&o, rotation(T.linear()) && finite(T.translation()), "a pose is not a rigid motion");
  for (const auto& [rig, members] : s.rigs)
    for (const auto& [sensor, T] : members)
      expect(&o, rotation(T.linear()) && finite(T.translation()), "a rig entry is not rigid");
  // Every image belongs to exactly one stream.
  std::multiset<size_t> seen;
  for (const datasets::LamarStream& stream : datasets::lamar_camera_streams(s))
    seen.insert(stream.images.begin(), stream.images.end());
  expect(&o, seen.size() == s.images.size() && std::set<size_t>(seen.begin(), seen.end()).size() ==
                                                   s.images.size(),
         "the camera streams do not split the images");
  return o;
}

Outcome feature_points(const uint8_t* data, size_t size) {
  ByteReader r(data, size);
  FeaturePoints msg;
  msg.ids = array<int64_t>(&r);
  msg.x = array<float>(&r);
  msg.y = array<float>(&r);
  ExternalFeatures f;
  std::string error;
  Outcome o = message_outcome(points_from_msg(msg, &f, &error), error);
  check_external(&o, f, false);
  return o;
}

Outcome feature_lines(const uint8_t* data, size_t size) {
  ByteReader r(data, size);
  FeatureLines msg;
  msg.ids = array<int64_t>(&r);
  msg.x1 = array<float>(&r);
  msg.y1 = array<float>(&r);
  msg.x2 = array<float>(&r);
  msg.y2 = array<float>(&r);
  ExternalFeatures f;
  std::string error;
  Outcome o = message_outcome(lines_from_msg(msg, &f, &error), error);
  check_external(&o, f, true);
  return o;
}

sensor_msgs::PointCloud point_cloud(ByteReader* r) {
  sensor_msgs::PointCloud msg;
  msg.points.resize(r->count(3 * sizeof(float)));
  for (auto& p : msg.points) {
    p.x = r->value<float>();
    p.y = r->value<float>();
    p.z = r->value<float>();
  }
  msg.channels.resize(r->u8() % 6);
  for (auto& c : msg.channels) c.values = array<float>(r);
  return msg;
}

// Both VINS encodings share one message type; `lines` picks the conversion.
Outcome vins(const uint8_t* data, size_t size, bool lines) {
  ByteReader r(data, size);
  const sensor_msgs::PointCloud msg = point_cloud(&r);
  ExternalFeatures f;
  std::string error;
  const bool ok = lines ? lines_from_vins(msg, vins_camera(), &f, &error)
                        : points_from_vins(msg, vins_camera(), &f, &error);
  Outcome o = message_outcome(ok, error);
  check_external(&o, f, lines);
  return o;
}

Outcome vins_points(const uint8_t* data, size_t size) { return vins(data, size, false); }
Outcome vins_lines(const uint8_t* data, size_t size) { return vins(data, size, true); }

Outcome camera_info(const uint8_t* data, size_t size) {
  ByteReader r(data, size);
  sensor_msgs::CameraInfo info;
  info.width = r.value<uint32_t>();
  info.height = r.value<uint32_t>();
  info.distortion_model = distortion_model(&r);
  info.D = array<double>(&r);
  for (double& k : info.K) k = r.value<double>();
  for (double& p : info.P) p = r.value<double>();
  CameraModel camera;
  std::string error;
  Outcome o = message_outcome(camera_from_info(info, &camera, &error), error);
  expect(&o, camera.valid() && valid_pinhole(camera.pinhole) && camera.pinhole.width > 0 &&
                 camera.pinhole.height > 0,
         "the camera is not valid");
  double baseline = 0.0;
  if (baseline_from_info(info, &baseline))
    if (!(finite(baseline) && baseline > 0.0) && o.violation.empty())
      o.violation = "a baseline that is not finite and positive";
  return o;
}

Outcome image(const uint8_t* data, size_t size) {
  ByteReader r(data, size);
  auto image = boost::make_shared<sensor_msgs::Image>();
  image->encoding = encoding(&r);
  const bool wide = r.u8() & 1;  // 16-bit sizes mostly, full 32-bit ones sometimes
  image->width = wide ? r.value<uint32_t>() : r.value<uint16_t>();
  image->height = wide ? r.value<uint32_t>() : r.value<uint16_t>();
  image->step = wide ? r.value<uint32_t>() : r.value<uint16_t>();
  image->is_bigendian = r.u8() & 1;
  const std::string pixels = r.rest();
  image->data.assign(pixels.begin(), pixels.end());
  cv::Mat gray;
  std::string error;
  Outcome o = message_outcome(gray_from_image(image, &gray, &error), error);
  expect(&o, gray.type() == CV_8UC1 && gray.cols == static_cast<int>(image->width) &&
                 gray.rows == static_cast<int>(image->height),
         "the grey image is not 8-bit of the message's size");
  return o;
}

// A CompressedImage: its format (one of the usual ones, or arbitrary text), the size its
// camera_info gives, then the payload.
Outcome compressed_image(const uint8_t* data, size_t size) {
  ByteReader r(data, size);
  static const char* kFormats[] = {"mono8; png compressed ", "mono8; jpeg compressed mono8",
                                   "bgr8; jpeg compressed bgr8", "png", "jpeg", "",
                                   "16UC1; compressedDepth png"};
  sensor_msgs::CompressedImage image;
  const uint8_t pick = r.u8();
  image.format = pick < 2 * std::size(kFormats) ? kFormats[pick % std::size(kFormats)] : r.text(30);
  const int width = r.value<uint16_t>(), height = r.value<uint16_t>();
  const std::string payload = r.rest();
  image.data.assign(payload.begin(), payload.end());
  cv::Mat gray;
  std::string error;
  Outcome o = message_outcome(gray_from_compressed(image, width, height, &gray, &error), error);
  expect(&o, gray.type() == CV_8UC1 && gray.cols == width && gray.rows == height,
         "the grey image is not 8-bit of the camera_info's size");
  return o;
}

// ------------------------------------------------------------------------------------------------
// Seeds

std::string number(double v) {
  char s[32];
  std::snprintf(s, sizeof(s), "%.15g", v);  // TUM stamps need 15 digits
  return s;
}

std::string matrix(const Eigen::Matrix3d& R, const char* separator = " ") {
  std::string s;
  for (int k = 0; k < 9; ++k) s += (k ? separator : "") + number(R(k / 3, k % 3));
  return s;
}

Eigen::Matrix3d some_rotation(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d(0.3, -0.8, 0.5).normalized()).toRotationMatrix();
}

std::vector<std::string> kitti_calib_seeds() {
  const std::string K = "7.188560000000e+02 0.000000000000e+00 6.071928000000e+02 ";
  const std::string row2 = "0.000000000000e+00 7.188560000000e+02 1.852157000000e+02 0.000000000000e+00 ";
  const std::string row3 = "0.000000000000e+00 0.000000000000e+00 1.000000000000e+00 0.000000000000e+00";
  return {"P0: " + K + "0.000000000000e+00 " + row2 + row3 + "\nP1: " + K +
              "-3.861448000000e+02 " + row2 + row3 + "\nP2: " + K + "4.538225000000e+01 " + row2 +
              row3 + "\nTr: 1 0 0 0 0 1 0 0 0 0 1 0\n",
          "P0: 500 0 320 0 0 500 240 0 0 0 1 0\n"};
}

std::vector<std::string> kitti_times_seeds() {
  return {"0.000000e+00\n1.036000e-01\n2.073000e-01\n3.109000e-01\n", "0\n0.1\n\n\n"};
}

std::vector<std::string> kitti_poses_seeds() {
  std::string moving;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Matrix3d R = some_rotation(0.1 * i);
    for (int r = 0; r < 3; ++r)
      moving += number(R(r, 0)) + " " + number(R(r, 1)) + " " + number(R(r, 2)) + " " +
                number(0.8 * i * (r + 1)) + (r < 2 ? " " : "\n");
  }
  return {"1 0 0 0 0 1 0 0 0 0 1 0\n", moving};
}

std::vector<std::string> tum_seeds() {
  const Eigen::Quaterniond q(some_rotation(0.4));
  auto gt = [&](double t, double x) {
    return number(t) + " " + number(x) + " 0.6266 1.6575 " + number(q.x()) + " " + number(q.y()) +
           " " + number(q.z()) + " " + number(q.w()) + "\n";
  };
  return {joined({"# color images\n# timestamp filename\n1305031102.175304 rgb/1.png\n"
                  "1305031102.211214 rgb/2.png\n",
                  "# ground truth trajectory\n" + gt(1305031102.1758, 1.3405) +
                      gt(1305031102.2058, 1.3303),
                  "fx 517.3\nfy 516.5\ncx 318.6\ncy 255.3\nk1 0.2624\nk2 -0.9531\np1 -0.0054\n"
                  "p2 0.0026\nk3 1.1633\nwidth 640\nheight 480\n"}),
          joined({"1 rgb/1.png\n", "1.01 0 0 0 0 0 0 1\n", "fx 500\nfy 500\ncx 320\ncy 240\n"})};
}

std::vector<std::string> strecha_seeds() {
  auto camera = [](double angle, double x) {
    return "2759.48 0 1520.69\n0 2764.16 1006.81\n0 0 1\n0 0 0\n" +
           matrix(some_rotation(angle), "\n") + "\n" + number(x) + " -7.57667 0.805813\n3072 2048\n";
  };
  return {joined({camera(0.2, -7.28), camera(0.3, -6.1)}), joined({camera(0.0, 0.0)})};
}

std::vector<std::string> superglue_seeds() {
  auto line = [](const char* a, const char* b, double angle) {
    const Eigen::Matrix3d R = some_rotation(angle);
    std::string T;
    for (int r = 0; r < 3; ++r)
      T += number(R(r, 0)) + " " + number(R(r, 1)) + " " + number(R(r, 2)) + " " +
           number(0.1 * (r + 1)) + " ";
    return std::string(a) + " " + b + " 0 1 1152 0 576 0 1152 432 0 0 1 "
           "1152 0 576 0 1152 432 0 0 1 " + T + "0 0 0 1\n";
  };
  return {"# pairs\n" + line("scene/a.jpg", "scene/b.jpg", 0.2) + line("c.png", "d.png", 1.0),
          line("x.png", "y.png", 0.0)};
}

std::vector<std::string> lamar_seeds() {
  const Eigen::Quaterniond q(some_rotation(0.3));
  const std::string quat =
      number(q.w()) + ", " + number(q.x()) + ", " + number(q.y()) + ", " + number(q.z());
  return {
      joined({"# sensor_id, name, sensor_type, [sensor_params]+\n"
              "cam-left, left, camera, PINHOLE, 640, 480, 500, 500, 320.5, 240.5\n"
              "cam_right, right, camera, OPENCV, 640, 480, 500, 501, 320.5, 240.5, 0.1, -0.02, "
              "0.001, 0.002\n"
              "imu, imu, imu\n",
              "# rig_id, sensor_id, qw, qx, qy, qz, tx, ty, tz\n"
              "rig, cam-left, 1, 0, 0, 0, 0, 0, 0\nrig, cam_right, " + quat + ", 0.12, 0, 0\n",
              "# timestamp, device_id, qw, qx, qy, qz, tx, ty, tz\n"
              "100000, rig, 1, 0, 0, 0, 0, 0, 0\n200000, rig, " + quat + ", 0.5, 0.1, 0\n",
              "# timestamp, sensor_id, image_path\n100000, cam-left, img/1.png\n"
              "100000, cam_right, img/2.png\n200000, cam-left, img/2.png\n"}),
      // A phone: one camera per frame.
      joined({"cam_phone_1000, phone, camera, SIMPLE_RADIAL, 480, 640, 480, 240, 320, 0.01\n"
              "cam_phone_2000, phone, camera, FULL_OPENCV, 480, 640, 480, 480, 240, 320, 0.1, "
              "0.01, 0, 0, 0, 0, 0, 0\n",
              "",
              "1000, cam_phone_1000, 1, 0, 0, 0, 1, 2, 3\n2000, cam_phone_2000, " + quat +
                  ", 1, 2, 3.1\n",
              "1000, cam_phone_1000, img/1.png\n2000, cam_phone_2000, img/2.png\n"})};
}

std::vector<std::string> feature_points_seeds() {
  return {ByteWriter()
              .array<int64_t>({1, 2, 3, 70000000000})
              .array<float>({10.5f, 200.f, 300.25f, 1.f})
              .array<float>({20.f, 40.f, 60.f, 479.f})
              .bytes(),
          ByteWriter().array<int64_t>({7}).array<float>({1.f, 2.f}).array<float>({3.f}).bytes()};
}

std::vector<std::string> feature_lines_seeds() {
  return {ByteWriter()
              .array<int64_t>({4, 5})
              .array<float>({10.f, 100.f})
              .array<float>({20.f, 200.f})
              .array<float>({50.f, 100.f})
              .array<float>({20.f, 300.f})
              .bytes()};
}

std::string point_cloud_seed(const std::vector<float>& xyz, const std::vector<std::vector<float>>& channels) {
  ByteWriter w;
  w.u8(static_cast<uint8_t>(xyz.size() / 3));
  for (float v : xyz) w.value(v);
  w.u8(static_cast<uint8_t>(channels.size()));
  for (const auto& c : channels) w.array(c);
  return w.bytes();
}

std::vector<std::string> vins_points_seeds() {
  return {point_cloud_seed({0.1f, -0.2f, 1.f, 0.3f, 0.05f, 1.f},
                           {{12.f, 13.f}, {400.f, 500.f}, {200.f, 260.f}, {0.f, 0.f}, {0.f, 0.f}}),
          point_cloud_seed({0.1f, 0.1f, 1.f}, {})};
}

std::vector<std::string> vins_lines_seeds() {
  return {point_cloud_seed({0.1f, -0.2f, 1.f, -0.3f, 0.05f, 1.f},
                           {{12.f, 13.f}, {0.2f, -0.3f}, {-0.2f, 0.25f}})};
}

std::vector<std::string> camera_info_seeds() {
  auto info = [](uint32_t w, uint32_t h, uint8_t model, const std::vector<double>& D, double tx) {
    ByteWriter b;
    b.value(w).value(h).u8(model).array(D);
    for (double k : {500.0, 0.0, 320.0, 0.0, 500.0, 240.0, 0.0, 0.0, 1.0}) b.value(k);
    for (double p : {500.0, 0.0, 320.0, tx, 0.0, 500.0, 240.0, 0.0, 0.0, 0.0, 1.0, 0.0}) b.value(p);
    return b.bytes();
  };
  return {info(640, 480, 0, {0.1, -0.2, 0.001, 0.002, 0.0}, 0.0),
          info(1241, 376, 1, {0.1, -0.2, 0.0, 0.0, 0.01, 0.0, 0.0, 0.0}, -386.1)};
}

std::vector<std::string> image_seeds() {
  auto image = [](uint8_t encoding, uint16_t w, uint16_t h, uint16_t step, size_t bytes) {
    ByteWriter b;
    b.u8(encoding).u8(0).value(w).value(h).value(step).u8(0);
    std::string s = b.bytes();
    for (size_t i = 0; i < bytes; ++i) s += static_cast<char>(i * 37);
    return s;
  };
  return {image(0, 4, 3, 4, 12), image(2, 3, 2, 9, 18), image(1, 2, 2, 4, 8),
          image(5, 2, 1, 8, 8)};
}

std::vector<std::string> compressed_image_seeds() {
  cv::Mat image(6, 8, CV_8UC1);
  for (int k = 0; k < 48; ++k) image.data[k] = static_cast<uint8_t>(k * 37);
  cv::Mat wide;
  image.convertTo(wide, CV_16U, 257.0);
  auto seed = [&](uint8_t format, const std::string& ext, const cv::Mat& pixels) {
    std::vector<uint8_t> bytes;
    cv::imencode(ext, pixels, bytes);
    ByteWriter b;
    b.u8(format).value(static_cast<uint16_t>(pixels.cols)).value(static_cast<uint16_t>(pixels.rows));
    return b.bytes() + std::string(bytes.begin(), bytes.end());
  };
  return {seed(0, ".png", image), seed(1, ".jpg", image), seed(3, ".png", wide)};
}

}  // namespace

const std::vector<Target>& targets() {
  static const std::vector<Target> all = {
      {"kitti_calib", kitti_calib, kitti_calib_seeds, true},
      {"kitti_times", kitti_times, kitti_times_seeds, true},
      {"kitti_poses", kitti_poses, kitti_poses_seeds, true},
      {"tum", tum, tum_seeds, true},
      {"strecha", strecha, strecha_seeds, true},
      {"superglue", superglue, superglue_seeds, true},
      {"lamar", lamar, lamar_seeds, true},
      {"feature_points", feature_points, feature_points_seeds, false},
      {"feature_lines", feature_lines, feature_lines_seeds, false},
      {"vins_points", vins_points, vins_points_seeds, false},
      {"vins_lines", vins_lines, vins_lines_seeds, false},
      {"camera_info", camera_info, camera_info_seeds, false},
      {"image", image, image_seeds, false},
      {"compressed_image", compressed_image, compressed_image_seeds, false},
  };
  return all;
}

const Target* find_target(const std::string& name) {
  for (const Target& t : targets())
    if (name == t.name) return &t;
  return nullptr;
}

}  // namespace fuzz
}  // namespace hybrid_vo
