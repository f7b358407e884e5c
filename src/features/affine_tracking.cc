#include "hybrid_vo/features/affine_tracking.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

namespace hybrid_vo {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Rows = Eigen::Matrix<double, Eigen::Dynamic, 6>;

// Bilinear sample of an 8-bit image at (x, y) in [0, cols - 1) x [0, rows - 1).
inline float bilinear(const cv::Mat& image, float x, float y) {
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const float fx = x - x0, fy = y - y0;
  const uchar* r0 = image.ptr<uchar>(y0) + x0;
  const uchar* r1 = r0 + image.step[0];
  const float top = r0[0] + fx * (r0[1] - r0[0]);
  const float bottom = r1[0] + fx * (r1[1] - r1[0]);
  return top + fy * (bottom - top);
}

// True when every point within (rx, ry) of p can be sampled, with a hundredth of a pixel to
// spare for the rounding of the samples' float coordinates.
bool inside(const cv::Mat& image, const Eigen::Vector2d& p, double rx, double ry) {
  constexpr double kSpare = 0.01;
  return p.x() - rx >= kSpare && p.y() - ry >= kSpare && p.x() + rx < image.cols - 1.0 - kSpare &&
         p.y() + ry < image.rows - 1.0 - kSpare;
}

// A square window of side 2 half + 1 around a point, its pixels row by row.
struct Window {
  explicit Window(int half) : half(half), side(2 * half + 1), size(side * side) {}
  int half, side, size;
};

// One point's template: the window around the feature (zero mean), and the inverse compositional
// steepest-descent rows [gx, gy, gx ox, gx oy, gy ox, gy oy] with their Gauss-Newton matrix,
// both constant over the iterations. Reused from point to point (no allocation per point).
class AffineTemplate {
 public:
  explicit AffineTemplate(const Window& w) : w_(w), values_(w.size), rows_(w.size, 6) {
    t_.resize(static_cast<size_t>(w.side + 2) * (w.side + 2));
  }

  // False for a window without texture.
  bool set(const cv::Mat& from, const Eigen::Vector2d& p) {
    // Samples at integer offsets from p share their bilinear weights.
    const int ext = w_.side + 2;
    const int x0 = static_cast<int>(std::floor(p.x())) - w_.half - 1;
    const int y0 = static_cast<int>(std::floor(p.y())) - w_.half - 1;
    const double fx = p.x() - std::floor(p.x()), fy = p.y() - std::floor(p.y());
    const double w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
    for (int j = 0; j < ext; ++j) {
      const uchar* r0 = from.ptr<uchar>(y0 + j) + x0;
      const uchar* r1 = r0 + from.step[0];
      for (int i = 0; i < ext; ++i)
        t_[j * ext + i] = w00 * r0[i] + w01 * r0[i + 1] + w10 * r1[i] + w11 * r1[i + 1];
    }
    Matrix6d RtR = Matrix6d::Zero();
    Vector6d sum = Vector6d::Zero();
    double mean = 0.0;
    for (int j = 0; j < w_.side; ++j)
      for (int i = 0; i < w_.side; ++i) {
        const int e = (j + 1) * ext + i + 1, k = j * w_.side + i;
        const double gx = 0.5 * (t_[e + 1] - t_[e - 1]), gy = 0.5 * (t_[e + ext] - t_[e - ext]);
        const double ox = i - w_.half, oy = j - w_.half;
        Vector6d r;
        r << gx, gy, gx * ox, gx * oy, gy * ox, gy * oy;
        rows_.row(k) = r.transpose();
        RtR.noalias() += r * r.transpose();
        sum += r;
        values_(k) = t_[e];
        mean += t_[e];
      }
    mean /= w_.size;
    values_.array() -= mean;
    energy_ = values_.squaredNorm();
    if (!(energy_ > 0.0)) return false;
    // The gain and bias are solved in closed form at every step, so the residual is orthogonal
    // to the constant and to the template: the steepest-descent rows are projected onto that
    // complement too ("project out", Baker and Matthews), or the Gauss-Newton matrix ignores how
    // a growing window changes the gain and the steps converge only slowly. With the row mean
    // m and the rows' correlation c with the template, P = R - 1 m - v c and
    // P^T P = R^T R - n m^T m - E c^T c.
    const Vector6d m = sum / w_.size;
    const Vector6d c = rows_.transpose() * values_ / energy_;
    H_ = RtR - w_.size * m * m.transpose() - energy_ * c * c.transpose();
    return true;
  }

  double energy() const { return energy_; }
  const Eigen::VectorXd& values() const { return values_; }
  const Rows& rows() const { return rows_; }
  const Matrix6d& H() const { return H_; }

 private:
  Window w_;
  std::vector<double> t_;
  Eigen::VectorXd values_;
  Rows rows_;
  Matrix6d H_ = Matrix6d::Zero();
  double energy_ = 0.0;
};

// The warp x -> A x + c of the template's window into the other image.
struct Warp {
  Eigen::Matrix2d A = Eigen::Matrix2d::Identity();
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
};

// The residual of the window under a warp, in the template's units after the brightness's gain
// and bias (closed form), and its sum of squares; false when the window leaves the image or
// the gain is implausible.
bool residual(const AffineTemplate& tpl, const Window& win, const cv::Mat& to, const Warp& w,
              Eigen::VectorXd* e, double* cost) {
  // The warped window is a parallelogram: its extent along x and y bounds every sample.
  const double rx = win.half * (std::abs(w.A(0, 0)) + std::abs(w.A(0, 1)));
  const double ry = win.half * (std::abs(w.A(1, 0)) + std::abs(w.A(1, 1)));
  if (!w.A.allFinite() || !w.c.allFinite() || !inside(to, w.c, rx, ry)) return false;
  const float a00 = static_cast<float>(w.A(0, 0)), a10 = static_cast<float>(w.A(1, 0));
  const double* v = tpl.values().data();
  double* out = e->data();
  // The template has zero mean: sum (s - mean) v = sum s v.
  double sum = 0.0, cross = 0.0;
  for (int j = 0; j < win.side; ++j) {
    // Along a row of the window the sample moves by the first column of A.
    const Eigen::Vector2d start = w.A * Eigen::Vector2d(-win.half, j - win.half) + w.c;
    float x = static_cast<float>(start.x()), y = static_cast<float>(start.y());
    for (int i = 0; i < win.side; ++i, x += a00, y += a10, ++out, ++v) {
      const double sample = bilinear(to, x, y);
      *out = sample;
      sum += sample;
      cross += sample * *v;
    }
  }
  const double mean = sum / win.size, gain = cross / tpl.energy();
  if (!(gain > 0.2)) return false;
  e->array() = (e->array() - mean) * (1.0 / gain) - tpl.values().array();
  *cost = e->squaredNorm();
  return true;
}

// Refines one point; false when the refinement leaves the options' limits or the image. Each
// Gauss-Newton step is halved until the residual decreases (an undamped step can oscillate
// between two warps when the window grows by a tenth); where no step decreases it any more,
// the warp is at the minimum.
bool refine_one(const AffineTemplate& tpl, const Eigen::LDLT<Matrix6d>& solver, const Window& win,
                const cv::Mat& to, const Eigen::Vector2d& start,
                const AffineTrackingOptions& options, Eigen::VectorXd* e,
                Eigen::VectorXd* trial_e, Eigen::Vector2d* result) {
  Warp w;
  w.c = start;
  double cost = 0.0;
  if (!residual(tpl, win, to, w, e, &cost)) return false;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    const Vector6d delta = solver.solve(tpl.rows().transpose() * *e);
    // Converged: the step would move the window's centre by less than epsilon (the centre
    // moves by A d: |d| up to the deformation, a few per cent).
    if (delta.head<2>().norm() < options.epsilon_px) break;
    bool descent = false;
    Warp trial;
    double trial_cost = 0.0, scale = 1.0;
    for (int halving = 0; halving < 2 && !descent; ++halving, scale *= 0.5) {
      // W <- W o dW^-1 with dW(x) = (I + D) x + d: A (I + D)^-1 and c - A (I + D)^-1 d.
      Eigen::Matrix2d M;
      M << 1.0 + scale * delta(2), scale * delta(3), scale * delta(4), 1.0 + scale * delta(5);
      if (!(std::abs(M.determinant()) > 1e-3)) continue;
      trial.A = w.A * M.inverse();
      trial.c = w.c - trial.A * (scale * delta.head<2>());
      descent = residual(tpl, win, to, trial, trial_e, &trial_cost) && trial_cost <= cost;
    }
    if (!descent) break;  // at the minimum (or lost: the limits below decide)
    const double step = (trial.c - w.c).norm();
    w = trial;
    e->swap(*trial_e);
    cost = trial_cost;
    if ((w.c - start).norm() > options.max_shift_px ||
        (w.A - Eigen::Matrix2d::Identity()).cwiseAbs().maxCoeff() > options.max_deformation)
      return false;
    if (step < options.epsilon_px) break;
  }
  *result = w.c;
  return true;
}

}  // namespace

std::vector<char> refine_tracks_affine(const cv::Mat& from, const cv::Mat& to,
                                       const std::vector<Eigen::Vector2d>& from_px,
                                       std::vector<Eigen::Vector2d>* to_px,
                                       const AffineTrackingOptions& options) {
  std::vector<char> refined(from_px.size(), 0);
  if (from.empty() || to.empty() || from.type() != CV_8UC1 || to.type() != CV_8UC1 ||
      to_px->size() != from_px.size() || options.window_px < 3)
    return refined;
  const Window win(options.window_px / 2);
  AffineTemplate tpl(win);
  Eigen::VectorXd e(win.size), trial_e(win.size);
  for (size_t i = 0; i < from_px.size(); ++i) {
    const Eigen::Vector2d& p = from_px[i];
    if (!p.allFinite() || !(*to_px)[i].allFinite() || !inside(from, p, win.half + 1, win.half + 1) ||
        !tpl.set(from, p))
      continue;
    const Eigen::LDLT<Matrix6d> solver(tpl.H());
    if (solver.info() != Eigen::Success || !solver.isPositive()) continue;
    Eigen::Vector2d result;
    if (refine_one(tpl, solver, win, to, (*to_px)[i], options, &e, &trial_e, &result)) {
      (*to_px)[i] = result;
      refined[i] = 1;
    }
  }
  return refined;
}

}  // namespace hybrid_vo
