// What the node draws for rviz, only while someone subscribes: tracked VP directions and inlier
// segments in 3D as ~markers, and inlier points and segments coloured by VP as ~debug_image.
#include <algorithm>
#include <cmath>

#include <cv_bridge/cv_bridge.h>
#include <visualization_msgs/MarkerArray.h>

#include "hybrid_vo/features/visualization.h"
#include "hybrid_vo/node/conversions.h"
#include "hybrid_vo/node/vo_node.h"

namespace hybrid_vo {
namespace {

// The map's confirmed directions as world-fixed axes through the camera centre (odom frame):
// each a line both ways (a direction has no sign), in its debug image colour, thicker while the
// current frame sees it.
void add_map_axes(const DirectionMap& map, const std::vector<int>& seen,
                  const Eigen::Matrix3d& R_odom_world, const Eigen::Vector3d& centre,
                  const std_msgs::Header& header, visualization_msgs::MarkerArray* markers) {
  for (const MapDirection& d : map.directions()) {
    if (!d.confirmed) continue;
    visualization_msgs::Marker axis;
    axis.header = header;
    axis.ns = "vanishing_points";
    axis.id = d.id;
    axis.type = visualization_msgs::Marker::LINE_LIST;
    const bool visible = std::find(seen.begin(), seen.end(), d.id) != seen.end();
    axis.scale.x = visible ? 0.04 : 0.015;
    const cv::Scalar c = vp_colour(d.id);
    axis.color.b = c[0] / 255.0;
    axis.color.g = c[1] / 255.0;
    axis.color.r = c[2] / 255.0;
    axis.color.a = 1.0;
    axis.pose.orientation.w = 1.0;
    const Eigen::Vector3d u = R_odom_world * d.direction;
    axis.points = {to_point(centre - u), to_point(centre + u)};
    markers->markers.push_back(axis);
  }
}

}  // namespace

void VoNode::publish_markers(const ros::Time& stamp, const VisualOdometryInput& input,
                             const VisualOdometryResult& result) {
  std_msgs::Header header;
  header.stamp = stamp;
  header.frame_id = params_.odom_frame;
  visualization_msgs::MarkerArray markers;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  markers.markers.push_back(clear);
  const Eigen::Vector3d offset = have_base_transform_ ? t_base_camera_ : Eigen::Vector3d::Zero();
  add_map_axes(vo_->direction_map(), result.orientation.location.direction_id, R_odom_world(),
               R_odom_world() * result.centre + offset, header, &markers);
  // Inlier segments in 3D need the depth, so a metric motion.
  if (result.status == VoStatus::kOk && result.scale_known) {
    visualization_msgs::Marker lines = inlier_segments(input, result);
    lines.header = header;
    if (!lines.points.empty()) markers.markers.push_back(lines);
  }
  markers_pub_.publish(markers);
}

// Each current endpoint of an inlier segment back-projected onto the plane of the matched
// keyframe segment, in the odom frame.
visualization_msgs::Marker VoNode::inlier_segments(const VisualOdometryInput& input,
                                                   const VisualOdometryResult& result) const {
  visualization_msgs::Marker lines;
  lines.ns = "inlier_segments";
  lines.type = visualization_msgs::Marker::LINE_LIST;
  lines.scale.x = 0.02;
  lines.color.r = lines.color.g = 0.9;
  lines.color.b = 0.2;
  lines.color.a = 1.0;
  lines.pose.orientation.w = 1.0;
  const RelativePoseEstimate& est = result.estimate.estimate;
  const Eigen::Matrix3d& R = result.motion.R;
  const Eigen::Vector3d& t = result.motion.t;
  const PinholeCamera& cam = input.camera.pinhole;
  const Eigen::Vector3d offset = have_base_transform_ ? t_base_camera_ : Eigen::Vector3d::Zero();
  for (size_t i = 0; i < result.matches.lines.size() && i < est.line_inliers.size(); ++i) {
    if (!est.line_inliers[i]) continue;
    const LineMatch& m = result.matches.lines[i];
    const Eigen::Vector3d l1 = LineSegment(cam.normalize(m.s1.p1), cam.normalize(m.s1.p2)).line();
    const Eigen::Vector3d n = R * l1;
    Eigen::Vector3d ends[2];
    bool ok = true;
    for (int e = 0; e < 2 && ok; ++e) {
      const Eigen::Vector3d b = homogeneous(cam.normalize(e == 0 ? m.s2.p1 : m.s2.p2));
      const double mu = n.dot(t) / n.dot(b);
      ok = std::isfinite(mu) && mu > 0.2 && mu < 100.0;
      ends[e] = R_odom_world() * (result.R_wc * (mu * b) + result.centre) + offset;
    }
    if (!ok) continue;
    lines.points.push_back(to_point(ends[0]));
    lines.points.push_back(to_point(ends[1]));
  }
  return lines;
}

void VoNode::publish_debug_image(const Frame& frame, const VisualOdometryInput& input,
                                 const VisualOdometryResult& result) {
  const RelativePoseEstimate& est = result.estimate.estimate;
  std::vector<Eigen::Vector2d> points;
  for (size_t i = 0; i < result.matches.points.size() && i < est.point_inliers.size(); ++i)
    if (est.point_inliers[i]) points.push_back(result.matches.points[i].x2);
  std::vector<LineSegment> segments;
  std::vector<int> labels;
  for (size_t i = 0; i < result.matches.lines.size() && i < est.line_inliers.size(); ++i) {
    if (!est.line_inliers[i]) continue;
    segments.push_back(result.matches.lines[i].s2);
    labels.push_back(i < result.matches.line_vp.size() ? result.matches.line_vp[i] : -1);
  }
  std::vector<Eigen::Vector3d> directions;
  for (const VpMatch& v : result.matches.vps) directions.push_back(v.d2);
  const cv::Mat canvas =
      draw_view(input.image, points, segments, labels, directions, input.camera.pinhole);
  std_msgs::Header header;
  header.stamp = frame.stamp;
  header.frame_id = frame.frame_id;
  debug_image_pub_.publish(cv_bridge::CvImage(header, "bgr8", canvas).toImageMsg());
}

}  // namespace hybrid_vo
