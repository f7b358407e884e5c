#include "hybrid_vo/render/renderer.h"

#include "hybrid_vo/render/imaging.h"
#include "shading.h"
#include "view_radiance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

namespace hybrid_vo {
namespace render {
namespace {

constexpr int kBands = 16;  // horizontal bands rendered in parallel; each pixel by one band

struct SampleGrid {
  int ss = 1, width = 0, height = 0;  // samples
  std::vector<float> depth;
  std::vector<int> id;
};

std::vector<QuadRaster> setup_quads(const Scene& scene, const PinholeCamera& cam,
                                    const CameraPose& pose, int ss, double near, int width,
                                    int height) {
  std::vector<QuadRaster> out;
  const Eigen::Matrix3d Rt = pose.R_world_from_camera.transpose();
  for (size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    QuadRaster r;
    if (!quad_plane(scene, static_cast<int>(i), pose.centre, &r)) continue;
    // Clip the quad to z >= near in the camera and bound its projection.
    std::array<Eigen::Vector3d, 4> corners = {Rt * (q.origin - pose.centre),
                                              Rt * (q.point(q.size_u, 0) - pose.centre),
                                              Rt * (q.point(q.size_u, q.size_v) - pose.centre),
                                              Rt * (q.point(0, q.size_v) - pose.centre)};
    std::vector<Eigen::Vector3d> clipped;
    for (int k = 0; k < 4; ++k) {
      const Eigen::Vector3d& p = corners[k];
      const Eigen::Vector3d& n = corners[(k + 1) % 4];
      if (p.z() >= near) clipped.push_back(p);
      if ((p.z() >= near) != (n.z() >= near))
        clipped.push_back(p + (n - p) * ((near - p.z()) / (n.z() - p.z())));
    }
    if (clipped.empty()) continue;
    double x_min = std::numeric_limits<double>::max(), x_max = -x_min;
    double y_min = x_min, y_max = -x_min;
    for (const Eigen::Vector3d& p : clipped) {
      const double x = cam.fx * p.x() / p.z() + cam.cx, y = cam.fy * p.y() / p.z() + cam.cy;
      x_min = std::min(x_min, x);
      x_max = std::max(x_max, x);
      y_min = std::min(y_min, y);
      y_max = std::max(y_max, y);
    }
    // Image point x is sample (x + 0.5) * ss - 0.5; one sample of slack for rounding.
    auto to_sample = [ss](double x) { return (x + 0.5) * ss - 0.5; };
    const double big = 1e7;
    r.x0 = static_cast<int>(std::max(0.0, std::floor(std::max(-big, to_sample(x_min))) - 1));
    r.x1 = static_cast<int>(std::min(width - 1.0, std::ceil(std::min(big, to_sample(x_max))) + 1));
    r.y0 = static_cast<int>(std::max(0.0, std::floor(std::max(-big, to_sample(y_min))) - 1));
    r.y1 = static_cast<int>(std::min(height - 1.0, std::ceil(std::min(big, to_sample(y_max))) + 1));
    if (r.x0 > r.x1 || r.y0 > r.y1) continue;
    out.push_back(r);
  }
  return out;
}

// The nearest quad hit by every sample's ray. The ray direction R (xn, yn, 1) has camera z = 1,
// so its parameter at the hit is the camera depth.
SampleGrid rasterize(const Scene& scene, const PinholeCamera& cam, const CameraPose& pose, int ss,
                     double near) {
  SampleGrid grid;
  grid.ss = ss;
  grid.width = cam.width * ss;
  grid.height = cam.height * ss;
  grid.depth.assign(static_cast<size_t>(grid.width) * grid.height,
                    std::numeric_limits<float>::infinity());
  grid.id.assign(grid.depth.size(), -1);
  const std::vector<QuadRaster> quads =
      setup_quads(scene, cam, pose, ss, near, grid.width, grid.height);
  const Eigen::Matrix3d& R = pose.R_world_from_camera;
  const Eigen::Vector3d& c = pose.centre;
  std::vector<double> xn(grid.width);
  for (int i = 0; i < grid.width; ++i) xn[i] = (sample_coord(i, ss) - cam.cx) / cam.fx;

  cv::parallel_for_(cv::Range(0, kBands), [&](const cv::Range& bands) {
    for (int band = bands.start; band < bands.end; ++band) {
      const int row0 = band * grid.height / kBands, row1 = (band + 1) * grid.height / kBands;
      for (const QuadRaster& q : quads) {
        const int y0 = std::max(q.y0, row0), y1 = std::min(q.y1, row1 - 1);
        for (int j = y0; j <= y1; ++j) {
          const double yn = (sample_coord(j, ss) - cam.cy) / cam.fy;
          const Eigen::Vector3d base = R.col(2) + yn * R.col(1);
          float* depth = &grid.depth[static_cast<size_t>(j) * grid.width];
          int* id = &grid.id[static_cast<size_t>(j) * grid.width];
          const double ca = c[q.a], cu = c[q.iu], cv = c[q.iv];
          const double ra = R(q.a, 0), ru = R(q.iu, 0), rv = R(q.iv, 0);
          for (int i = q.x0; i <= q.x1; ++i) {
            const double da = base[q.a] + xn[i] * ra;
            const double t = (q.plane - ca) / da;
            if (!(t > near) || t >= depth[i]) continue;
            const double hu = cu + t * (base[q.iu] + xn[i] * ru);
            if (hu < q.lo_u || hu > q.hi_u) continue;
            const double hv = cv + t * (base[q.iv] + xn[i] * rv);
            if (hv < q.lo_v || hv > q.hi_v) continue;
            depth[i] = static_cast<float>(t);
            id[i] = q.index;
          }
        }
      }
    }
  });
  return grid;
}

}  // namespace

PinholeCamera default_camera(int width, int height) {
  const double f = 0.72 * width;
  return PinholeCamera(f, f, 0.5 * (width - 1), 0.5 * (height - 1), width, height);
}

RenderedView render_view(const Scene& scene, const CameraModel& camera, const CameraPose& pose,
                         const RenderOptions& options) {
  return render_exposure(scene, camera, {pose}, options);
}

CameraModel fisheye_camera(double fov_deg, int width, int height) {
  check(fov_deg > 0.0 && fov_deg < 220.0, "the fisheye's field of view must be in (0, 220)");
  CameraModel c;
  c.model = LensModel::kEquidistant;
  c.distortion = {-0.02, 0.003, -0.0005, 0.0001, 0.0};
  const double half = 0.5 * fov_deg * M_PI / 180.0, h2 = half * half;
  const double theta_d =
      half * (1.0 + h2 * (c.distortion[0] + h2 * (c.distortion[1] +
                                                  h2 * (c.distortion[2] + h2 * c.distortion[3]))));
  const double f = 0.5 * width / theta_d;
  c.pinhole = PinholeCamera(f, f, 0.5 * (width - 1), 0.5 * (height - 1), width, height);
  return c;
}

int cast_ray(const Scene& scene, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
             double* t, double near) {
  int hit = -1;
  *t = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    const int a = q.normal_axis();
    // One-sided, as setup_quads: the origin must be on the side the normal points to.
    if (q.normal[a] * (origin[a] - q.origin[a]) <= 1e-9) continue;
    const double ti = (q.origin[a] - origin[a]) / direction[a];
    if (!(ti > near) || ti >= *t) continue;
    const Eigen::Vector2d uv = q.local(origin + ti * direction);
    if (uv.x() < 0.0 || uv.x() > q.size_u || uv.y() < 0.0 || uv.y() > q.size_v) continue;
    *t = ti;
    hit = static_cast<int>(i);
  }
  return hit;
}

RenderedView render_view(const Scene& scene, const PinholeCamera& camera, const CameraPose& pose,
                         const RenderOptions& options) {
  ViewRadiance v = pinhole_radiance(scene, camera, pose, options, true);
  RenderedView view;
  view.image = sensor_image(v.radiance, options);
  view.depth = v.depth;
  view.quad_id = v.quad_id;
  return view;
}

ViewRadiance pinhole_radiance(const Scene& scene, const PinholeCamera& cam, const CameraPose& pose,
                              const RenderOptions& o, bool with_geometry) {
  check(cam.valid() && cam.width >= 1 && cam.height >= 1 && cam.width <= 8192 && cam.height <= 8192,
        "the camera needs valid intrinsics and a size in [1, 8192]");
  check_render_inputs(o, pose);

  const int ss = o.supersampling;
  const SampleGrid grid = rasterize(scene, cam, pose, ss, o.near);
  const Eigen::Matrix3d& R = pose.R_world_from_camera;
  const Eigen::Vector3d& c = pose.centre;
  // Ray direction change per sample step along x and y.
  const Eigen::Vector3d ex = R.col(0) / (cam.fx * ss), ey = R.col(1) / (cam.fy * ss);

  cv::Mat radiance(cam.height, cam.width, CV_32FC1);
  cv::parallel_for_(cv::Range(0, kBands), [&](const cv::Range& bands) {
    for (int band = bands.start; band < bands.end; ++band) {
      for (int y = band * cam.height / kBands; y < (band + 1) * cam.height / kBands; ++y) {
        float* out = radiance.ptr<float>(y);
        for (int x = 0; x < cam.width; ++x) {
          double sum = 0.0;
          for (int sj = 0; sj < ss; ++sj) {
            const int j = y * ss + sj;
            const double yn = (sample_coord(j, ss) - cam.cy) / cam.fy;
            for (int si = 0; si < ss; ++si) {
              const int i = x * ss + si;
              const size_t k = static_cast<size_t>(j) * grid.width + i;
              const int id = grid.id[k];
              if (id < 0) continue;
              const Quad& q = scene.quads[id];
              const double t = grid.depth[k];
              const double xn = (sample_coord(i, ss) - cam.cx) / cam.fx;
              const Eigen::Vector3d d = R.col(2) + xn * R.col(0) + yn * R.col(1);
              const Eigen::Vector3d X = c + t * d;
              const Eigen::Vector2d uv = q.local(X);
              // Footprint: dX = t (e - d (n . e) / (n . d)) for a ray step e.
              const double nd = q.normal.dot(d);
              const Eigen::Vector3d dX_dx = t * (ex - d * (q.normal.dot(ex) / nd));
              const Eigen::Vector3d dX_dy = t * (ey - d * (q.normal.dot(ey) / nd));
              sum += shade(q, uv, dX_dx, dX_dy, o.max_anisotropy);
            }
          }
          out[x] = static_cast<float>(o.exposure * sum / (ss * ss));
        }
      }
    }
  });

  ViewRadiance view;
  view.radiance = radiance;
  if (!with_geometry) return view;

  // Depth and quad at the pixel centres: the middle sample for odd ss, else one more pass.
  const SampleGrid centres = ss % 2 == 1 ? SampleGrid() : rasterize(scene, cam, pose, 1, o.near);
  const SampleGrid& g = ss % 2 == 1 ? grid : centres;
  const int gs = ss % 2 == 1 ? ss : 1, mid = gs / 2;
  view.depth = cv::Mat(cam.height, cam.width, CV_32FC1);
  view.quad_id = cv::Mat(cam.height, cam.width, CV_32SC1);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const size_t k = static_cast<size_t>(y * gs + mid) * g.width + x * gs + mid;
      view.quad_id.at<int>(y, x) = g.id[k];
      view.depth.at<float>(y, x) = g.id[k] >= 0 ? g.depth[k] : 0.0f;
    }
  return view;
}

}  // namespace render
}  // namespace hybrid_vo
