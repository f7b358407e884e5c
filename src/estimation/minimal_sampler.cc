#include "minimal_sampler.h"

#include <algorithm>

namespace hybrid_vo {

MinimalSampler::MinimalSampler(const HybridProblem& problem, std::mt19937_64* rng)
    : problem_(problem), rng_(rng) {
  for (int i = 0; i < problem.num_lines(); ++i) {
    if (!problem.line_valid[i]) continue;
    valid_lines_.push_back(i);
    const int neighbours = static_cast<int>(problem.line_neighbours[i].size());
    for (int k = 1; k <= 3; ++k)
      if (neighbours >= k) lines_with_neighbours_[k].push_back(i);
  }
  for (const auto& [k, j] : problem.orthogonal_vps) {
    bool any = false, connected = false, points = false;
    for (int line : problem.vp_lines[j]) {
      any = true;
      connected = connected || !problem.line_neighbours[line].empty();
      points = points || problem.line_junctions[line].size() >= 2;
    }
    if (any) orth_with_lines_.emplace_back(k, j);
    if (connected) orth_with_connected_.emplace_back(k, j);
    if (points) orth_with_points_.emplace_back(k, j);
  }
  const int pool = problem.num_pool(), vps = problem.num_vps();
  const int lines = static_cast<int>(valid_lines_.size());
  auto set = [this](SolverId id, bool value) { available_[static_cast<int>(id)] = value; };
  set(SolverId::k5pt, pool >= 5);
  set(SolverId::kHomography4pt, pool >= 4);
  set(SolverId::kHomography3pt1l, pool >= 3 && lines >= 1);
  set(SolverId::kHomography2pt2l, false);  // degenerate for every input
  set(SolverId::kHomography1pt3l, pool >= 1 && !lines_with_neighbours_[2].empty());
  set(SolverId::kHomography4l, !lines_with_neighbours_[3].empty());
  set(SolverId::k2pt3line, pool >= 2 && !lines_with_neighbours_[2].empty());
  set(SolverId::k1vp3pt, vps >= 1 && pool >= 3);
  set(SolverId::k1vp3line, vps >= 1 && !lines_with_neighbours_[2].empty());
  set(SolverId::k2vp2pt, vps >= 2 && pool >= 2);
  set(SolverId::k1vpOrthline2pt, !orth_with_lines_.empty() && pool >= 2);
  set(SolverId::k1vp2line1pt, !orth_with_connected_.empty() && pool >= 1);
  set(SolverId::k1vp2ptOrth, !orth_with_points_.empty());
}

bool MinimalSampler::draw_points(int count, MinimalSample* s, int first_slot) {
  const int n = problem_.num_pool();
  if (n < count) return false;
  int chosen[5];
  for (int k = 0; k < count; ++k) {
    int i;
    do {
      i = uniform(n);
    } while (std::find(chosen, chosen + k, i) != chosen + k);
    chosen[k] = i;
    s->x1[first_slot + k] = problem_.n1[i];
    s->x2[first_slot + k] = problem_.n2[i];
  }
  return true;
}

void MinimalSampler::put_line(int line, int slot, MinimalSample* s) const {
  s->s1[slot] = problem_.s1[line];
  s->s2[slot] = problem_.s2[line];
}

void MinimalSampler::put_vp(int vp, int slot, MinimalSample* s) const {
  s->v1[slot] = problem_.d1[vp];
  s->v2[slot] = problem_.d2[vp];
}

bool MinimalSampler::draw_connected_lines(int count, MinimalSample* s, int exclude_vp) {
  if (count == 1) {
    if (valid_lines_.empty()) return false;
    put_line(valid_lines_[uniform(static_cast<int>(valid_lines_.size()))], 0, s);
    return true;
  }
  const std::vector<int>& seeds = lines_with_neighbours_[count - 1];
  if (seeds.empty()) return false;
  const int a = seeds[uniform(static_cast<int>(seeds.size()))];
  // Lines through the VP meet there, not on a plane: 0-3-1 would see three junctions at the VP.
  if (exclude_vp >= 0 && problem_.line_vp[a] == exclude_vp) return false;
  const std::vector<int>& neighbours = problem_.line_neighbours[a];
  put_line(a, 0, s);
  int chosen[3];
  for (int k = 0; k < count - 1; ++k) {
    int b;
    do {
      b = neighbours[uniform(static_cast<int>(neighbours.size()))];
    } while (std::find(chosen, chosen + k, b) != chosen + k);
    chosen[k] = b;
    put_line(b, k + 1, s);
  }
  return true;
}

bool MinimalSampler::draw(SolverId id, MinimalSample* s) {
  if (!available(id)) return false;
  s->vp_signs_known = false;
  switch (id) {
    case SolverId::k5pt:
      return draw_points(5, s);
    case SolverId::kHomography4pt:
      return draw_points(4, s);
    case SolverId::kHomography3pt1l:
      return draw_points(3, s) && draw_connected_lines(1, s);
    case SolverId::kHomography1pt3l:
      return draw_points(1, s) && draw_connected_lines(3, s);
    case SolverId::kHomography4l:
      return draw_connected_lines(4, s);
    case SolverId::k2pt3line:
      return draw_points(2, s) && draw_connected_lines(3, s);
    case SolverId::k1vp3pt: {
      const int k = uniform(problem_.num_vps());
      put_vp(k, 0, s);
      s->vp_signs_known = problem_.vp_sign_known[k];
      return draw_points(3, s);
    }
    case SolverId::k1vp3line: {
      const int k = uniform(problem_.num_vps());
      put_vp(k, 0, s);
      s->vp_signs_known = problem_.vp_sign_known[k];
      return draw_connected_lines(3, s, k);
    }
    case SolverId::k2vp2pt: {
      const int a = uniform(problem_.num_vps());
      int b = uniform(problem_.num_vps() - 1);
      if (b >= a) ++b;
      put_vp(a, 0, s);
      put_vp(b, 1, s);
      s->vp_signs_known = problem_.vp_sign_known[a] && problem_.vp_sign_known[b];
      return draw_points(2, s);
    }
    case SolverId::k1vpOrthline2pt: {
      const auto [k, j] = orth_with_lines_[uniform(static_cast<int>(orth_with_lines_.size()))];
      const std::vector<int>& cluster = problem_.vp_lines[j];
      put_vp(k, 0, s);
      s->vp_signs_known = problem_.vp_sign_known[k];
      put_line(cluster[uniform(static_cast<int>(cluster.size()))], 0, s);
      return draw_points(2, s);
    }
    case SolverId::k1vp2line1pt: {
      const auto [k, j] =
          orth_with_connected_[uniform(static_cast<int>(orth_with_connected_.size()))];
      const std::vector<int>& cluster = problem_.vp_lines[j];
      const int a = cluster[uniform(static_cast<int>(cluster.size()))];
      const std::vector<int>& neighbours = problem_.line_neighbours[a];
      if (neighbours.empty()) return false;
      put_vp(k, 0, s);
      s->vp_signs_known = problem_.vp_sign_known[k];
      put_line(a, 0, s);
      put_line(neighbours[uniform(static_cast<int>(neighbours.size()))], 1, s);
      return draw_points(1, s);
    }
    case SolverId::k1vp2ptOrth: {
      const auto [k, j] = orth_with_points_[uniform(static_cast<int>(orth_with_points_.size()))];
      const std::vector<int>& cluster = problem_.vp_lines[j];
      const int line = cluster[uniform(static_cast<int>(cluster.size()))];
      // Two junctions on a line of the orthogonal cluster: their joining line is that line.
      const std::vector<int>& on_line = problem_.line_junctions[line];
      if (on_line.size() < 2) return false;
      const int a = uniform(static_cast<int>(on_line.size()));
      int b = uniform(static_cast<int>(on_line.size()) - 1);
      if (b >= a) ++b;
      put_vp(k, 0, s);
      s->vp_signs_known = problem_.vp_sign_known[k];
      for (int slot = 0; slot < 2; ++slot) {
        const int i = on_line[slot == 0 ? a : b];
        s->x1[slot] = problem_.junction_n1[i];
        s->x2[slot] = problem_.junction_n2[i];
      }
      return true;
    }
    case SolverId::kHomography2pt2l:
      return false;
  }
  return false;
}

}  // namespace hybrid_vo
