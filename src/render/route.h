#pragma once

// The scene's route as the camera follows it: straight edges joined by quarter circles at its
// rounded right-angle corners, addressed by arc length.

#include <vector>

#include <Eigen/Core>

#include "hybrid_vo/render/scene.h"

namespace hybrid_vo {
namespace render {

// One piece of the rounded route: a straight line, or a quarter circle around `centre`.
struct RoutePiece {
  bool arc = false;
  Eigen::Vector2d start = Eigen::Vector2d::Zero(), dir = Eigen::Vector2d::Zero();  // line
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();                                // arc
  Eigen::Vector2d d_in = Eigen::Vector2d::Zero(), d_out = Eigen::Vector2d::Zero();
  double radius = 0.0, length = 0.0;
};

// Throws std::invalid_argument for a route that is missing, has a corner other than a right
// angle, or an edge too short for its rounded corners.
std::vector<RoutePiece> route_pieces(const Scene& scene);

double route_length(const std::vector<RoutePiece>& pieces);

// Position and unit tangent at arc length s (wrapped onto the loop of length `total`).
void point_on_route(const std::vector<RoutePiece>& pieces, double total, double s,
                    Eigen::Vector2d* pos, Eigen::Vector2d* tangent);

}  // namespace render
}  // namespace hybrid_vo
