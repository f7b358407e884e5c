#include "view_radiance.h"
#include "shading.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/core/utility.hpp>

namespace hybrid_vo {
namespace render {
namespace {

constexpr int kBands = 16;  // horizontal bands rendered in parallel, as the pinhole view's

// The unit ray of every sample in the camera frame (NaN where the lens has none).
struct SampleRays {
  int ss = 1, width = 0, height = 0;
  std::vector<Eigen::Vector3d> ray;
  const Eigen::Vector3d& at(int i, int j) const { return ray[static_cast<size_t>(j) * width + i]; }
  // The ray's change per sample step along x (or y), by central differences (one-sided at the
  // border or next to a sample without a ray); zero when there is none.
  Eigen::Vector3d step(int i, int j, bool along_x) const {
    auto valid = [&](int a, int b) {
      return a >= 0 && b >= 0 && a < width && b < height && at(a, b).allFinite();
    };
    const int di = along_x ? 1 : 0, dj = along_x ? 0 : 1;
    const bool next = valid(i + di, j + dj), previous = valid(i - di, j - dj);
    if (next && previous) return 0.5 * (at(i + di, j + dj) - at(i - di, j - dj));
    if (next) return at(i + di, j + dj) - at(i, j);
    if (previous) return at(i, j) - at(i - di, j - dj);
    return Eigen::Vector3d::Zero();
  }
};

SampleRays sample_rays(const CameraModel& camera, int ss) {
  SampleRays rays;
  rays.ss = ss;
  rays.width = camera.pinhole.width * ss;
  rays.height = camera.pinhole.height * ss;
  rays.ray.resize(static_cast<size_t>(rays.width) * rays.height);
  cv::parallel_for_(cv::Range(0, rays.height), [&](const cv::Range& rows) {
    for (int j = rows.start; j < rows.end; ++j)
      for (int i = 0; i < rays.width; ++i)
        rays.ray[static_cast<size_t>(j) * rays.width + i] =
            camera.ray(Eigen::Vector2d(sample_coord(i, ss), sample_coord(j, ss)));
  });
  return rays;
}

// Whether the ray from origin along direction meets the quad (either side).
bool meets(const Quad& q, const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) {
  const int a = q.normal_axis();
  const double t = (q.origin[a] - origin[a]) / direction[a];
  if (!(t > 0.0) || !std::isfinite(t)) return false;
  const Eigen::Vector2d uv = q.local(origin + t * direction);
  return uv.x() >= 0.0 && uv.x() <= q.size_u && uv.y() >= 0.0 && uv.y() <= q.size_v;
}

// The image of the quad's outline: each edge subdivided until consecutive points are within
// 0.25 degrees as seen from the camera, projected through the lens. False when the outline
// passes near the backward axis, where the lens' image of it swings around the whole image.
bool outline_bounds(const Quad& q, const CameraModel& camera, const CameraPose& pose,
                    Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  const std::array<Eigen::Vector3d, 4> corners = {q.origin, q.point(q.size_u, 0),
                                                  q.point(q.size_u, q.size_v),
                                                  q.point(0, q.size_v)};
  const double max_step = 0.25 * M_PI / 180.0, max_angle = 170.0 * M_PI / 180.0;
  *lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  *hi = -*lo;
  for (int k = 0; k < 4; ++k) {
    const Eigen::Vector3d a = pose.to_camera(corners[k]), b = pose.to_camera(corners[(k + 1) % 4]);
    // Uniform steps along the edge subtend at most their length over the edge's nearest
    // distance to the camera.
    const Eigen::Vector3d edge = b - a;
    const double s = std::clamp(-a.dot(edge) / edge.squaredNorm(), 0.0, 1.0);
    const double nearest = std::max((a + s * edge).norm(), 1e-6);
    const int n = std::clamp(static_cast<int>(std::ceil(edge.norm() / nearest / max_step)), 1,
                             200000);
    for (int m = 0; m <= n; ++m) {
      const Eigen::Vector3d X = a + edge * (static_cast<double>(m) / n);
      if (std::atan2(X.head<2>().norm(), X.z()) > max_angle) return false;
      Eigen::Vector2d p;
      if (!camera.project(X, &p)) return false;
      *lo = lo->cwiseMin(p);
      *hi = hi->cwiseMax(p);
    }
  }
  return true;
}

std::vector<QuadRaster> setup_quads(const Scene& scene, const CameraModel& camera,
                                    const CameraPose& pose, int ss, int width, int height) {
  std::vector<QuadRaster> out;
  const Eigen::Vector3d backward = -pose.R_world_from_camera.col(2);
  for (size_t i = 0; i < scene.quads.size(); ++i) {
    const Quad& q = scene.quads[i];
    QuadRaster r;
    if (!quad_plane(scene, static_cast<int>(i), pose.centre, &r)) continue;
    // Samples to test: the whole image when the quad holds the backward axis (its outline then
    // surrounds the rest of the image) or its outline passes near it, else the outline's box
    // with a margin of 3 pixels for the curve between the outline's points.
    Eigen::Vector2d lo, hi;
    if (meets(q, pose.centre, backward) || !outline_bounds(q, camera, pose, &lo, &hi)) {
      r.x0 = r.y0 = 0;
      r.x1 = width - 1;
      r.y1 = height - 1;
    } else {
      auto to_sample = [ss](double x) { return (x + 0.5) * ss - 0.5; };
      const double margin = 3.0 * ss, big = 1e7;
      r.x0 = static_cast<int>(std::max(0.0, std::floor(std::max(-big, to_sample(lo.x()) - margin))));
      r.x1 = static_cast<int>(std::min(width - 1.0, std::ceil(std::min(big, to_sample(hi.x()) + margin))));
      r.y0 = static_cast<int>(std::max(0.0, std::floor(std::max(-big, to_sample(lo.y()) - margin))));
      r.y1 = static_cast<int>(std::min(height - 1.0, std::ceil(std::min(big, to_sample(hi.y()) + margin))));
    }
    if (r.x0 > r.x1 || r.y0 > r.y1) continue;
    out.push_back(r);
  }
  return out;
}

struct SampleGrid {
  int width = 0, height = 0;
  std::vector<double> t;  // along the unit ray
  std::vector<int> id;
};

// The nearest quad each sample's ray meets, and the distance along the (unit) ray.
SampleGrid rasterize(const Scene& scene, const CameraModel& camera, const CameraPose& pose,
                     const SampleRays& rays, double near) {
  SampleGrid grid;
  grid.width = rays.width;
  grid.height = rays.height;
  grid.t.assign(static_cast<size_t>(grid.width) * grid.height,
                std::numeric_limits<double>::infinity());
  grid.id.assign(grid.t.size(), -1);
  const std::vector<QuadRaster> quads =
      setup_quads(scene, camera, pose, rays.ss, grid.width, grid.height);
  const Eigen::Matrix3d& R = pose.R_world_from_camera;
  const Eigen::Vector3d& c = pose.centre;
  cv::parallel_for_(cv::Range(0, kBands), [&](const cv::Range& bands) {
    for (int band = bands.start; band < bands.end; ++band) {
      const int row0 = band * grid.height / kBands, row1 = (band + 1) * grid.height / kBands;
      for (const QuadRaster& q : quads) {
        const Eigen::Vector3d ra = R.row(q.a).transpose(), ru = R.row(q.iu).transpose(),
                              rv = R.row(q.iv).transpose();
        for (int j = std::max(q.y0, row0); j <= std::min(q.y1, row1 - 1); ++j) {
          double* t_row = &grid.t[static_cast<size_t>(j) * grid.width];
          int* id_row = &grid.id[static_cast<size_t>(j) * grid.width];
          for (int i = q.x0; i <= q.x1; ++i) {
            const Eigen::Vector3d& d = rays.at(i, j);
            const double t = (q.plane - c[q.a]) / ra.dot(d);
            if (!(t > near) || t >= t_row[i]) continue;  // also NaN rays
            const double hu = c[q.iu] + t * ru.dot(d);
            if (hu < q.lo_u || hu > q.hi_u) continue;
            const double hv = c[q.iv] + t * rv.dot(d);
            if (hv < q.lo_v || hv > q.hi_v) continue;
            t_row[i] = t;
            id_row[i] = q.index;
          }
        }
      }
    }
  });
  return grid;
}

}  // namespace

ViewRadiance equidistant_radiance(const Scene& scene, const CameraModel& camera,
                                  const CameraPose& pose, const RenderOptions& o,
                                  bool with_geometry) {
  const PinholeCamera& cam = camera.pinhole;
  check(camera.model == LensModel::kEquidistant && camera_model_problem(camera).empty() &&
            cam.width >= 1 && cam.height >= 1 && cam.width <= 8192 && cam.height <= 8192,
        "the fisheye camera needs a valid equidistant model and a size in [1, 8192]");
  check_render_inputs(o, pose);
  const int ss = o.supersampling;
  const SampleRays rays = sample_rays(camera, ss);
  const SampleGrid grid = rasterize(scene, camera, pose, rays, o.near);
  const Eigen::Matrix3d& R = pose.R_world_from_camera;
  const Eigen::Vector3d& c = pose.centre;

  cv::Mat radiance(cam.height, cam.width, CV_32FC1);
  cv::parallel_for_(cv::Range(0, kBands), [&](const cv::Range& bands) {
    for (int band = bands.start; band < bands.end; ++band) {
      for (int y = band * cam.height / kBands; y < (band + 1) * cam.height / kBands; ++y) {
        float* out = radiance.ptr<float>(y);
        for (int x = 0; x < cam.width; ++x) {
          double sum = 0.0;
          for (int sj = 0; sj < ss; ++sj) {
            const int j = y * ss + sj;
            for (int si = 0; si < ss; ++si) {
              const int i = x * ss + si;
              const size_t k = static_cast<size_t>(j) * grid.width + i;
              const int id = grid.id[k];
              if (id < 0) continue;
              const Quad& q = scene.quads[id];
              const double t = grid.t[k];
              const Eigen::Vector3d d = R * rays.at(i, j);
              const Eigen::Vector3d X = c + t * d;
              // Footprint: dX = t (e - d (n . e) / (n . d)) for a ray step e, as the pinhole's.
              const Eigen::Vector3d ex = R * rays.step(i, j, true), ey = R * rays.step(i, j, false);
              const double nd = q.normal.dot(d);
              const Eigen::Vector3d dX_dx = t * (ex - d * (q.normal.dot(ex) / nd));
              const Eigen::Vector3d dX_dy = t * (ey - d * (q.normal.dot(ey) / nd));
              sum += shade(q, q.local(X), dX_dx, dX_dy, o.max_anisotropy);
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
  const bool odd = ss % 2 == 1;
  const SampleRays centre_rays = odd ? SampleRays() : sample_rays(camera, 1);
  const SampleGrid centres =
      odd ? SampleGrid() : rasterize(scene, camera, pose, centre_rays, o.near);
  const SampleGrid& g = odd ? grid : centres;
  const SampleRays& r = odd ? rays : centre_rays;
  const int gs = odd ? ss : 1, mid = gs / 2;
  view.depth = cv::Mat(cam.height, cam.width, CV_32FC1);
  view.quad_id = cv::Mat(cam.height, cam.width, CV_32SC1);
  for (int y = 0; y < cam.height; ++y)
    for (int x = 0; x < cam.width; ++x) {
      const int i = x * gs + mid, j = y * gs + mid;
      const size_t k = static_cast<size_t>(j) * g.width + i;
      view.quad_id.at<int>(y, x) = g.id[k];
      view.depth.at<float>(y, x) = g.id[k] >= 0 ? static_cast<float>(g.t[k] * r.at(i, j).z()) : 0.0f;
    }
  return view;
}

}  // namespace render
}  // namespace hybrid_vo
