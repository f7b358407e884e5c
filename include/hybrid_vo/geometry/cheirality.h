#pragma once

#include <Eigen/Core>

#include "hybrid_vo/geometry/homogeneous.h"

namespace hybrid_vo {

// Non-owning view of point and segment matches in normalised image coordinates, used to decide
// which candidate poses put the observed geometry in front of both cameras.
struct MatchView {
  const Eigen::Vector2d* x1 = nullptr;
  const Eigen::Vector2d* x2 = nullptr;
  int num_points = 0;
  const LineSegment* s1 = nullptr;
  const LineSegment* s2 = nullptr;
  int num_segments = 0;
};

// Given R and t up to sign, flips t so that every point match triangulates in front of both
// cameras and every segment endpoint back-projects onto the matched 3D line at positive depth.
// Returns false when no sign of t satisfies all of them. Matches without parallax (or segments
// whose plane contains the baseline) say nothing and are skipped.
bool orient_translation(const Eigen::Matrix3d& R, Eigen::Vector3d* t, const MatchView& matches);

// orient_translation for point matches given as rays in camera 2's frame: r[i] = R x1_i and
// q[i] = x2_i, each up to a positive scale, in any rotated copy of that frame (t in the same copy).
// Solvers that work in a canonical frame decide the sign there, before forming R.
bool orient_translation_rays(const Eigen::Vector3d* r, const Eigen::Vector3d* q, int n,
                             Eigen::Vector3d* t);

// The vote of one point match on the sign of t, for solvers that test many candidate poses and
// share work between them: the match as rays r = R x1 and q = x2 in camera 2's frame (or any
// common rotation of it), each up to a positive scale, given by its dot products rr = r.r,
// qq = q.q, qr = q.r, qt = q.t, rt = r.t and tt = t.t. Returns +1 (in front of both cameras with
// t), -1 (with -t), 0 (no parallax: the match says nothing) or kCheiralityConflict (neither).
// orient_translation and orient_translation_rays combine these votes.
constexpr int kCheiralityConflict = 2;
// Relative size under which a depth counts as infinite (no parallax): its sign is noise. The
// tests compare squares, which spares the square roots.
constexpr double kCheiralityNoParallax2 = 1e-12 * 1e-12;
inline int cheirality_vote(double rr, double qq, double qr, double qt, double rt, double tt) {
  // lambda1 r + t = lambda2 q, so with n = r x q, lambda1 ~ (q x t).n and lambda2 ~ (r x t).n,
  // both / |n|^2. By the Binet-Cauchy identity these are (q.r)(q.t) - (q.q)(r.t) and
  // (r.r)(q.t) - (q.r)(r.t), and |n|^2 = (r.r)(q.q) - (q.r)^2: no cross products.
  const double d1 = qr * qt - qq * rt, d2 = rr * qt - qr * rt;
  const double nn = rr * qq - qr * qr;
  // Each depth relative to |n|^2 |t| |q| |r|.
  const double scale2 = nn * nn * tt * qq * rr;
  if (!(scale2 > 0.0)) return 0;
  if (d1 * d1 < kCheiralityNoParallax2 * scale2 || d2 * d2 < kCheiralityNoParallax2 * scale2)
    return 0;
  if ((d1 > 0.0) != (d2 > 0.0)) return kCheiralityConflict;
  return d1 > 0.0 ? 1 : -1;
}

// The sign the votes so far agree on (0 while none has said anything) combined with one more
// vote; kCheiralityConflict once two disagree.
inline int combine_cheirality_votes(int sign, int vote) {
  if (vote == 0 || sign == kCheiralityConflict) return sign;
  if (vote == kCheiralityConflict) return kCheiralityConflict;
  if (sign == 0) return vote;
  return sign == vote ? sign : kCheiralityConflict;
}

// Same test with a majority vote instead of unanimity, for a model fitted to many noisy matches:
// flips t when more matches lie in front with -t than with t. Returns the margin of votes for the
// chosen sign (0: undecided, t kept).
int orient_translation_by_majority(const Eigen::Matrix3d& R, Eigen::Vector3d* t,
                                   const MatchView& matches);

}  // namespace hybrid_vo
