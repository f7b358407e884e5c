#include "shading.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>


namespace hybrid_vo {
namespace render {

void check(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument("render: " + what);
}

void check_render_inputs(const RenderOptions& o, const CameraPose& pose) {
  check(o.supersampling >= 1 && o.supersampling <= 8, "supersampling must be in [1, 8]");
  check(std::isfinite(o.blur_sigma) && o.blur_sigma >= 0.0 && o.blur_sigma <= 10.0,
        "blur_sigma must be in [0, 10]");
  check(std::isfinite(o.noise_sigma) && o.noise_sigma >= 0.0 && o.noise_sigma <= 100.0,
        "noise_sigma must be in [0, 100]");
  check(o.max_anisotropy >= 1 && o.max_anisotropy <= 16, "max_anisotropy must be in [1, 16]");
  check(std::isfinite(o.exposure) && o.exposure > 0.0, "exposure must be positive");
  check(std::isfinite(o.near) && o.near > 0.0, "near must be positive");
  check(std::isfinite(o.vignetting) && o.vignetting >= 0.0 && o.vignetting < 1.0,
        "vignetting must be in [0, 1)");
  check(std::isfinite(o.shot_noise_gain) && o.shot_noise_gain >= 0.0 && o.shot_noise_gain <= 10.0,
        "shot_noise_gain must be in [0, 10]");
  check(o.jpeg_quality >= 0 && o.jpeg_quality <= 100, "jpeg_quality must be in [0, 100]");
  check(pose.R_world_from_camera.allFinite() && pose.centre.allFinite() &&
            (pose.R_world_from_camera.transpose() * pose.R_world_from_camera -
             Eigen::Matrix3d::Identity())
                    .norm() < 1e-6,
        "the pose needs a finite rotation matrix and centre");
}

float bilinear(const cv::Mat& m, double x, double y) {
  x = std::clamp(x, 0.0, m.cols - 1.0);
  y = std::clamp(y, 0.0, m.rows - 1.0);
  const int x0 = std::min(static_cast<int>(x), m.cols - 2 < 0 ? 0 : m.cols - 2);
  const int y0 = std::min(static_cast<int>(y), m.rows - 2 < 0 ? 0 : m.rows - 2);
  const int x1 = std::min(x0 + 1, m.cols - 1), y1 = std::min(y0 + 1, m.rows - 1);
  const double fx = x - x0, fy = y - y0;
  if (m.type() == CV_8UC1) {
    const uchar* r0 = m.ptr<uchar>(y0);
    const uchar* r1 = m.ptr<uchar>(y1);
    const double top = r0[x0] + fx * (r0[x1] - r0[x0]);
    const double bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
    return static_cast<float>(top + fy * (bottom - top));
  }
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y1);
  const double top = r0[x0] + fx * (r0[x1] - r0[x0]);
  const double bottom = r1[x0] + fx * (r1[x1] - r1[x0]);
  return static_cast<float>(top + fy * (bottom - top));
}

double sample_texture(const Texture& tex, double tu, double tv, double dux, double dvx, double duy,
                      double dvy, int max_anisotropy) {
  const double lx = std::hypot(dux, dvx), ly = std::hypot(duy, dvy);
  const bool x_major = lx >= ly;
  const double major = x_major ? lx : ly, minor = std::max(x_major ? ly : lx, 1e-9);
  const double au = x_major ? dux : duy, av = x_major ? dvx : dvy;
  const int taps = std::clamp(static_cast<int>(std::ceil(major / minor - 1e-6)), 1, max_anisotropy);
  const double footprint = std::max(minor, major / taps);
  const int top_level = static_cast<int>(tex.levels.size()) - 1;
  const double lod =
      std::clamp(std::log2(std::max(footprint, 1e-9)), 0.0, static_cast<double>(top_level));
  const int l0 = std::min(static_cast<int>(lod), top_level);
  const int l1 = std::min(l0 + 1, top_level);
  const double f = lod - l0;
  const double s0 = 1.0 / (1 << l0), s1 = 1.0 / (1 << l1);
  double sum = 0.0;
  for (int k = 0; k < taps; ++k) {
    const double o = (k + 0.5) / taps - 0.5;
    const double u = tu + o * au, v = tv + o * av;
    double value = bilinear(tex.levels[l0], u * s0 - 0.5, v * s0 - 0.5);
    if (f > 1e-3 && l1 != l0)
      value += f * (bilinear(tex.levels[l1], u * s1 - 0.5, v * s1 - 0.5) - value);
    sum += value;
  }
  return sum / taps;
}

double shade(const Quad& q, const Eigen::Vector2d& uv, const Eigen::Vector3d& dX_dx,
             const Eigen::Vector3d& dX_dy, int max_anisotropy) {
  const double tpm = q.texture.texels_per_metre;
  const double albedo =
      sample_texture(q.texture, uv.x() * tpm, uv.y() * tpm, dX_dx.dot(q.u_axis) * tpm,
                     dX_dx.dot(q.v_axis) * tpm, dX_dy.dot(q.u_axis) * tpm,
                     dX_dy.dot(q.v_axis) * tpm, max_anisotropy);
  const double lpm = q.lightmap_per_metre;
  const double light = bilinear(q.lightmap, uv.x() * lpm - 0.5, uv.y() * lpm - 0.5);
  return albedo * light;
}

bool quad_plane(const Scene& scene, int index, const Eigen::Vector3d& centre, QuadRaster* r) {
  const Quad& q = scene.quads[index];
  r->index = index;
  r->a = q.normal_axis();
  r->plane = q.origin[r->a];
  if (q.normal[r->a] * (centre[r->a] - r->plane) <= 1e-9) return false;
  q.u_axis.cwiseAbs().maxCoeff(&r->iu);
  q.v_axis.cwiseAbs().maxCoeff(&r->iv);
  const Eigen::Vector3d far = q.point(q.size_u, q.size_v);
  r->lo_u = std::min(q.origin[r->iu], far[r->iu]);
  r->hi_u = std::max(q.origin[r->iu], far[r->iu]);
  r->lo_v = std::min(q.origin[r->iv], far[r->iv]);
  r->hi_v = std::max(q.origin[r->iv], far[r->iv]);
  return true;
}

}  // namespace render
}  // namespace hybrid_vo
