#pragma once

#include <string>
#include <vector>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/PoseWithCovariance.h>
#include <geometry_msgs/Transform.h>
#include <geometry_msgs/Vector3.h>
#include <hybrid_vo/FeatureLines.h>
#include <hybrid_vo/FeaturePoints.h>
#include <opencv2/core.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud.h>

#include "hybrid_vo/odometry/visual_odometry.h"

namespace hybrid_vo {

// camera_info to the front end's camera model. False with a reason when it cannot be used: zero
// or non-finite K, zero image size, non-finite coefficients, a distortion model other than
// plumb_bob / rational_polynomial with up to five coefficients (more are not supported) or
// equidistant with up to four, or equidistant coefficients that fold back inside the image.
bool camera_from_info(const sensor_msgs::CameraInfo& info, CameraModel* camera,
                      std::string* reason);

// camera_info's rectifying rotation R: identity when it is all zero (not set); false when it is
// not a finite rotation matrix.
bool rectification_from_info(const sensor_msgs::CameraInfo& info, Eigen::Matrix3d* R);

// Stereo baseline in metres from the right camera's projection matrix (P[3] = -fx * B). False
// when fx or Tx give no finite positive baseline.
bool baseline_from_info(const sensor_msgs::CameraInfo& right, double* baseline);

// An image as 8-bit grayscale (mono8, mono16, bgr8, rgb8, bgra8, rgba8). False with a reason for
// an empty image, another encoding, more than 65536 pixels a side, or a step and data size that
// do not fit the width, height and encoding.
bool gray_from_image(const sensor_msgs::ImageConstPtr& image, cv::Mat* gray, std::string* reason);

// Feature messages to external features (pixels). Mismatched array sizes are an error.
bool points_from_msg(const FeaturePoints& msg, ExternalFeatures* features, std::string* reason);
bool lines_from_msg(const FeatureLines& msg, ExternalFeatures* features, std::string* reason);

// The VINS-Mono / PL-VINS encodings (sensor_msgs/PointCloud with undistorted normalised
// coordinates): points carry channels [id, u, v, ...], lines a start point and channels
// [id, end x, end y], both normalised. Converted to undistorted pixels with the camera. Features
// with non-finite coordinates or an id that is not a finite integer are skipped.
bool points_from_vins(const sensor_msgs::PointCloud& msg, const PinholeCamera& camera,
                      ExternalFeatures* features, std::string* reason);
bool lines_from_vins(const sensor_msgs::PointCloud& msg, const PinholeCamera& camera,
                     ExternalFeatures* features, std::string* reason);

geometry_msgs::Transform to_transform(const Eigen::Matrix3d& R, const Eigen::Vector3d& t);
geometry_msgs::Vector3 to_vector(const Eigen::Vector3d& v);
geometry_msgs::Point to_point(const Eigen::Vector3d& p);

// A 6x6 covariance as a message's row-major array (the pose's and twist's of nav_msgs/Odometry).
using CovarianceArray = geometry_msgs::PoseWithCovariance::_covariance_type;
CovarianceArray to_covariance(const Matrix6d& C);
// What a lost track or an unknown twist reports, as viso2 does: 9999 on the diagonal.
CovarianceArray unknown_covariance();

}  // namespace hybrid_vo
