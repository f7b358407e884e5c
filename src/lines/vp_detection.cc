#include "hybrid_vo/lines/vp_detection.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <random>

#include <Eigen/Eigenvalues>
#include <ceres/ceres.h>

#include "hybrid_vo/geometry/vp_distance.h"

namespace hybrid_vo {
namespace {

constexpr double kDegree = M_PI / 180.0;

// One segment per view (one view for single-image detection, two for a segment match).
struct Item {
  int index = -1;                        // into the caller's list
  std::array<Eigen::Vector3d, 2> line;   // unit line in normalised coordinates (K^T l)
  std::array<Eigen::Vector3d, 2> l_px;   // p1 x p2 in pixels, for Tardif's distance
  std::array<Eigen::Vector2d, 2> mid;    // midpoint in pixels
  std::array<Eigen::Vector2d, 2> dir_n;  // p2 - p1 in normalised coordinates
  std::array<Eigen::Vector2d, 2> mid_n;  // midpoint in normalised coordinates
  double length = 0.0;                   // summed over the views, pixels
};

struct Model {
  std::array<Eigen::Vector3d, 2> d;  // unit directions (camera frames)
  std::vector<int> inliers;          // indices into the item list
  double score = 0.0;
};

// Ceres residual: Tardif's distance in pixels of a segment to the VP K d, d on the sphere.
class TardifCost final : public ceres::SizedCostFunction<1, 3> {
 public:
  TardifCost(const Eigen::Matrix3d& K, const Eigen::Vector3d& l, const Eigen::Vector2d& m)
      : K_(K), l_(l), m_(m) {}
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Vector3d> d(parameters[0]);
    Eigen::Vector3d dr_dv;
    if (!tardif_distance(l_, m_, K_ * d, residuals, jacobians ? &dr_dv : nullptr)) {
      residuals[0] = 0.0;
      dr_dv.setZero();
    }
    if (jacobians && jacobians[0]) {
      Eigen::Map<Eigen::RowVector3d> J(jacobians[0]);
      J = dr_dv.transpose() * K_;
    }
    return true;
  }

 private:
  Eigen::Matrix3d K_;
  Eigen::Vector3d l_;
  Eigen::Vector2d m_;
};

class VpFitter {
 public:
  VpFitter(const std::vector<PinholeCamera>& cameras, std::vector<Item> items,
           const VpDetectionOptions& options)
      : cameras_(cameras), views_(static_cast<int>(cameras.size())), items_(std::move(items)),
        options_(options), rng_(options.seed) {}

  std::vector<Model> fit() {
    std::vector<Model> models;
    std::vector<int> active(items_.size());
    std::iota(active.begin(), active.end(), 0);
    while (static_cast<int>(models.size()) < options_.max_vps &&
           static_cast<int>(active.size()) >= std::max(2, min_count())) {
      Model model;
      if (!ransac(active, &model)) break;
      const std::vector<int> drawn = model.inliers;
      // Refit on the inliers and take the inliers again: the minimal sample is noisy.
      for (int round = 0; round < 2; ++round) {
        if (!fit_directions(model.inliers, &model)) break;
        model.inliers = inliers_of(model, active);
      }
      // A refit can keep none of the hypothesis' items (three segments of a loose pencil whose
      // length-weighted direction misses each of them). They leave the active set all the same:
      // left in it, they would be drawn again, and again, forever.
      std::vector<char> taken(items_.size(), 0);
      for (int i : model.inliers.empty() ? drawn : model.inliers) taken[i] = 1;
      active.erase(std::remove_if(active.begin(), active.end(), [&](int i) { return taken[i]; }),
                   active.end());
      if (!enough(model.inliers)) continue;
      if (options_.manhattan && !orthogonal_to_all(model, models)) continue;
      models.push_back(model);
    }
    merge_duplicates(&models);
    reassign(&models);
    if (options_.refine)
      for (Model& m : models) refine(&m);
    for (Model& m : models) m.score = score_of(m.inliers);
    std::sort(models.begin(), models.end(),
              [](const Model& a, const Model& b) { return a.score > b.score; });
    return models;
  }

  const std::vector<Item>& items() const { return items_; }

  // Enough evidence for a VP: min_inliers segments, or min_long_inliers of min_support_px in all
  // per image.
  bool enough(const std::vector<int>& inliers) const {
    const int count = static_cast<int>(inliers.size());
    if (count >= options_.min_inliers) return true;
    return options_.min_long_inliers > 0 && count >= std::max(2, options_.min_long_inliers) &&
           score_of(inliers) >= options_.min_support_px * views_;
  }
  int min_count() const {
    return options_.min_long_inliers > 0 ? std::min(options_.min_inliers, options_.min_long_inliers)
                                         : options_.min_inliers;
  }

  // Distance of item i to the model: the worse view.
  double distance(const Model& m, int i) const {
    double worst = 0.0;
    for (int k = 0; k < views_; ++k) {
      double r;
      if (!tardif_distance(items_[i].l_px[k], items_[i].mid[k], K(k) * m.d[k], &r))
        return INFINITY;
      worst = std::max(worst, std::abs(r));
    }
    return worst;
  }

 private:
  Eigen::Matrix3d K(int view) const { return cameras_[view].K(); }

  std::vector<int> inliers_of(const Model& m, const std::vector<int>& candidates) const {
    std::vector<int> inliers;
    for (int i : candidates)
      if (distance(m, i) < options_.inlier_threshold_px) inliers.push_back(i);
    return inliers;
  }

  double score_of(const std::vector<int>& inliers) const {
    double s = 0.0;
    for (int i : inliers) s += items_[i].length;
    return s;
  }

  // Best hypothesis from pairs of active items, with the usual adaptive number of draws.
  bool ransac(const std::vector<int>& active, Model* best) {
    const int n = static_cast<int>(active.size());
    std::uniform_int_distribution<int> pick(0, n - 1);
    int best_count = 0;
    double needed = options_.max_iterations;
    for (int it = 0; it < options_.max_iterations && it < needed; ++it) {
      const int a = active[pick(rng_)], b = active[pick(rng_)];
      if (a == b) continue;
      Model m;
      bool ok = true;
      for (int k = 0; k < views_ && ok; ++k) {
        m.d[k] = items_[a].line[k].cross(items_[b].line[k]);
        const double norm = m.d[k].norm();
        ok = norm > 1e-9;
        if (ok) m.d[k] /= norm;
      }
      if (!ok) continue;
      m.inliers = inliers_of(m, active);
      const int count = static_cast<int>(m.inliers.size());
      if (count <= best_count) continue;
      best_count = count;
      *best = std::move(m);
      const double w = static_cast<double>(count) / n;
      const double miss = 1.0 - w * w;
      needed = miss <= 0.0 ? 0.0 : std::log(1.0 - options_.confidence) / std::log(miss);
    }
    return best_count >= 2;
  }

  // Least-squares direction per view: the unit d minimising sum w (l . d)^2 over the inliers'
  // normalised lines, weighted by segment length.
  bool fit_directions(const std::vector<int>& inliers, Model* m) const {
    if (inliers.size() < 2) return false;
    for (int k = 0; k < views_; ++k) {
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
      for (int i : inliers) M += items_[i].length * items_[i].line[k] * items_[i].line[k].transpose();
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(M);
      if (eig.info() != Eigen::Success) return false;
      const Eigen::Vector3d d = eig.eigenvectors().col(0);
      // Keep the sign so that repeated fits do not flip the model.
      m->d[k] = d.dot(m->d[k]) < 0.0 ? Eigen::Vector3d(-d) : d;
    }
    return true;
  }

  bool orthogonal_to_all(const Model& m, const std::vector<Model>& models) const {
    const double max_cos = std::sin(options_.manhattan_tolerance_deg * kDegree);
    for (const Model& other : models)
      for (int k = 0; k < views_; ++k)
        if (std::abs(m.d[k].dot(other.d[k])) > max_cos) return false;
    return true;
  }

  // Near-duplicates in every view are one VP: merge them. A VP that repeats another only in
  // some view pairs one 3D direction with two (typically wrong matches between two pencils):
  // the weaker one goes.
  void merge_duplicates(std::vector<Model>* models) const {
    const double min_cos = std::cos(options_.merge_angle_deg * kDegree);
    for (Model& m : *models) m.score = score_of(m.inliers);
    std::sort(models->begin(), models->end(),
              [](const Model& a, const Model& b) { return a.score > b.score; });
    for (size_t a = 0; a < models->size(); ++a) {
      for (size_t b = a + 1; b < models->size();) {
        int same = 0;
        for (int k = 0; k < views_; ++k)
          same += std::abs((*models)[a].d[k].dot((*models)[b].d[k])) >= min_cos;
        if (same == 0) {
          ++b;
          continue;
        }
        if (same == views_) {
          Model& keep = (*models)[a];
          keep.inliers.insert(keep.inliers.end(), (*models)[b].inliers.begin(),
                              (*models)[b].inliers.end());
          fit_directions(keep.inliers, &keep);
        }
        models->erase(models->begin() + b);
      }
    }
  }

  // Every item to its closest VP within the threshold, then a refit: sequential RANSAC hands
  // items at the intersection of two VPs' pencils to whichever came first.
  void reassign(std::vector<Model>* models) const {
    for (int round = 0; round < 2; ++round) {
      for (Model& m : *models) m.inliers.clear();
      for (int i = 0; i < static_cast<int>(items_.size()); ++i) {
        int best = -1;
        double best_distance = options_.inlier_threshold_px;
        for (int v = 0; v < static_cast<int>(models->size()); ++v) {
          const double dist = distance((*models)[v], i);
          if (dist < best_distance) best_distance = dist, best = v;
        }
        if (best >= 0) (*models)[best].inliers.push_back(i);
      }
      for (Model& m : *models) fit_directions(m.inliers, &m);
    }
    models->erase(std::remove_if(models->begin(), models->end(),
                                 [this](const Model& m) { return !enough(m.inliers); }),
                  models->end());
  }

  // Levenberg-Marquardt on the summed squared Tardif distances of the inliers, jointly over the
  // views (the paper's Sec. 3 refinement).
  void refine(Model* m) const {
    ceres::Problem problem;
    for (int k = 0; k < views_; ++k) {
      problem.AddParameterBlock(m->d[k].data(), 3, new ceres::SphereManifold<3>);
      for (int i : m->inliers)
        problem.AddResidualBlock(new TardifCost(K(k), items_[i].l_px[k], items_[i].mid[k]),
                                 nullptr, m->d[k].data());
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.max_num_iterations = 20;
    options.logging_type = ceres::SILENT;
    options.num_threads = 1;
    ceres::Solver::Summary summary;
    const std::array<Eigen::Vector3d, 2> before = m->d;
    ceres::Solve(options, &problem, &summary);
    for (int k = 0; k < views_; ++k) {
      if (!summary.IsSolutionUsable() || !all_finite(m->d[k]) || !(m->d[k].norm() > 0.0))
        m->d[k] = before[k];
      m->d[k].normalize();
    }
  }

  std::vector<PinholeCamera> cameras_;
  int views_;
  std::vector<Item> items_;
  VpDetectionOptions options_;
  std::mt19937_64 rng_;
};

// True when the segments of a view span at least two image directions. With a single family of
// parallel segments nothing can be verified (every pair meets at the same point at infinity), so
// the input is treated as degenerate rather than reported as one VP.
bool spans_two_directions(const std::vector<Item>& items, int view) {
  constexpr double kMinSin = 0.087;  // 5 degrees
  if (items.empty()) return false;
  const Eigen::Vector2d first = items.front().dir_n[view].normalized();
  for (const Item& item : items) {
    const Eigen::Vector2d d = item.dir_n[view].normalized();
    if (std::abs(first.x() * d.y() - first.y() * d.x()) > kMinSin) return true;
  }
  return false;
}

bool make_view(const PinholeCamera& camera, const LineSegment& s, double min_length, Item* item,
               int view) {
  if (!all_finite(s.p1) || !all_finite(s.p2) || !(s.length() >= min_length)) return false;
  const Eigen::Vector2d a = camera.normalize(s.p1), b = camera.normalize(s.p2);
  const Eigen::Vector3d l = homogeneous(a).cross(homogeneous(b));
  if (!(l.norm() > 0.0)) return false;
  item->line[view] = l.normalized();
  item->l_px[view] = s.line();
  item->mid[view] = s.midpoint();
  item->dir_n[view] = b - a;
  item->mid_n[view] = 0.5 * (a + b);
  item->length += s.length();
  return true;
}

// +1 when segment p1 -> p2 runs towards the image of +d (the projection of X + lambda d moves
// along d_xy - d_z m for a point in front), -1 when away from it.
int orientation(const Item& item, int view, const Eigen::Vector3d& d) {
  const Eigen::Vector2d towards = d.head<2>() - d.z() * item.mid_n[view];
  return item.dir_n[view].dot(towards) >= 0.0 ? 1 : -1;
}

// Orients each direction towards where most of its segments point, and says whether the
// segments agree across the views (then d2 = +R d1).
bool orient(const std::vector<Item>& items, const std::vector<int>& inliers, int views,
            double agreement, std::array<Eigen::Vector3d, 2>* d) {
  for (int k = 0; k < views; ++k) {
    int votes = 0;
    for (int i : inliers) votes += orientation(items[i], k, (*d)[k]);
    if (votes < 0) (*d)[k] = -(*d)[k];
  }
  if (views < 2 || inliers.empty()) return false;
  int agree = 0;
  for (int i : inliers) agree += orientation(items[i], 0, (*d)[0]) == orientation(items[i], 1, (*d)[1]);
  return agree >= agreement * inliers.size();
}

MatchedVps to_matches(const VpFitter& fitter, const std::vector<Model>& models, size_t num_lines,
                      const VpDetectionOptions& options) {
  MatchedVps out;
  out.labels.assign(num_lines, -1);
  for (const Model& m : models) {
    std::array<Eigen::Vector3d, 2> d = m.d;
    const bool sign_known = orient(fitter.items(), m.inliers, 2, options.sign_agreement, &d);
    std::vector<int> lines;
    for (int i : m.inliers) {
      lines.push_back(fitter.items()[i].index);
      out.labels[fitter.items()[i].index] = static_cast<int>(out.matches.size());
    }
    out.matches.push_back({d[0], d[1], sign_known});
    out.inliers.push_back(lines);
    out.scores.push_back(m.score);
  }
  return out;
}

}  // namespace

SingleImageVps detect_vanishing_points(const PinholeCamera& camera,
                                       const std::vector<LineSegment>& segments,
                                       const VpDetectionOptions& options) {
  SingleImageVps out;
  out.labels.assign(segments.size(), -1);
  if (!camera.valid()) return out;
  std::vector<Item> items;
  for (int i = 0; i < static_cast<int>(segments.size()); ++i) {
    Item item;
    item.index = i;
    if (make_view(camera, segments[i], options.min_segment_length_px, &item, 0))
      items.push_back(item);
  }
  if (!spans_two_directions(items, 0)) return out;
  VpFitter fitter({camera}, std::move(items), options);
  const std::vector<Model> models = fitter.fit();
  for (const Model& m : models) {
    ImageVp vp;
    std::array<Eigen::Vector3d, 2> d = m.d;
    orient(fitter.items(), m.inliers, 1, options.sign_agreement, &d);
    vp.direction = d[0];
    vp.score = m.score;
    for (int i : m.inliers) {
      vp.inliers.push_back(fitter.items()[i].index);
      out.labels[fitter.items()[i].index] = static_cast<int>(out.vps.size());
    }
    out.vps.push_back(vp);
  }
  return out;
}

MatchedVps detect_vanishing_points_joint(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                         const std::vector<LineMatch>& lines,
                                         const VpDetectionOptions& options) {
  if (!camera1.valid() || !camera2.valid()) {
    MatchedVps empty;
    empty.labels.assign(lines.size(), -1);
    return empty;
  }
  std::vector<Item> items;
  for (int i = 0; i < static_cast<int>(lines.size()); ++i) {
    Item item;
    item.index = i;
    if (make_view(camera1, lines[i].s1, options.min_segment_length_px, &item, 0) &&
        make_view(camera2, lines[i].s2, options.min_segment_length_px, &item, 1))
      items.push_back(item);
  }
  if (!spans_two_directions(items, 0) || !spans_two_directions(items, 1)) {
    MatchedVps empty;
    empty.labels.assign(lines.size(), -1);
    return empty;
  }
  VpFitter fitter({camera1, camera2}, std::move(items), options);
  const std::vector<Model> models = fitter.fit();
  return to_matches(fitter, models, lines.size(), options);
}

MatchedVps detect_vanishing_points_standard(const PinholeCamera& camera1,
                                            const PinholeCamera& camera2,
                                            const std::vector<LineMatch>& lines,
                                            const VpDetectionOptions& options) {
  MatchedVps out;
  out.labels.assign(lines.size(), -1);
  std::vector<LineSegment> s1, s2;
  for (const LineMatch& m : lines) {
    s1.push_back(m.s1);
    s2.push_back(m.s2);
  }
  const SingleImageVps a = detect_vanishing_points(camera1, s1, options);
  const SingleImageVps b = detect_vanishing_points(camera2, s2, options);
  // Match greedily by the number of line matches joining two VPs.
  std::vector<std::vector<int>> joint(a.vps.size(), std::vector<int>(b.vps.size(), 0));
  for (size_t i = 0; i < lines.size(); ++i)
    if (a.labels[i] >= 0 && b.labels[i] >= 0) joint[a.labels[i]][b.labels[i]]++;
  std::vector<char> used_a(a.vps.size(), 0), used_b(b.vps.size(), 0);
  for (;;) {
    int best = options.min_inliers - 1, ba = -1, bb = -1;
    for (size_t i = 0; i < a.vps.size(); ++i)
      for (size_t j = 0; j < b.vps.size(); ++j)
        if (!used_a[i] && !used_b[j] && joint[i][j] > best) best = joint[i][j], ba = i, bb = j;
    if (ba < 0) break;
    used_a[ba] = used_b[bb] = 1;
    std::vector<int> members;
    for (size_t i = 0; i < lines.size(); ++i)
      if (a.labels[i] == ba && b.labels[i] == bb) members.push_back(static_cast<int>(i));
    // Each image's VP was oriented on its own segments; agreement of the joint members tells
    // whether the signs correspond.
    int agree = 0, total = 0;
    for (int i : members) {
      Item item;
      if (!make_view(camera1, lines[i].s1, 0.0, &item, 0) ||
          !make_view(camera2, lines[i].s2, 0.0, &item, 1))
        continue;
      ++total;
      agree += orientation(item, 0, a.vps[ba].direction) == orientation(item, 1, b.vps[bb].direction);
    }
    const bool sign_known = total > 0 && agree >= options.sign_agreement * total;
    for (int i : members) out.labels[i] = static_cast<int>(out.matches.size());
    out.matches.push_back({a.vps[ba].direction, b.vps[bb].direction, sign_known});
    out.inliers.push_back(members);
    out.scores.push_back(a.vps[ba].score + b.vps[bb].score);
  }
  return out;
}

}  // namespace hybrid_vo
