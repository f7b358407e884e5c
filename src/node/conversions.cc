#include "hybrid_vo/node/conversions.h"

#include <cmath>

#include <Eigen/Geometry>
#include <cv_bridge/cv_bridge.h>
#include <opencv2/imgproc.hpp>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/image_encodings.h>
#include <tf2_eigen/tf2_eigen.h>

namespace hybrid_vo {

bool camera_from_info(const sensor_msgs::CameraInfo& info, CameraModel* camera,
                      std::string* reason) {
  CameraModel c;
  c.pinhole = PinholeCamera(info.K[0], info.K[4], info.K[2], info.K[5], info.width, info.height);
  if (!c.pinhole.valid() || info.width == 0 || info.height == 0) {
    *reason = "camera_info has no valid K or image size";
    return false;
  }
  namespace models = sensor_msgs::distortion_models;
  const std::string& model = info.distortion_model;
  // plumb_bob: k1 k2 p1 p2 k3; rational_polynomial adds k4..k6, taken while they are zero;
  // equidistant: k1..k4.
  size_t coefficients = 5;
  if (model == models::EQUIDISTANT) {
    c.model = LensModel::kEquidistant;
    coefficients = 4;
  } else if (!model.empty() && model != models::PLUMB_BOB &&
             model != models::RATIONAL_POLYNOMIAL) {
    *reason = "unsupported distortion model '" + model +
              "' (plumb_bob, rational_polynomial or equidistant)";
    return false;
  }
  for (size_t k = 0; k < info.D.size(); ++k) {
    if (!std::isfinite(info.D[k])) {
      *reason = "camera_info has a non-finite distortion coefficient";
      return false;
    }
    if (k < coefficients) {
      c.distortion[k] = info.D[k];
    } else if (info.D[k] != 0.0) {
      *reason = "distortion model '" + (model.empty() ? std::string("plumb_bob") : model) +
                "' with more than " + std::to_string(coefficients) +
                " coefficients is not supported";
      return false;
    }
  }
  if (const std::string problem = camera_model_problem(c); !problem.empty()) {
    *reason = problem;
    return false;
  }
  *camera = c;
  return true;
}

bool rectification_from_info(const sensor_msgs::CameraInfo& info, Eigen::Matrix3d* R) {
  Eigen::Matrix3d m;
  for (int k = 0; k < 9; ++k) m(k / 3, k % 3) = info.R[k];
  if (m.isZero(0.0)) {
    *R = Eigen::Matrix3d::Identity();
    return true;
  }
  if (!all_finite(m) || !((m.transpose() * m - Eigen::Matrix3d::Identity()).norm() < 1e-6) ||
      !(m.determinant() > 0.0))
    return false;
  *R = m;
  return true;
}

bool baseline_from_info(const sensor_msgs::CameraInfo& right, double* baseline) {
  // Tx = -fx * baseline; an infinite fx, or a ratio that under- or overflows, is no baseline.
  const double fx = right.P[0], tx = right.P[3];
  if (!(fx > 0.0) || !std::isfinite(fx) || !std::isfinite(tx)) return false;
  const double b = std::abs(tx / fx);
  if (!(b > 0.0) || !std::isfinite(b)) return false;
  *baseline = b;
  return true;
}

namespace {

// mono16 in the message's byte order to 8 bits. cv_bridge returns a big-endian image on a
// little-endian host as a two-channel 8-bit Mat (it byte-swaps but never reinterprets the
// result), so the swap is done here.
cv::Mat gray_from_mono16(const sensor_msgs::Image& image) {
  const int rows = static_cast<int>(image.height), cols = static_cast<int>(image.width);
  uint8_t* data = const_cast<uint8_t*>(image.data.data());  // read only
  const bool host_big_endian = __BYTE_ORDER__ == __ORDER_BIG_ENDIAN__;
  cv::Mat native(rows, cols, CV_16UC1, data, image.step);
  if (static_cast<bool>(image.is_bigendian) != host_big_endian) {
    const cv::Mat bytes(rows, cols, CV_8UC2, data, image.step);
    native = cv::Mat(rows, cols, CV_16UC1);
    cv::Mat swapped(rows, cols, CV_8UC2, native.data, native.step);
    const int from_to[] = {0, 1, 1, 0};
    cv::mixChannels(&bytes, 1, &swapped, 1, from_to, 2);
  }
  cv::Mat gray;
  native.convertTo(gray, CV_8U, 1.0 / 256.0);
  return gray;
}

}  // namespace

bool gray_from_image(const sensor_msgs::ImageConstPtr& image, cv::Mat* gray, std::string* reason) {
  namespace enc = sensor_msgs::image_encodings;
  if (!image || image->width == 0 || image->height == 0 || image->data.empty()) {
    *reason = "empty image";
    return false;
  }
  const std::string& e = image->encoding;
  if (e != enc::MONO8 && e != enc::MONO16 && e != enc::BGR8 && e != enc::RGB8 &&
      e != enc::BGRA8 && e != enc::RGBA8) {
    *reason = "unsupported encoding '" + e + "'";
    return false;
  }
  // cv_bridge checks step and size in 32-bit arithmetic, which wraps: a height * step or a
  // width * pixel size beyond 4 GB passes its checks and the pixels are read past the data.
  constexpr uint32_t kMaxSide = 1u << 16;
  if (image->width > kMaxSide || image->height > kMaxSide) {
    *reason = "image size " + std::to_string(image->width) + "x" + std::to_string(image->height) +
              " beyond " + std::to_string(kMaxSide) + " pixels a side";
    return false;
  }
  const uint64_t row = static_cast<uint64_t>(image->width) * (enc::bitDepth(e) / 8) *
                       enc::numChannels(e);
  const int bytes_per_value = enc::bitDepth(e) / 8;
  // OpenCV throws on a row step that is not a whole number of 16-bit values.
  if (image->step < row || image->step % bytes_per_value != 0 ||
      static_cast<uint64_t>(image->step) * image->height != image->data.size()) {
    *reason = "malformed image: step " + std::to_string(image->step) + " for " +
              std::to_string(row) + " bytes a row and " + std::to_string(image->data.size()) +
              " bytes for " + std::to_string(image->height) + " rows";
    return false;
  }
  try {
    if (e == enc::MONO16) {
      *gray = gray_from_mono16(*image);
      return !gray->empty();
    }
    const cv_bridge::CvImageConstPtr cv = cv_bridge::toCvShare(image);
    if (e == enc::MONO8) {
      *gray = cv->image.clone();
    } else if (e == enc::BGR8) {
      cv::cvtColor(cv->image, *gray, cv::COLOR_BGR2GRAY);
    } else if (e == enc::RGB8) {
      cv::cvtColor(cv->image, *gray, cv::COLOR_RGB2GRAY);
    } else if (e == enc::BGRA8) {
      cv::cvtColor(cv->image, *gray, cv::COLOR_BGRA2GRAY);
    } else {
      cv::cvtColor(cv->image, *gray, cv::COLOR_RGBA2GRAY);
    }
  } catch (const cv_bridge::Exception& ex) {
    *reason = std::string("cv_bridge: ") + ex.what();
    return false;
  } catch (const cv::Exception& ex) {
    *reason = std::string("OpenCV: ") + ex.what();
    return false;
  }
  return !gray->empty();
}

bool points_from_msg(const FeaturePoints& msg, ExternalFeatures* f, std::string* reason) {
  if (msg.x.size() != msg.y.size() || msg.ids.size() != msg.x.size()) {
    *reason = "features/points: ids, x and y differ in length";
    return false;
  }
  f->has_points = true;
  f->points_undistorted = false;
  f->points.clear();
  f->point_ids.clear();
  for (size_t i = 0; i < msg.x.size(); ++i) {
    if (!std::isfinite(msg.x[i]) || !std::isfinite(msg.y[i])) continue;
    f->points.emplace_back(msg.x[i], msg.y[i]);
    f->point_ids.push_back(msg.ids[i]);
  }
  return true;
}

bool lines_from_msg(const FeatureLines& msg, ExternalFeatures* f, std::string* reason) {
  const size_t n = msg.ids.size();
  if (msg.x1.size() != n || msg.y1.size() != n || msg.x2.size() != n || msg.y2.size() != n) {
    *reason = "features/lines: ids, x1, y1, x2 and y2 differ in length";
    return false;
  }
  f->has_lines = true;
  f->lines_undistorted = false;
  f->lines.clear();
  f->line_ids.clear();
  for (size_t i = 0; i < n; ++i) {
    const LineSegment s({msg.x1[i], msg.y1[i]}, {msg.x2[i], msg.y2[i]});
    if (!all_finite(s.p1) || !all_finite(s.p2) || !(s.length() > 0.0)) continue;
    f->lines.push_back(s);
    f->line_ids.push_back(msg.ids[i]);
  }
  return true;
}

namespace {

const sensor_msgs::ChannelFloat32* channel(const sensor_msgs::PointCloud& msg, size_t index,
                                           std::string* reason) {
  if (msg.channels.size() <= index || msg.channels[index].values.size() != msg.points.size()) {
    *reason = "PointCloud features: channel " + std::to_string(index) + " missing or of the wrong size";
    return nullptr;
  }
  return &msg.channels[index];
}

// VINS ids are floats; one that is not a finite integer would turn into an arbitrary id shared by
// every such feature, i.e. false matches between frames.
bool vins_id(float value, int64_t* id) {
  if (!(std::abs(value) < 9.0e15f) || value != std::round(value)) return false;
  *id = static_cast<int64_t>(value);
  return true;
}

}  // namespace

bool points_from_vins(const sensor_msgs::PointCloud& msg, const PinholeCamera& camera,
                      ExternalFeatures* f, std::string* reason) {
  const sensor_msgs::ChannelFloat32* ids = channel(msg, 0, reason);
  if (!ids) return false;
  f->has_points = true;
  f->points_undistorted = true;
  f->points.clear();
  f->point_ids.clear();
  for (size_t i = 0; i < msg.points.size(); ++i) {
    const Eigen::Vector2d p = camera.denormalize({msg.points[i].x, msg.points[i].y});
    int64_t id = 0;
    if (!all_finite(p) || !vins_id(ids->values[i], &id)) continue;
    f->points.push_back(p);
    f->point_ids.push_back(id);
  }
  return true;
}

bool lines_from_vins(const sensor_msgs::PointCloud& msg, const PinholeCamera& camera,
                     ExternalFeatures* f, std::string* reason) {
  const sensor_msgs::ChannelFloat32* ids = channel(msg, 0, reason);
  const sensor_msgs::ChannelFloat32* ex = ids ? channel(msg, 1, reason) : nullptr;
  const sensor_msgs::ChannelFloat32* ey = ex ? channel(msg, 2, reason) : nullptr;
  if (!ey) return false;
  f->has_lines = true;
  f->lines_undistorted = true;
  f->lines.clear();
  f->line_ids.clear();
  for (size_t i = 0; i < msg.points.size(); ++i) {
    const LineSegment s(camera.denormalize({msg.points[i].x, msg.points[i].y}),
                        camera.denormalize({ex->values[i], ey->values[i]}));
    int64_t id = 0;
    if (!all_finite(s.p1) || !all_finite(s.p2) || !(s.length() > 0.0) ||
        !vins_id(ids->values[i], &id))
      continue;
    f->lines.push_back(s);
    f->line_ids.push_back(id);
  }
  return true;
}

geometry_msgs::Transform to_transform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  geometry_msgs::Transform tf;
  const Eigen::Quaterniond q(R);
  tf.rotation.x = q.x();
  tf.rotation.y = q.y();
  tf.rotation.z = q.z();
  tf.rotation.w = q.w();
  tf.translation.x = t.x();
  tf.translation.y = t.y();
  tf.translation.z = t.z();
  return tf;
}

geometry_msgs::Vector3 to_vector(const Eigen::Vector3d& v) {
  geometry_msgs::Vector3 m;
  return tf2::toMsg(v, m);
}

geometry_msgs::Point to_point(const Eigen::Vector3d& p) { return tf2::toMsg(p); }

CovarianceArray to_covariance(const Matrix6d& C) {
  CovarianceArray a;
  for (int i = 0; i < 36; ++i) a[i] = C(i / 6, i % 6);
  return a;
}

CovarianceArray unknown_covariance() {
  CovarianceArray a{};
  for (int i = 0; i < 6; ++i) a[i * 7] = 9999.0;
  return a;
}

}  // namespace hybrid_vo
