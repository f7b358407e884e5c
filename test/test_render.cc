// The synthetic sequence renderer: determinism, geometry (depth, painted corners, motion and
// stereo consistent with the ground truth), image content that real detectors find (corners,
// long segments through the Manhattan VPs), the walk and the other motions (rest, turning in
// place, starting from rest), option checking, and the low-texture variant (plain surfaces: only
// edges, noise elsewhere, few trackable corners).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "hybrid_vo/features/fisheye_rectifier.h"
#include "hybrid_vo/render/sequence.h"

namespace {

using namespace hybrid_vo;
using namespace hybrid_vo::render;

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::infinity();
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::infinity();
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(q * v.size()));
  std::nth_element(v.begin(), v.begin() + k, v.end());
  return v[k];
}

// Pixel of a world point, or false when it is behind the camera or outside the image by margin.
bool project(const PinholeCamera& cam, const CameraPose& pose, const Eigen::Vector3d& X,
             double margin, Eigen::Vector2d* pixel, double* depth) {
  const Eigen::Vector3d Xc = pose.to_camera(X);
  if (Xc.z() < 0.1) return false;
  *pixel = Eigen::Vector2d(cam.fx * Xc.x() / Xc.z() + cam.cx, cam.fy * Xc.y() / Xc.z() + cam.cy);
  *depth = Xc.z();
  return pixel->x() >= margin && pixel->y() >= margin && pixel->x() <= cam.width - 1 - margin &&
         pixel->y() <= cam.height - 1 - margin;
}

Eigen::Vector3d back_project(const PinholeCamera& cam, const CameraPose& pose, double x, double y,
                             double depth) {
  return pose.to_world(Eigen::Vector3d((x - cam.cx) / cam.fx, (y - cam.cy) / cam.fy, 1.0) * depth);
}

float bilinear(const cv::Mat& image, double x, double y) {
  cv::Mat patch;
  cv::getRectSubPix(image, cv::Size(1, 1),
                    cv::Point2f(static_cast<float>(x), static_cast<float>(y)), patch, CV_32F);
  return patch.at<float>(0, 0);
}

// How far cornerSubPix, started 1.4 px off, ends from landmark lm's projection p, with a
// (2 half_window + 1)^2 window; NaN unless lm is visible (nothing in front, and its own quad all
// around it) and faces the camera obliquely enough that its corner is not a sliver.
double painted_corner_error(const Scene& scene, const RenderedView& view, const CameraPose& pose,
                            const Landmark& lm, const Eigen::Vector2d& p, int half_window) {
  const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
  for (int dy = -5; dy <= 5; ++dy)
    for (int dx = -5; dx <= 5; ++dx)
      if (view.quad_id.at<int>(y + dy, x + dx) != lm.quad) return kNaN;
  const Quad& q = scene.quads[lm.quad];
  if (q.normal.dot((pose.centre - lm.position).normalized()) < 0.5) return kNaN;
  std::vector<cv::Point2f> corner = {
      cv::Point2f(static_cast<float>(p.x() + 1.2), static_cast<float>(p.y() - 0.8))};
  cv::cornerSubPix(view.image, corner, cv::Size(half_window, half_window), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 40, 1e-3));
  return std::hypot(corner[0].x - p.x(), corner[0].y - p.y());
}

// The three Manhattan VPs (world axes) in homogeneous pixels.
std::array<Eigen::Vector3d, 3> manhattan_vps(const PinholeCamera& cam, const CameraPose& pose) {
  std::array<Eigen::Vector3d, 3> vps;
  for (int k = 0; k < 3; ++k)
    vps[k] = cam.K() * pose.R_world_from_camera.transpose() * Eigen::Vector3d::Unit(k);
  return vps;
}

// Angle in degrees between a segment and the line from its midpoint to a homogeneous VP.
double vp_angle_deg(const cv::Vec4f& s, const Eigen::Vector3d& vp) {
  const Eigen::Vector2d a(s[0], s[1]), b(s[2], s[3]), m = 0.5 * (a + b);
  const Eigen::Vector2d to_vp = vp.head<2>() - m * vp.z();
  const Eigen::Vector2d d = b - a;
  const double c = std::abs(d.dot(to_vp)) / (d.norm() * to_vp.norm() + 1e-300);
  return std::acos(std::min(1.0, c)) * 180.0 / kPi;
}

class RenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SequenceOptions options;
    options.out_bag = "unused.bag";
    options.frames = 120;
    options.stereo = true;
    sequence_ = new Sequence(make_sequence(options));
  }
  static void TearDownTestSuite() {
    delete sequence_;
    sequence_ = nullptr;
  }
  static const Sequence& seq() { return *sequence_; }
  static Sequence* sequence_;
};

Sequence* RenderTest::sequence_ = nullptr;

TEST_F(RenderTest, RenderingIsDeterministic) {
  const RenderedView a = render_frame(seq(), 5);
  const RenderedView b = render_frame(seq(), 5);
  EXPECT_EQ(cv::norm(a.image, b.image, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.depth, b.depth, cv::NORM_INF), 0.0);
  // A second scene from the same seed is identical; another seed gives another scene.
  SequenceOptions options = seq().options;
  options.frames = 6;
  const Sequence again = make_sequence(options);
  EXPECT_EQ(cv::norm(render_frame(again, 5).image, a.image, cv::NORM_INF), 0.0);
  options.seed = 2;
  const Sequence other = make_sequence(options);
  EXPECT_GT(cv::norm(render_frame(other, 5).image, a.image, cv::NORM_L1) / a.image.total(), 5.0);
  // The noise differs between frames and cameras, not the picture.
  const RenderedView right = render_frame(seq(), 5, true);
  EXPECT_GT(cv::norm(right.image, a.image, cv::NORM_INF), 0.0);
}

TEST_F(RenderTest, SceneIsClosedAndManhattan) {
  const Scene& scene = seq().scene;
  int walls = 0;
  for (const Quad& q : scene.quads) {
    for (const Eigen::Vector3d& axis : {q.u_axis, q.v_axis, q.normal}) {
      EXPECT_NEAR(axis.norm(), 1.0, 1e-12);
      EXPECT_NEAR(axis.cwiseAbs().maxCoeff(), 1.0, 1e-12);  // a signed world axis
    }
    EXPECT_LT((q.v_axis.cross(q.u_axis) - q.normal).norm(), 1e-12);
    EXPECT_FALSE(q.texture.levels.empty());
    walls += q.kind == SurfaceKind::kWall;
  }
  EXPECT_EQ(walls, 8);  // the ring corridor: four outer and four inner walls
  EXPECT_GE(scene.landmarks.size(), 30u);
  // Every pixel of every tested view sees a surface: no holes in the geometry.
  for (int frame : {0, 30, 60, 100}) {
    const RenderedView view = render_frame(seq(), frame);
    EXPECT_EQ(cv::countNonZero(view.quad_id < 0), 0) << "frame " << frame;
    double min_depth = 0.0;
    cv::minMaxLoc(view.depth, &min_depth);
    EXPECT_GT(min_depth, 0.3) << "frame " << frame;
  }
}

TEST_F(RenderTest, DepthBufferMatchesGeometry) {
  const PinholeCamera& cam = seq().camera;
  std::mt19937 rng(3);
  for (int frame : {10, 40}) {
    const CameraPose& pose = seq().trajectory.poses[frame];
    const RenderedView view = render_frame(seq(), frame);
    // Back-projected pixels lie on the plane and inside the extent of the quad they show.
    for (int n = 0; n < 3000; ++n) {
      const int x = static_cast<int>(rng() % cam.width), y = static_cast<int>(rng() % cam.height);
      const int id = view.quad_id.at<int>(y, x);
      ASSERT_GE(id, 0);
      const Quad& q = seq().scene.quads[id];
      const Eigen::Vector3d X = back_project(cam, pose, x, y, view.depth.at<float>(y, x));
      const Eigen::Vector2d uv = q.local(X);
      const double tol = 1e-5 * view.depth.at<float>(y, x) + 1e-6;
      ASSERT_NEAR(q.normal.dot(X - q.origin), 0.0, tol);
      ASSERT_GT(uv.x(), -tol);
      ASSERT_GT(uv.y(), -tol);
      ASSERT_LT(uv.x(), q.size_u + tol);
      ASSERT_LT(uv.y(), q.size_v + tol);
    }
    // Independently: random points on the quads, projected; where the pixel centre's ray
    // meets the same quad, the renderer must show it or something nearer, never farther.
    int checked = 0, seen = 0;
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int n = 0; n < 50000; ++n) {
      const int id = static_cast<int>(rng() % seq().scene.quads.size());
      const Quad& q = seq().scene.quads[id];
      if (q.normal.dot(pose.centre - q.origin) <= 0.0) continue;  // seen from behind
      const Eigen::Vector3d P = q.point(unit(rng) * q.size_u, unit(rng) * q.size_v);
      Eigen::Vector2d p;
      double z = 0.0;
      if (!project(cam, pose, P, 0.0, &p, &z)) continue;
      const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
      const Eigen::Vector3d ray = back_project(cam, pose, x, y, 1.0) - pose.centre;
      const double t = q.normal.dot(q.origin - pose.centre) / q.normal.dot(ray);
      const Eigen::Vector2d uv = q.local(pose.centre + t * ray);
      if (uv.x() < 1e-3 || uv.y() < 1e-3 || uv.x() > q.size_u - 1e-3 || uv.y() > q.size_v - 1e-3)
        continue;
      ++checked;
      const double rendered = view.depth.at<float>(y, x);
      EXPECT_LT(rendered, t * (1.0 + 1e-5)) << "quad " << id << " hidden behind a farther one";
      if (view.quad_id.at<int>(y, x) == id) {
        ++seen;
        EXPECT_NEAR(rendered, t, 1e-5 * t);
      }
    }
    EXPECT_GT(checked, 1000);
    EXPECT_GT(seen, 300);
    // cast_ray through pixel centres finds what the renderer shows there, at its depth.
    for (int n = 0; n < 500; ++n) {
      const int x = static_cast<int>(rng() % cam.width), y = static_cast<int>(rng() % cam.height);
      double t = 0.0;
      const int id = cast_ray(seq().scene, pose.centre,
                              back_project(cam, pose, x, y, 1.0) - pose.centre, &t);
      EXPECT_EQ(id, view.quad_id.at<int>(y, x));
      EXPECT_NEAR(t, view.depth.at<float>(y, x), 1e-5 * t);
    }
  }
}

// The painted corners (door frames, posters, windows, boards) are image corners exactly where
// the pose projects them: this checks the texture mapping, not only the depth.
TEST_F(RenderTest, PaintedCornersProjectWhereExpected) {
  const PinholeCamera& cam = seq().camera;
  std::vector<double> errors;
  for (int frame = 0; frame < 120; frame += 8) {
    const CameraPose& pose = seq().trajectory.poses[frame];
    const RenderedView view = render_frame(seq(), frame);
    for (const Landmark& lm : seq().scene.landmarks) {
      Eigen::Vector2d p;
      double z = 0.0;
      if (!project(cam, pose, lm.position, 12.0, &p, &z) || z > 5.0) continue;
      const double error = painted_corner_error(seq().scene, view, pose, lm, p, 3);
      if (std::isfinite(error)) errors.push_back(error);
    }
  }
  ASSERT_GE(errors.size(), 40u);
  EXPECT_LT(median(errors), 0.35);
  EXPECT_LT(quantile(errors, 0.8), 0.6);
  RecordProperty("painted_corners", static_cast<int>(errors.size()));
}

// Consecutive frames are related by the ground-truth motion: warping frame i into frame i + 1
// with the depth and the poses leaves only noise, and KLT tracks move where the motion says.
TEST_F(RenderTest, ConsecutiveFramesAgreeWithGroundTruthMotion) {
  const PinholeCamera& cam = seq().camera;
  for (int frame : {8, 22, 29}) {  // straight, entering the first turn, at its fastest
    const CameraPose& pose1 = seq().trajectory.poses[frame];
    const CameraPose& pose2 = seq().trajectory.poses[frame + 1];
    const RenderedView v1 = render_frame(seq(), frame), v2 = render_frame(seq(), frame + 1);
    auto predict = [&](double x, double y, Eigen::Vector2d* p2) {
      const Eigen::Vector3d X = back_project(cam, pose1, x, y, bilinear(v1.depth, x, y));
      double z2 = 0.0;
      if (!project(cam, pose2, X, 2.0, p2, &z2)) return false;
      // Not occluded in frame 2, and not on a depth edge in frame 1.
      const float d2 = v2.depth.at<float>(static_cast<int>(std::lround(p2->y())),
                                          static_cast<int>(std::lround(p2->x())));
      const int xi = static_cast<int>(std::lround(x)), yi = static_cast<int>(std::lround(y));
      const int id = v1.quad_id.at<int>(yi, xi);
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
          const int yy = std::clamp(yi + dy, 0, cam.height - 1);
          const int xx = std::clamp(xi + dx, 0, cam.width - 1);
          if (v1.quad_id.at<int>(yy, xx) != id) return false;
        }
      return std::abs(d2 - z2) < 0.01 * z2;
    };
    std::vector<double> warped, unwarped;
    for (int y = 4; y < cam.height - 4; y += 4)
      for (int x = 4; x < cam.width - 4; x += 4) {
        Eigen::Vector2d p2;
        if (!predict(x, y, &p2)) continue;
        const double i1 = v1.image.at<uchar>(y, x);
        warped.push_back(std::abs(i1 - bilinear(v2.image, p2.x(), p2.y())));
        unwarped.push_back(std::abs(i1 - v2.image.at<uchar>(y, x)));
      }
    ASSERT_GT(warped.size(), 8000u) << "frame " << frame;
    EXPECT_LT(median(warped), 2.0) << "frame " << frame;
    EXPECT_LT(quantile(warped, 0.9), 6.0) << "frame " << frame;
    EXPECT_GT(quantile(unwarped, 0.9), 3.0 * quantile(warped, 0.9)) << "frame " << frame;

    std::vector<cv::Point2f> corners, tracked;
    cv::goodFeaturesToTrack(v1.image, corners, 500, 0.01, 8);
    std::vector<uchar> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(v1.image, v2.image, corners, tracked, status, error, cv::Size(21, 21),
                             3);
    std::vector<double> klt;
    for (size_t k = 0; k < corners.size(); ++k) {
      Eigen::Vector2d p2;
      if (!status[k] || !predict(corners[k].x, corners[k].y, &p2)) continue;
      klt.push_back(std::hypot(tracked[k].x - p2.x(), tracked[k].y - p2.y()));
    }
    ASSERT_GT(klt.size(), 100u) << "frame " << frame;
    EXPECT_LT(median(klt), 0.3) << "frame " << frame;
    EXPECT_LT(quantile(klt, 0.9), 1.5) << "frame " << frame;
  }
}

// What the VO front end needs: hundreds of corners that repeat where the motion takes them
// (aliasing would make corners that do not), and dozens of long segments, nearly all through
// the three Manhattan VPs predicted from the pose.
TEST_F(RenderTest, ImagesHaveRepeatableCornersAndManhattanSegments) {
  const PinholeCamera& cam = seq().camera;
  cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector();
  std::array<int, 3> total_per_vp = {0, 0, 0};
  for (int frame : {0, 20, 30, 60, 90}) {
    const CameraPose& pose = seq().trajectory.poses[frame];
    const RenderedView view = render_frame(seq(), frame);
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(view.image, corners, 3000, 0.01, 5);
    EXPECT_GE(corners.size(), 300u) << "frame " << frame;

    // Repeatability in the next frame.
    const RenderedView next = render_frame(seq(), frame + 1);
    const CameraPose& pose2 = seq().trajectory.poses[frame + 1];
    std::vector<cv::Point2f> corners2;
    cv::goodFeaturesToTrack(next.image, corners2, 3000, 0.01, 5);
    int predicted = 0, repeated = 0;
    for (const cv::Point2f& c : corners) {
      const float z = view.depth.at<float>(static_cast<int>(std::lround(c.y)),
                                           static_cast<int>(std::lround(c.x)));
      Eigen::Vector2d p2;
      double z2 = 0.0;
      if (!project(cam, pose2, back_project(cam, pose, c.x, c.y, z), 8.0, &p2, &z2)) continue;
      const float d2 = next.depth.at<float>(static_cast<int>(std::lround(p2.y())),
                                            static_cast<int>(std::lround(p2.x())));
      if (std::abs(d2 - z2) > 0.01 * z2) continue;
      ++predicted;
      for (const cv::Point2f& c2 : corners2)
        if (std::hypot(c2.x - p2.x(), c2.y - p2.y()) < 1.5) {
          ++repeated;
          break;
        }
    }
    ASSERT_GT(predicted, 150) << "frame " << frame;
    EXPECT_GT(static_cast<double>(repeated) / predicted, 0.6) << "frame " << frame;

    std::vector<cv::Vec4f> segments;
    lsd->detect(view.image, segments);
    const auto vps = manhattan_vps(cam, pose);
    int long_segments = 0, manhattan = 0;
    std::array<int, 3> per_vp = {0, 0, 0};
    for (const cv::Vec4f& s : segments) {
      if (std::hypot(s[2] - s[0], s[3] - s[1]) < 40.0) continue;
      ++long_segments;
      int best = 0;
      double best_angle = 180.0;
      for (int k = 0; k < 3; ++k) {
        const double a = vp_angle_deg(s, vps[k]);
        if (a < best_angle) best_angle = a, best = k;
      }
      if (best_angle < 2.0) {
        ++manhattan;
        ++per_vp[best];
      }
    }
    EXPECT_GE(long_segments, 30) << "frame " << frame;
    EXPECT_GE(manhattan, 0.9 * long_segments) << "frame " << frame;
    // Facing a wall, the direction towards it has few segments; the other two are always there.
    EXPECT_GE(std::count_if(per_vp.begin(), per_vp.end(), [](int n) { return n >= 5; }), 2)
        << "frame " << frame;
    for (int k = 0; k < 3; ++k) total_per_vp[k] += per_vp[k];
  }
  for (int k = 0; k < 3; ++k) EXPECT_GE(total_per_vp[k], 20) << "VP " << k;
}

// Antialiasing: the default 3 x 3 rays per pixel are close to a 8 x 8 reference, at the edges
// (where a single ray per pixel gives staircases) and on distant textures.
TEST_F(RenderTest, SupersamplingConvergesToTheReference) {
  RenderOptions options = seq().render;
  options.noise_sigma = 0.0;
  const CameraPose& pose = seq().trajectory.poses[30];
  options.supersampling = 8;
  const cv::Mat reference = render_view(seq().scene, seq().camera, pose, options).image;
  auto error = [&](int ss, double* mean, double* q999) {
    options.supersampling = ss;
    cv::Mat diff;
    cv::absdiff(render_view(seq().scene, seq().camera, pose, options).image, reference, diff);
    *mean = cv::mean(diff)[0];
    *q999 = quantile(std::vector<double>(diff.begin<uchar>(), diff.end<uchar>()), 0.999);
  };
  double mean3 = 0.0, q999_3 = 0.0, mean1 = 0.0, q999_1 = 0.0;
  error(3, &mean3, &q999_3);
  error(1, &mean1, &q999_1);
  EXPECT_LT(mean3, 0.1);
  EXPECT_LE(q999_3, 5.0);
  EXPECT_GT(q999_1, 2.0 * q999_3);  // one ray per pixel is visibly worse: the test can tell
}

TEST_F(RenderTest, RightCameraIsLeftShiftedByTheBaseline) {
  const PinholeCamera& cam = seq().camera;
  const double B = seq().options.baseline;
  for (int frame : {15, 45}) {
    const CameraPose left = frame_pose(seq(), frame), right = frame_pose(seq(), frame, true);
    EXPECT_LT((right.R_world_from_camera - left.R_world_from_camera).norm(), 1e-15);
    EXPECT_LT((left.to_camera(right.centre) - Eigen::Vector3d(B, 0, 0)).norm(), 1e-12);
    const RenderedView l = render_frame(seq(), frame), r = render_frame(seq(), frame, true);
    std::vector<double> shifted, unshifted;
    for (int y = 4; y < cam.height - 4; y += 3)
      for (int x = 4; x < cam.width - 4; x += 3) {
        const double z = l.depth.at<float>(y, x);
        const double xr = x - cam.fx * B / z;  // rectified: same row, disparity f B / z
        if (xr < 2.0) continue;
        const float zr = r.depth.at<float>(y, static_cast<int>(std::lround(xr)));
        if (std::abs(zr - z) > 0.01 * z) continue;  // occluded in the right view
        const int id = l.quad_id.at<int>(y, x);
        if (l.quad_id.at<int>(y, x - 2) != id || l.quad_id.at<int>(y, x + 2) != id) continue;
        const double i = l.image.at<uchar>(y, x);
        shifted.push_back(std::abs(i - bilinear(r.image, xr, y)));
        unshifted.push_back(std::abs(i - r.image.at<uchar>(y, x)));
      }
    ASSERT_GT(shifted.size(), 10000u);
    EXPECT_LT(median(shifted), 2.0) << "frame " << frame;
    EXPECT_LT(quantile(shifted, 0.9), 5.0) << "frame " << frame;
    EXPECT_GT(quantile(unshifted, 0.9), 2.0 * quantile(shifted, 0.9)) << "frame " << frame;
  }
}

TEST_F(RenderTest, WalkTurnsAndStaysInside) {
  const Trajectory& traj = seq().trajectory;
  ASSERT_EQ(traj.poses.size(), 120u);
  double min_heading = 0.0, max_heading = 0.0, heading = 0.0, previous = 0.0;
  for (size_t i = 0; i < traj.poses.size(); ++i) {
    const CameraPose& pose = traj.poses[i];
    const Eigen::Matrix3d& R = pose.R_world_from_camera;
    EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    EXPECT_TRUE(seq().scene.is_free(pose.centre, 0.5)) << "frame " << i;
    const Eigen::Vector3d forward = R.col(2);
    EXPECT_LT(std::abs(forward.z()), std::sin(10.0 * kPi / 180.0));  // roughly level
    EXPECT_GT(R.col(1).z(), -1.0);
    EXPECT_LT(R.col(1).z(), -0.95);  // image y points down
    const double h = std::atan2(forward.y(), forward.x());
    if (i > 0) {
      heading += std::remainder(h - previous, 2.0 * kPi);
      const double step = (pose.centre - traj.poses[i - 1].centre).norm();
      EXPECT_NEAR(step, 0.15, 0.03) << "frame " << i;
    }
    previous = h;
    min_heading = std::min(min_heading, heading);
    max_heading = std::max(max_heading, heading);
  }
  EXPECT_GT((max_heading - min_heading) * 180.0 / kPi, 150.0);  // two left turns
  EXPECT_NEAR(traj.total_turn_deg, 180.0, 5.0);
  EXPECT_NEAR(traj.length, 119 * 0.15, 0.5);

  // The room: a loop around the pillar, inside the walls too.
  SceneOptions room;
  room.type = SceneType::kRoom;
  const Scene scene = build_scene(room);
  PathOptions path;
  path.num_frames = 200;
  const Trajectory walk = make_trajectory(scene, path);
  for (const CameraPose& pose : walk.poses) EXPECT_TRUE(scene.is_free(pose.centre, 0.5));
  EXPECT_GT(walk.total_turn_deg, 45.0);
}

// ------------------------------------------------------------------------------------------------
// The other motions (--motion rest|turn|ramp) and the walk they must leave as it was.

Scene motion_scene(SceneType type) {
  SceneOptions o;
  o.type = type;
  o.texels_per_metre = 64;  // the route and the free space do not depend on the textures
  return build_scene(o);
}

Trajectory motion_path(const Scene& scene, Motion motion, int frames, double rate = 10.0) {
  PathOptions o;
  o.motion = motion;
  o.num_frames = frames;
  o.rate_hz = rate;
  return make_trajectory(scene, o);
}

Eigen::Vector3d level(Eigen::Vector3d v) {
  v.z() = 0.0;
  return v;
}

TEST(CameraMotion, WalkIsUnchanged) {
  const Scene scene = motion_scene(SceneType::kCorridor);
  const Trajectory walk = motion_path(scene, Motion::kWalk, 150);
  const Trajectory by_default = make_trajectory(scene, PathOptions{});
  ASSERT_EQ(walk.poses.size(), by_default.poses.size());
  for (size_t i = 0; i < walk.poses.size(); ++i) {
    EXPECT_EQ(walk.poses[i].R_world_from_camera, by_default.poses[i].R_world_from_camera);
    EXPECT_EQ(walk.poses[i].centre, by_default.poses[i].centre);
  }
  // Frame 37 (in the first turn) as the renderer wrote it before the motions existed.
  Eigen::Matrix<double, 3, 4, Eigen::RowMajor> before;
  before << 9.880643992795e-01, -8.020739539813e-04, 1.540392792562e-01, 1.670149008850e+01,
      -1.537588677823e-01, -6.566940251016e-02, 9.859238003782e-01, 2.779203673205e+00,
      9.324883630960e-03, -9.978411127285e-01, -6.500892472529e-02, 1.440348836809e+00;
  EXPECT_LT((walk.poses[37].R_world_from_camera - before.leftCols<3>()).norm(), 1e-11);
  EXPECT_LT((walk.poses[37].centre - before.col(3)).norm(), 1e-10);
}

TEST(CameraMotion, RestStandsStillAtTheRoutesStart) {
  for (SceneType type : {SceneType::kCorridor, SceneType::kRoom}) {
    const Scene scene = motion_scene(type);
    const Trajectory rest = motion_path(scene, Motion::kRest, 40);
    PathOptions still;
    still.sway = false;
    const CameraPose start = make_trajectory(scene, still).poses[0];
    ASSERT_EQ(rest.poses.size(), 40u);
    for (const CameraPose& pose : rest.poses) {
      EXPECT_EQ(pose.R_world_from_camera, start.R_world_from_camera);
      EXPECT_EQ(pose.centre, start.centre);
    }
    EXPECT_EQ(rest.length, 0.0);
    EXPECT_EQ(rest.total_turn_deg, 0.0);
    EXPECT_NEAR(rest.times.back(), 3.9, 1e-12);
  }
}

TEST(CameraMotion, TurnIsAboutAVerticalAxisBehindTheCamera) {
  constexpr double kRate = 30.0;
  for (SceneType type : {SceneType::kCorridor, SceneType::kRoom})
    for (double lever_arm : {0.2, 0.0, 0.35}) {
      const Scene scene = motion_scene(type);
      PathOptions o;
      o.motion = Motion::kTurn;
      o.lever_arm = lever_arm;
      o.num_frames = 451;  // 15 s: 435 degrees, once round and more
      o.rate_hz = kRate;
      const Trajectory turn = make_trajectory(scene, o);
      const CameraPose& first = turn.poses[0];
      const Eigen::Vector3d pivot =
          first.centre - lever_arm * level(first.R_world_from_camera.col(2)).normalized();
      double yaw = 0.0, max_rate = 0.0;
      for (size_t i = 0; i < turn.poses.size(); ++i) {
        const CameraPose& pose = turn.poses[i];
        const Eigen::Vector3d arm = pose.centre - pivot;
        EXPECT_NEAR(arm.z(), 0.0, 1e-12);
        EXPECT_NEAR(arm.norm(), lever_arm, 1e-12) << "frame " << i;
        // The camera looks away from the axis: the arm is its level forward direction.
        if (lever_arm > 0.0) {
          EXPECT_LT((arm.normalized() - level(pose.R_world_from_camera.col(2)).normalized()).norm(),
                    1e-9);
        }
        if (i == 0) continue;
        const Eigen::AngleAxisd step(pose.R_world_from_camera *
                                     turn.poses[i - 1].R_world_from_camera.transpose());
        if (step.angle() > 1e-9) {
          EXPECT_NEAR(step.axis().z(), 1.0, 1e-9) << "frame " << i;
        }
        const double rate_deg = step.angle() * kRate * 180.0 / kPi;
        EXPECT_GE(rate_deg, max_rate - 1e-6) << "frame " << i;  // rises, then holds
        max_rate = std::max(max_rate, rate_deg);
        if (i <= 30) {
          EXPECT_LT(rate_deg, 30.0 + 1e-6);
        } else if (i > 31) {
          EXPECT_NEAR(rate_deg, 30.0, 1e-6) << "frame " << i;
        }
        yaw += step.angle();
      }
      EXPECT_LT(turn.poses[1].R_world_from_camera.col(2).dot(first.R_world_from_camera.col(2)),
                1.0);
      EXPECT_NEAR(yaw * 180.0 / kPi, 30.0 * (15.0 - 0.5), 1e-6);
      EXPECT_NEAR(turn.total_turn_deg, 435.0, 1e-6);
      EXPECT_NEAR(turn.length, 2.0 * kPi * lever_arm * 435.0 / 360.0, 1e-3);
    }
}

TEST(CameraMotion, TurnStopsAndTurnsRight) {
  const Scene scene = motion_scene(SceneType::kCorridor);
  PathOptions o;
  o.motion = Motion::kTurn;
  o.num_frames = 61;
  o.turn_stop = true;
  o.turn_rate_deg = -45.0;
  const Trajectory turn = make_trajectory(scene, o);
  auto step = [&](int i) {
    return Eigen::AngleAxisd(turn.poses[i].R_world_from_camera *
                             turn.poses[i - 1].R_world_from_camera.transpose());
  };
  EXPECT_NEAR(step(30).axis().z(), -1.0, 1e-9);  // negative: to the right
  EXPECT_NEAR(step(30).angle() * 10.0 * 180.0 / kPi, 45.0, 1e-6);
  EXPECT_LT(step(60).angle() * 10.0 * 180.0 / kPi, 45.0 * 0.03);  // ramped down
  EXPECT_NEAR(turn.total_turn_deg, 45.0 * (6.0 - 1.0), 1e-6);
  o.num_frames = 15;  // 1.4 s: no room for the two ramps
  EXPECT_THROW(make_trajectory(scene, o), std::invalid_argument);
}

TEST(CameraMotion, RampRestsThenReachesTheWalk) {
  const Scene scene = motion_scene(SceneType::kCorridor);
  PathOptions o;
  o.motion = Motion::kRamp;
  o.num_frames = 80;
  const Trajectory ramp = make_trajectory(scene, o);
  for (int i = 1; i <= 10; ++i) {  // 1 s at rest
    EXPECT_EQ(ramp.poses[i].centre, ramp.poses[0].centre);
    EXPECT_EQ(ramp.poses[i].R_world_from_camera, ramp.poses[0].R_world_from_camera);
  }
  EXPECT_GT((ramp.poses[11].centre - ramp.poses[10].centre).norm(), 0.0);
  // After the ramp, the walk delayed by the rest and half the ramp, sway and all.
  PathOptions walk;
  walk.start = -1.5 * (1.0 + 1.0);
  walk.num_frames = 80;
  const Trajectory delayed = make_trajectory(scene, walk);
  for (int i = 30; i < 80; ++i) {
    EXPECT_LT((ramp.poses[i].centre - delayed.poses[i].centre).norm(), 1e-9) << "frame " << i;
    EXPECT_LT((ramp.poses[i].R_world_from_camera - delayed.poses[i].R_world_from_camera).norm(),
              1e-9);
  }
  // Without the sway the speed rises smoothly from 0 to 1.5 m/s.
  o.sway = false;
  const Trajectory smooth = make_trajectory(scene, o);
  double previous = 0.0;
  for (int i = 11; i < 40; ++i) {
    const double speed = (smooth.poses[i].centre - smooth.poses[i - 1].centre).norm() * 10.0;
    EXPECT_GE(speed, previous - 1e-9) << "frame " << i;
    EXPECT_LT(speed - previous, 0.2) << "frame " << i;  // no jump
    previous = speed;
  }
  EXPECT_NEAR(previous, 1.5, 1e-3);
}

// Hand-held (issue 53): a stroll at 0.09 m/s from the command line, looking around at up to
// about 9-15 deg/s with a shake, smooth frame to frame at 30 Hz, inside the room.
TEST(CameraMotion, HandheldStrollsSlowlyAndLooksAround) {
  SequenceOptions options;
  ASSERT_EQ(parse_sequence_args({"--kitti-dir", "x", "--scene", "room", "--motion", "handheld",
                                 "--rate", "30", "--frames", "300"},
                                &options),
            "");
  EXPECT_EQ(options.motion, Motion::kHandheld);
  EXPECT_DOUBLE_EQ(options.speed, 0.09);
  const Scene scene = motion_scene(SceneType::kRoom);
  PathOptions o;
  o.motion = Motion::kHandheld;
  o.rate_hz = 30.0;
  o.num_frames = 300;
  o.speed = 0.09;
  const Trajectory hand = make_trajectory(scene, o);
  double path = 0.0, peak_rate = 0.0, turned = 0.0, peak_step = 0.0;
  for (int i = 1; i < 300; ++i) {
    const double step = (hand.poses[i].centre - hand.poses[i - 1].centre).norm();
    const double angle = Eigen::AngleAxisd(hand.poses[i].R_world_from_camera.transpose() *
                                           hand.poses[i - 1].R_world_from_camera)
                             .angle() * 180.0 / kPi;
    path += step;
    turned += angle;
    peak_step = std::max(peak_step, step);
    peak_rate = std::max(peak_rate, angle * 30.0);
  }
  // 10 s: 0.9 m along the route, plus the hand's drift; it turns, but slowly.
  EXPECT_GT(path, 0.9);
  EXPECT_LT(path, 2.0);
  EXPECT_LT(peak_step, 0.02);
  EXPECT_GT(peak_rate, 5.0);
  EXPECT_LT(peak_rate, 25.0);
  EXPECT_GT(turned, 40.0);
  // Repeatable, and the seed sets the swings' phases.
  const Trajectory again = make_trajectory(scene, o);
  EXPECT_EQ(again.poses[123].centre, hand.poses[123].centre);  // repeatable
  o.seed = 2;
  EXPECT_NE(make_trajectory(scene, o).poses[123].centre, hand.poses[123].centre);
}

TEST(CameraMotion, EveryMotionIsRenderedInStereo) {
  for (const char* motion : {"walk", "rest", "turn", "ramp", "handheld"}) {
    std::vector<std::string> args = {"--out",  "x.bag", "--stereo", "--motion", motion,
                                     "--frames", "12", "--width", "64", "--height",
                                     "48",     "--scene", "room"};
    if (std::string(motion) == "ramp") args.insert(args.end(), {"--rest-seconds", "0.2"});
    SequenceOptions options;
    ASSERT_EQ(parse_sequence_args(args, &options), "");
    const Sequence seq = make_sequence(options);
    ASSERT_EQ(seq.trajectory.poses.size(), 12u);
    for (int frame : {0, 11}) {
      const CameraPose left = frame_pose(seq, frame), right = frame_pose(seq, frame, true);
      EXPECT_LT((left.to_camera(right.centre) - Eigen::Vector3d(0.12, 0, 0)).norm(), 1e-12);
      EXPECT_EQ(right.R_world_from_camera, left.R_world_from_camera);
    }
    const RenderedView a = render_frame(seq, 0), b = render_frame(seq, 11);
    const RenderedView r = render_frame(seq, 11, true);
    EXPECT_EQ(a.image.size(), cv::Size(64, 48));
    EXPECT_EQ(r.image.size(), cv::Size(64, 48));
    const double change = cv::norm(a.image, b.image, cv::NORM_L1) / a.image.total();
    if (std::string(motion) == "rest") {  // the noise alone: 1 grey level, about 1.1 apart
      EXPECT_LT(change, 2.0) << motion;
    } else {
      EXPECT_GT(change, 2.0) << motion;
    }
  }
}

// ------------------------------------------------------------------------------------------------
// The low-texture variant (--texture plain): the same corridor and walk with plain surfaces.

class PlainRenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SequenceOptions options;
    options.out_bag = "unused.bag";
    options.frames = 60;
    options.texture = TextureStyle::kPlain;
    plain_ = new Sequence(make_sequence(options));
    options.texture = TextureStyle::kTextured;
    textured_ = new Sequence(make_sequence(options));
  }
  static void TearDownTestSuite() {
    delete plain_;
    delete textured_;
    plain_ = textured_ = nullptr;
  }
  static const Sequence& plain() { return *plain_; }
  static const Sequence& textured() { return *textured_; }
  static Sequence* plain_;
  static Sequence* textured_;
};

Sequence* PlainRenderTest::plain_ = nullptr;
Sequence* PlainRenderTest::textured_ = nullptr;

// The albedo (level-0 texel, 0..255) each pixel centre sees, from the depth and quad buffers.
cv::Mat albedo_image(const Sequence& seq, const CameraPose& pose, const RenderedView& view) {
  cv::Mat albedo(view.image.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < albedo.rows; ++y)
    for (int x = 0; x < albedo.cols; ++x) {
      const int id = view.quad_id.at<int>(y, x);
      if (id < 0) continue;
      const Quad& q = seq.scene.quads[id];
      const cv::Mat& texels = q.texture.levels[0];
      const Eigen::Vector2d uv =
          q.local(back_project(seq.camera, pose, x, y, view.depth.at<float>(y, x)));
      const double tpm = q.texture.texels_per_metre;
      const int c = std::clamp(static_cast<int>(std::floor(uv.x() * tpm)), 0, texels.cols - 1);
      const int r = std::clamp(static_cast<int>(std::floor(uv.y() * tpm)), 0, texels.rows - 1);
      albedo.at<uchar>(y, x) = texels.at<uchar>(r, c);
    }
  return albedo;
}

// Pixels within `radius` of an edge: where the surface (quad) or its albedo changes.
cv::Mat edge_mask(const RenderedView& view, const cv::Mat& albedo, int radius) {
  cv::Mat edges(view.image.size(), CV_8UC1, cv::Scalar(0));
  for (int y = 0; y + 1 < edges.rows; ++y)
    for (int x = 0; x + 1 < edges.cols; ++x) {
      const int id = view.quad_id.at<int>(y, x);
      const uchar a = albedo.at<uchar>(y, x);
      if (view.quad_id.at<int>(y, x + 1) != id || view.quad_id.at<int>(y + 1, x) != id ||
          albedo.at<uchar>(y, x + 1) != a || albedo.at<uchar>(y + 1, x) != a)
        edges.at<uchar>(y, x) = 255;
    }
  cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_RECT,
                                                     cv::Size(2 * radius + 1, 2 * radius + 1)));
  return edges;
}

// Gradient magnitude in grey levels per pixel (Sobel / 8).
cv::Mat gradient(const cv::Mat& image) {
  cv::Mat gx, gy, magnitude;
  cv::Sobel(image, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
  cv::Sobel(image, gy, CV_32F, 0, 1, 3, 1.0 / 8.0);
  cv::magnitude(gx, gy, magnitude);
  return magnitude;
}

std::vector<double> values_where(const cv::Mat& values, const cv::Mat& mask) {
  std::vector<double> out;
  for (int y = 2; y < values.rows - 2; ++y)
    for (int x = 2; x < values.cols - 2; ++x)
      if (mask.at<uchar>(y, x)) out.push_back(values.at<float>(y, x));
  return out;
}

// Every texture is a few plain areas: almost no texel differs from its neighbours (the door
// frames, floor joints and light panels are the exceptions), where the textured scene's differ
// nearly everywhere.
TEST_F(PlainRenderTest, SurfacesHaveNoTexture) {
  auto changing_texels = [](const Scene& scene, SurfaceKind kind) {
    double changing = 0.0, total = 0.0;
    for (const Quad& q : scene.quads) {
      if (q.kind != kind) continue;
      const cv::Mat& t = q.texture.levels[0];
      cv::Mat dx, dy;
      cv::absdiff(t.colRange(1, t.cols), t.colRange(0, t.cols - 1), dx);
      cv::absdiff(t.rowRange(1, t.rows), t.rowRange(0, t.rows - 1), dy);
      changing += cv::countNonZero(dx) + cv::countNonZero(dy);
      total += dx.total() + dy.total();
    }
    return changing / total;
  };
  for (const SurfaceKind kind :
       {SurfaceKind::kFloor, SurfaceKind::kCeiling, SurfaceKind::kWall, SurfaceKind::kFurniture}) {
    const double plain_fraction = changing_texels(plain().scene, kind);
    const double textured_fraction = changing_texels(textured().scene, kind);
    EXPECT_LT(plain_fraction, 0.005) << "kind " << static_cast<int>(kind);
    EXPECT_GT(textured_fraction, 0.3) << "kind " << static_cast<int>(kind);
  }
}

// The same corridor, lights, boxes and walk as the textured scene of the seed: only the
// surfaces' look differs.
TEST_F(PlainRenderTest, GeometryAndWalkAreTheTexturedScenes) {
  const Scene& a = plain().scene;
  const Scene& b = textured().scene;
  ASSERT_EQ(a.quads.size(), b.quads.size());
  for (size_t i = 0; i < a.quads.size(); ++i) {
    EXPECT_EQ(a.quads[i].origin, b.quads[i].origin);
    EXPECT_EQ(a.quads[i].normal, b.quads[i].normal);
    EXPECT_EQ(a.quads[i].size_u, b.quads[i].size_u);
    EXPECT_EQ(a.quads[i].size_v, b.quads[i].size_v);
    EXPECT_EQ(a.quads[i].kind, b.quads[i].kind);
    EXPECT_EQ(cv::norm(a.quads[i].lightmap, b.quads[i].lightmap, cv::NORM_INF), 0.0);
  }
  ASSERT_EQ(a.boxes.size(), b.boxes.size());
  for (size_t i = 0; i < a.boxes.size(); ++i) EXPECT_EQ(a.boxes[i].min, b.boxes[i].min);
  EXPECT_EQ(a.lights.size(), b.lights.size());
  ASSERT_EQ(plain().trajectory.poses.size(), textured().trajectory.poses.size());
  for (size_t i = 0; i < plain().trajectory.poses.size(); ++i)
    EXPECT_EQ(plain().trajectory.poses[i].centre, textured().trajectory.poses[i].centre);
  EXPECT_EQ(plain().scene.options.texture, TextureStyle::kPlain);
  // A few plain door frames on the walls: their top corners are the landmarks.
  EXPECT_GE(a.landmarks.size(), 6u);
  EXPECT_LT(a.landmarks.size(), b.landmarks.size() / 2);
}

// Away from the edges (of the surfaces and of their albedo) a plain image is flat: with the
// noise off its gradient is the lighting's (smooth, in 8-bit steps), and with the noise on it is
// close to the noise's. Most of the image is such flat area. The textured image of the same pose
// has little of it, and over the plain image's flat area its gradient fails the same check.
// Edges are where the geometry says: visible where surfaces meet, and LSD's segments lie on
// the edges of the surfaces and their albedo.
TEST_F(PlainRenderTest, ImagesAreFlatAwayFromTheEdges) {
  cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector();
  int long_segments = 0, on_edges = 0;
  for (int frame : {0, 15, 30, 45}) {
    const CameraPose& pose = plain().trajectory.poses[frame];
    const RenderedView view = render_frame(plain(), frame);
    RenderOptions quiet = plain().render;
    quiet.noise_sigma = 0.0;
    const cv::Mat clean = render_view(plain().scene, plain().camera, pose, quiet).image;
    const cv::Mat edges = edge_mask(view, albedo_image(plain(), pose, view), 3);
    cv::Mat flat;
    cv::bitwise_not(edges, flat);
    EXPECT_GT(cv::countNonZero(flat), 0.8 * flat.total()) << "frame " << frame;

    cv::Mat noise;
    cv::subtract(view.image, clean, noise, cv::noArray(), CV_32F);
    const std::vector<double> lit = values_where(gradient(clean), flat);
    const std::vector<double> noisy = values_where(gradient(view.image), flat);
    const std::vector<double> noise_only = values_where(gradient(noise), flat);
    EXPECT_LT(quantile(lit, 0.9), 1.5) << "frame " << frame;
    EXPECT_LT(quantile(noisy, 0.5), 1.3 * quantile(noise_only, 0.5)) << "frame " << frame;
    EXPECT_LT(quantile(noisy, 0.9), 1.5 * quantile(noise_only, 0.9)) << "frame " << frame;

    const RenderedView textured_view = render_frame(textured(), frame);
    const cv::Mat textured_edges =
        edge_mask(textured_view, albedo_image(textured(), pose, textured_view), 3);
    EXPECT_LT(cv::countNonZero(~textured_edges), 0.2 * flat.total()) << "frame " << frame;
    // The plain criterion, on the textured image: its texture fails it.
    EXPECT_GT(quantile(values_where(gradient(textured_view.image), flat), 0.9),
              1.5 * quantile(noise_only, 0.9))
        << "frame " << frame;

    // Where two surfaces of different orientation meet, the lighting draws the edge: within
    // 2 px of the crease the gradient is many times the noise's.
    cv::Mat near_crease;
    cv::dilate(gradient(clean), near_crease, cv::Mat::ones(5, 5, CV_8U));
    std::vector<double> crease;
    for (int y = 3; y + 3 < view.image.rows; ++y)
      for (int x = 3; x + 3 < view.image.cols; ++x) {
        const int id = view.quad_id.at<int>(y, x);
        for (const cv::Point d : {cv::Point(1, 0), cv::Point(0, 1)}) {
          const int other = view.quad_id.at<int>(y + d.y, x + d.x);
          if (other != id && plain().scene.quads[other].normal != plain().scene.quads[id].normal)
            crease.push_back(near_crease.at<float>(y, x));
        }
      }
    EXPECT_GT(crease.size(), 1000u) << "frame " << frame;
    EXPECT_GT(quantile(crease, 0.5), 10.0 * quantile(noise_only, 0.5)) << "frame " << frame;

    std::vector<cv::Vec4f> segments;
    lsd->detect(view.image, segments);
    int frame_segments = 0, frame_on_edges = 0;
    for (const cv::Vec4f& s : segments) {
      if (std::hypot(s[2] - s[0], s[3] - s[1]) < 20.0) continue;
      ++frame_segments;
      bool on = true;
      for (double t = 0.0; t <= 1.0; t += 0.1) {
        const int x = static_cast<int>(std::lround(s[0] + t * (s[2] - s[0])));
        const int y = static_cast<int>(std::lround(s[1] + t * (s[3] - s[1])));
        on = on && edges.at<uchar>(std::clamp(y, 0, edges.rows - 1),
                                   std::clamp(x, 0, edges.cols - 1));
      }
      frame_on_edges += on;
    }
    EXPECT_GE(frame_segments, 3) << "frame " << frame;
    EXPECT_GE(frame_on_edges, 0.8 * frame_segments) << "frame " << frame;
    long_segments += frame_segments;
    on_edges += frame_on_edges;
  }
  EXPECT_GE(long_segments, 40);
  EXPECT_GE(on_edges, 0.9 * long_segments);
}

// A point tracker finds a handful of corners that follow the motion (box, door and joint
// corners); the textured corridor gives hundreds.
TEST_F(PlainRenderTest, FewCornersFollowTheMotion) {
  const PinholeCamera& cam = plain().camera;
  auto tracked_with_the_motion = [&](const Sequence& seq, int frame) {
    const CameraPose& pose1 = seq.trajectory.poses[frame];
    const CameraPose& pose2 = seq.trajectory.poses[frame + 1];
    const RenderedView v1 = render_frame(seq, frame), v2 = render_frame(seq, frame + 1);
    std::vector<cv::Point2f> corners, tracked;
    cv::goodFeaturesToTrack(v1.image, corners, 1000, 0.01, 8);
    std::vector<uchar> status;
    std::vector<float> error;
    cv::calcOpticalFlowPyrLK(v1.image, v2.image, corners, tracked, status, error,
                             cv::Size(21, 21), 3);
    int good = 0;
    for (size_t k = 0; k < corners.size(); ++k) {
      if (!status[k]) continue;
      const float z = v1.depth.at<float>(static_cast<int>(std::lround(corners[k].y)),
                                         static_cast<int>(std::lround(corners[k].x)));
      Eigen::Vector2d p2;
      double z2 = 0.0;
      if (!project(cam, pose2, back_project(cam, pose1, corners[k].x, corners[k].y, z), 2.0,
                   &p2, &z2))
        continue;
      good += std::hypot(tracked[k].x - p2.x(), tracked[k].y - p2.y()) < 0.5;
    }
    return good;
  };
  for (int frame : {5, 25, 40}) {
    const int plain_good = tracked_with_the_motion(plain(), frame);
    const int textured_good = tracked_with_the_motion(textured(), frame);
    EXPECT_LT(plain_good, 60) << "frame " << frame;
    EXPECT_GT(textured_good, 100) << "frame " << frame;
    EXPECT_LT(3 * plain_good, textured_good) << "frame " << frame;
  }
}

TEST(RenderOptions, StampsAreExact) {
  EXPECT_EQ(frame_stamp_ns(0, 10.0), 1000000000ull);
  EXPECT_EQ(frame_stamp_ns(1, 10.0), 1100000000ull);
  EXPECT_EQ(frame_stamp_ns(3, 30.0), 1100000000ull);
  EXPECT_EQ(frame_stamp_ns(149, 10.0), 15900000000ull);
}

TEST(RenderOptions, ArgumentsAreParsedAndBadOnesRejected) {
  SequenceOptions o;
  EXPECT_EQ(parse_sequence_args(
                {"--out", "x.bag", "--frames", "20", "--stereo", "--width", "320", "--height",
                 "240", "--rate", "20", "--seed", "7", "--scene", "room", "--png-dir", "/tmp/p"},
                &o),
            "");
  EXPECT_EQ(o.out_bag, "x.bag");
  EXPECT_EQ(o.frames, 20);
  EXPECT_TRUE(o.stereo);
  EXPECT_EQ(o.width, 320);
  EXPECT_EQ(o.height, 240);
  EXPECT_EQ(o.rate, 20.0);
  EXPECT_EQ(o.seed, 7u);
  EXPECT_EQ(o.scene, SceneType::kRoom);
  EXPECT_EQ(o.png_dir, "/tmp/p");
  EXPECT_EQ(o.texture, TextureStyle::kTextured);
  EXPECT_TRUE(o.kitti_dir.empty());

  // The KITTI layout alone is an output too; the plain surfaces.
  SequenceOptions kitti;
  EXPECT_EQ(parse_sequence_args({"--kitti-dir", "/tmp/k", "--kitti-name", "lowtex", "--texture",
                                 "plain"},
                                &kitti),
            "");
  EXPECT_TRUE(kitti.out_bag.empty());
  EXPECT_EQ(kitti.kitti_dir, "/tmp/k");
  EXPECT_EQ(kitti.kitti_name, "lowtex");
  EXPECT_EQ(kitti.texture, TextureStyle::kPlain);
  SequenceOptions default_name;
  EXPECT_EQ(parse_sequence_args({"--kitti-dir", "/tmp/k"}, &default_name), "");
  EXPECT_EQ(default_name.kitti_name, "00");
  SequenceOptions more;
  EXPECT_EQ(parse_sequence_args({"--out", "x.bag", "--fisheye-fov", "150", "--compressed", "jpeg",
                                 "--jpeg-quality", "80"},
                                &more),
            "");
  EXPECT_EQ(more.fisheye_fov, 150.0);
  EXPECT_EQ(more.compressed_images, "jpeg");
  EXPECT_EQ(more.jpeg_quality, 80);

  SequenceOptions turn;
  EXPECT_EQ(parse_sequence_args({"--out", "x.bag", "--motion", "turn", "--lever-arm", "0",
                                 "--turn-rate", "-20", "--turn-stop"},
                                &turn),
            "");
  EXPECT_EQ(turn.motion, Motion::kTurn);
  EXPECT_EQ(turn.lever_arm, 0.0);
  EXPECT_EQ(turn.turn_rate, -20.0);
  EXPECT_TRUE(turn.turn_stop);
  SequenceOptions ramp;
  EXPECT_EQ(parse_sequence_args({"--out", "x.bag", "--motion", "ramp", "--rest-seconds", "0.5",
                                 "--ramp-seconds", "3"},
                                &ramp),
            "");
  EXPECT_EQ(ramp.motion, Motion::kRamp);
  EXPECT_EQ(ramp.rest_seconds, 0.5);
  EXPECT_EQ(ramp.ramp_seconds, 3.0);
  EXPECT_EQ(o.motion, Motion::kWalk);

  const std::vector<std::vector<std::string>> bad = {
      {},         // no --out
      {"--out"},  // missing value
      {"--out", "x.bag", "--frames", "0"},
      {"--out", "x.bag", "--frames", "12abc"},
      {"--out", "x.bag", "--frames", "-3"},
      {"--out", "x.bag", "--width", "5"},
      {"--out", "x.bag", "--height", "100000"},
      {"--out", "x.bag", "--rate", "0"},
      {"--out", "x.bag", "--rate", "nan"},
      {"--out", "x.bag", "--seed", "-1"},
      {"--out", "x.bag", "--scene", "garden"},
      {"--out", "x.bag", "--baseline", "0"},
      {"--out", "x.bag", "--speed", "9"},
      {"--out", "x.bag", "--noise", "-1"},
      {"--out", "x.bag", "--supersampling", "0"},
      {"--out", "x.bag", "--compression", "zip"},
      {"--out", "x.bag", "--bogus"},
      {"--out", "x.bag", "--texture", "wood"},
      {"--kitti-dir", "/tmp/k", "--kitti-name", "a/b"},
      {"--kitti-dir", "/tmp/k", "--kitti-name", ".."},
      {"--kitti-dir", ""},
      {"--kitti-name", "00"},  // no output
      {"--out", "x.bag", "--fisheye-fov", "0"},
      {"--out", "x.bag", "--fisheye-fov", "150", "--focal", "300"},
      {"--out", "x.bag", "--compressed", "gif"},
      {"--out", "x.bag", "--jpeg-quality", "101"},
      {"--kitti-dir", "/tmp/k", "--fisheye-fov", "150"},  // calib.txt is pinhole
      {"--out", "x.bag", "--motion", "fly"},
      {"--out", "x.bag", "--motion", "turn", "--lever-arm", "-0.1"},
      {"--out", "x.bag", "--motion", "turn", "--lever-arm", "nan"},
      {"--out", "x.bag", "--motion", "turn", "--turn-rate", "inf"},
      {"--out", "x.bag", "--motion", "turn", "--turn-rate", "nan"},
      {"--out", "x.bag", "--motion", "turn", "--turn-rate", "400"},
      {"--out", "x.bag", "--motion", "ramp", "--rest-seconds", "-1"},
      {"--out", "x.bag", "--motion", "ramp", "--ramp-seconds", "nan"},
      {"--out", "x.bag", "--lever-arm", "0.3"},  // an option of the turn, for the walk
      {"--out", "x.bag", "--motion", "turn", "--rest-seconds", "2"},
      {"--out", "x.bag", "--motion", "ramp", "--turn-stop"},
      {"--out", "x.bag", "--motion", "rest", "--laps", "1"},
  };
  for (const auto& args : bad) {
    SequenceOptions options;
    std::string joined;
    for (const std::string& a : args) joined += a + " ";
    EXPECT_NE(parse_sequence_args(args, &options), "") << joined;
  }
  SequenceOptions help;
  EXPECT_EQ(parse_sequence_args({"--help"}, &help), "");
  EXPECT_TRUE(help.help);

  const std::string dir = testing::TempDir();
  EXPECT_EQ(check_writable_file(dir + "/render_test.bag"), "");
  EXPECT_NE(check_writable_file("/nonexistent_hybrid_vo_dir/x.bag"), "");
  EXPECT_NE(check_writable_file(dir), "");  // a directory
}

TEST(RenderOptions, InvalidSceneCameraAndPathAreRejected) {
  auto scene_with = [](auto change) {
    SceneOptions o;
    o.texels_per_metre = 64;
    change(o);
    return build_scene(o);
  };
  EXPECT_THROW(scene_with([](SceneOptions& o) { o.height = 1.0; }), std::invalid_argument);
  EXPECT_THROW(scene_with([](SceneOptions& o) { o.corridor_width = 1.0; }), std::invalid_argument);
  EXPECT_THROW(scene_with([](SceneOptions& o) { o.size_x = 5.0; }), std::invalid_argument);
  EXPECT_THROW(scene_with([](SceneOptions& o) { o.texels_per_metre = 4.0; }),
               std::invalid_argument);
  EXPECT_THROW(scene_with([](SceneOptions& o) { o.num_furniture = -1; }), std::invalid_argument);
  EXPECT_THROW(scene_with([](SceneOptions& o) { o.height = std::nan(""); }), std::invalid_argument);

  const Scene scene = scene_with([](SceneOptions&) {});
  auto path_with = [&](auto change) {
    PathOptions p;
    change(p);
    return make_trajectory(scene, p);
  };
  EXPECT_THROW(path_with([](PathOptions& p) { p.num_frames = 0; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.rate_hz = 0.0; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.speed = 10.0; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.camera_height = 2.6; }), std::invalid_argument);
  EXPECT_NO_THROW(path_with([](PathOptions&) {}));
  EXPECT_THROW(path_with([](PathOptions& p) { p.lever_arm = -0.1; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.lever_arm = kNaN; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.turn_rate_deg = kNaN; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.turn_rate_deg = HUGE_VAL; }),
               std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.rest_seconds = -1.0; }), std::invalid_argument);
  EXPECT_THROW(path_with([](PathOptions& p) { p.ramp_seconds = kNaN; }), std::invalid_argument);
  // A circle through the corridor's walls.
  EXPECT_THROW(path_with([](PathOptions& p) {
                 p.motion = Motion::kTurn;
                 p.lever_arm = 1.9;
               }),
               std::invalid_argument);

  const CameraPose pose = make_trajectory(scene, PathOptions{}).poses[0];
  PinholeCamera cam = default_camera(64, 48);
  EXPECT_NO_THROW(render_view(scene, cam, pose));
  PinholeCamera no_size = cam;
  no_size.width = 0;
  EXPECT_THROW(render_view(scene, no_size, pose), std::invalid_argument);
  PinholeCamera bad_focal = cam;
  bad_focal.fx = 0.0;
  EXPECT_THROW(render_view(scene, bad_focal, pose), std::invalid_argument);
  RenderOptions bad_ss;
  bad_ss.supersampling = 0;
  EXPECT_THROW(render_view(scene, cam, pose, bad_ss), std::invalid_argument);
  CameraPose not_rotation = pose;
  not_rotation.R_world_from_camera *= 2.0;
  EXPECT_THROW(render_view(scene, cam, not_rotation), std::invalid_argument);
  // Lenses: plumb_bob distortion is not rendered, nor equidistant coefficients that fold back.
  CameraModel radial;
  radial.pinhole = cam;
  radial.distortion[0] = 0.1;
  EXPECT_THROW(render_view(scene, radial, pose), std::invalid_argument);
  CameraModel folding = fisheye_camera(150.0, 64, 48);
  folding.distortion = {-0.5, 0, 0, 0, 0};
  EXPECT_THROW(render_view(scene, folding, pose), std::invalid_argument);
  EXPECT_NO_THROW(render_view(scene, fisheye_camera(150.0, 64, 48), pose));
  EXPECT_THROW(fisheye_camera(0.0), std::invalid_argument);
}

// The fisheye: a 150-degree equidistant lens on the same walk. What each pixel shows is what its
// ray through the lens model meets (also beyond 90 degrees, in the corners), and the painted
// corners appear where the lens model projects them.
class FisheyeRenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SequenceOptions options;
    options.out_bag = "unused.bag";
    options.frames = 120;
    options.fisheye_fov = 150.0;
    sequence_ = new Sequence(make_sequence(options));
  }
  static void TearDownTestSuite() {
    delete sequence_;
    sequence_ = nullptr;
  }
  static const Sequence& seq() { return *sequence_; }
  static Sequence* sequence_;
};

Sequence* FisheyeRenderTest::sequence_ = nullptr;

TEST_F(FisheyeRenderTest, EveryPixelShowsWhatItsRayMeets) {
  const CameraModel& lens = seq().lens;
  ASSERT_EQ(lens.model, LensModel::kEquidistant);
  // 150 degrees across the image's outer edges.
  EXPECT_NEAR(std::acos(lens.ray({-0.5, lens.pinhole.cy}).z()) * 180.0 / kPi, 75.0, 1e-6);
  std::mt19937 rng(5);
  for (int frame : {10, 60}) {
    const CameraPose& pose = seq().trajectory.poses[frame];
    const RenderedView view = render_frame(seq(), frame);
    int hits = 0, behind = 0;
    for (int n = 0; n < 2000; ++n) {
      const int x = static_cast<int>(rng() % lens.pinhole.width);
      const int y = static_cast<int>(rng() % lens.pinhole.height);
      const Eigen::Vector3d ray = lens.ray(Eigen::Vector2d(x, y));
      double t = 0.0;
      const int id = cast_ray(seq().scene, pose.centre, pose.R_world_from_camera * ray, &t);
      ASSERT_EQ(id, view.quad_id.at<int>(y, x)) << x << ", " << y;
      if (id < 0) continue;
      ++hits;
      behind += ray.z() < 0.0;
      EXPECT_NEAR(view.depth.at<float>(y, x), t * ray.z(), 1e-5 * t);
    }
    EXPECT_GT(hits, 1990);  // a closed corridor
    EXPECT_GT(behind, 0);   // the corners see behind the image plane
  }
}

TEST_F(FisheyeRenderTest, PaintedCornersProjectThroughTheLens) {
  const CameraModel& lens = seq().lens;
  std::vector<double> errors;
  for (int frame = 0; frame < 120; frame += 8) {
    const CameraPose& pose = seq().trajectory.poses[frame];
    const RenderedView view = render_frame(seq(), frame);
    for (const Landmark& lm : seq().scene.landmarks) {
      Eigen::Vector2d p;
      const Eigen::Vector3d X = pose.to_camera(lm.position);
      if (!lens.project(X, &p) || X.norm() > 5.0 || p.x() < 12 || p.y() < 12 ||
          p.x() > lens.pinhole.width - 13 || p.y() > lens.pinhole.height - 13)
        continue;
      // A 5 x 5 window, not the pinhole test's 7 x 7: the fisheye's pixels are about twice as
      // wide, so the painted corners come twice as close to one another.
      const double error = painted_corner_error(seq().scene, view, pose, lm, p, 2);
      if (std::isfinite(error)) errors.push_back(error);
    }
  }
  ASSERT_GE(errors.size(), 30u);
  EXPECT_LT(median(errors), 0.35);
  EXPECT_LT(quantile(errors, 0.8), 0.6);
  RecordProperty("painted_corners", static_cast<int>(errors.size()));
}

// Two independent paths to the same picture: the fisheye view rectified into a 100-degree pinhole
// view (features/fisheye_rectifier.h) against the pinhole renderer's view of that camera. Where
// the fisheye resolves at least as finely as the view (the middle), they agree to a few grey
// levels and without a shift.
TEST_F(FisheyeRenderTest, RectifiedViewIsThePinholeRenderersView) {
  FisheyeRectifier rectifier(100.0);
  const PinholeCamera view = rectifier.view(640, 480);
  RenderOptions clean;
  clean.noise_sigma = 0.0;
  for (int frame : {20, 90}) {
    const CameraPose& pose = seq().trajectory.poses[frame];
    const RenderedView fisheye = render_view(seq().scene, seq().lens, pose, clean);
    const RenderedView pinhole = render_view(seq().scene, view, pose, clean);
    cv::Mat rectified;
    CameraModel rectified_camera;
    std::string reason;
    ASSERT_TRUE(rectifier.rectify(seq().lens, Eigen::Matrix3d::Identity(), fisheye.image,
                                  &rectified, &rectified_camera, &reason))
        << reason;
    EXPECT_EQ(rectified_camera.pinhole.fx, view.fx);
    const cv::Rect middle(160, 120, 320, 240);
    cv::Mat a, b, difference;
    rectified(middle).convertTo(a, CV_32F);
    pinhole.image(middle).convertTo(b, CV_32F);
    cv::absdiff(a, b, difference);
    EXPECT_LT(cv::mean(difference)[0], 3.0) << "frame " << frame;
    const cv::Point2d shift = cv::phaseCorrelate(a, b);
    EXPECT_LT(std::hypot(shift.x, shift.y), 0.1) << "frame " << frame;
    cv::Mat correlation;
    cv::matchTemplate(a, b, correlation, cv::TM_CCOEFF_NORMED);
    EXPECT_GT(correlation.at<float>(0, 0), 0.97) << "frame " << frame;
  }
}

}  // namespace
