#include "route.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hybrid_vo {
namespace render {
namespace {

constexpr double kPi = 3.14159265358979323846;

}  // namespace

std::vector<RoutePiece> route_pieces(const Scene& scene) {
  const std::vector<Eigen::Vector2d>& p = scene.route;
  const int n = static_cast<int>(p.size());
  if (n < 3) throw std::invalid_argument("render path: the scene has no route");
  const double r = scene.route_corner_radius;
  std::vector<double> trim(n, 0.0);
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d d_in = (p[i] - p[(i + n - 1) % n]).normalized();
    const Eigen::Vector2d d_out = (p[(i + 1) % n] - p[i]).normalized();
    const double turn = d_in.x() * d_out.y() - d_in.y() * d_out.x();
    if (std::abs(turn) > 1e-9) {
      if (std::abs(d_in.dot(d_out)) > 1e-9)
        throw std::invalid_argument("render path: route corners must be right angles");
      trim[i] = r;
    }
  }
  std::vector<RoutePiece> pieces;
  for (int i = 0; i < n; ++i) {
    const int j = (i + 1) % n;
    const Eigen::Vector2d d = (p[j] - p[i]).normalized();
    RoutePiece line;
    line.start = p[i] + trim[i] * d;
    line.dir = d;
    line.length = (p[j] - p[i]).norm() - trim[i] - trim[j];
    if (line.length < 0.0) throw std::invalid_argument("render path: route edge too short");
    pieces.push_back(line);
    if (trim[j] > 0.0) {
      RoutePiece arc;
      arc.arc = true;
      arc.d_in = d;
      arc.d_out = (p[(j + 1) % n] - p[j]).normalized();
      arc.radius = r;
      arc.centre = p[j] - r * arc.d_in + r * arc.d_out;
      arc.length = 0.5 * kPi * r;
      pieces.push_back(arc);
    }
  }
  return pieces;
}

void point_on_route(const std::vector<RoutePiece>& pieces, double total, double s,
                    Eigen::Vector2d* pos, Eigen::Vector2d* tangent) {
  s = std::fmod(s, total);
  if (s < 0.0) s += total;
  for (const RoutePiece& piece : pieces) {
    if (s > piece.length && &piece != &pieces.back()) {
      s -= piece.length;
      continue;
    }
    s = std::min(s, piece.length);
    if (!piece.arc) {
      *pos = piece.start + s * piece.dir;
      *tangent = piece.dir;
    } else {
      const double t = s / piece.radius;
      *pos = piece.centre + piece.radius * (-piece.d_out * std::cos(t) + piece.d_in * std::sin(t));
      *tangent = piece.d_out * std::sin(t) + piece.d_in * std::cos(t);
    }
    return;
  }
}

double route_length(const std::vector<RoutePiece>& pieces) {
  double total = 0.0;
  for (const RoutePiece& piece : pieces) total += piece.length;
  return total;
}

}  // namespace render
}  // namespace hybrid_vo
