#include "hybrid_problem.h"

#include <cmath>

namespace hybrid_vo {
namespace {

void add_to_pool(const HybridProblem& p, const DerivedPoint& d, HybridProblem* out) {
  out->px1.push_back(d.match.x1);
  out->px2.push_back(d.match.x2);
  out->n1.push_back(p.camera1.normalize(d.match.x1));
  out->n2.push_back(p.camera2.normalize(d.match.x2));
  out->origin.push_back(d);
}

}  // namespace

HybridProblem build_hybrid_problem(const PinholeCamera& camera1, const PinholeCamera& camera2,
                                   const TwoViewMatches& matches,
                                   const HybridProblemOptions& options,
                                   std::vector<DerivedPoint>* junctions,
                                   std::vector<DerivedPoint>* endpoints, RejectedInputs* rejected) {
  HybridProblem p;
  p.camera1 = camera1;
  p.camera2 = camera2;
  *rejected = RejectedInputs();

  for (int i = 0; i < static_cast<int>(matches.points.size()); ++i) {
    const PointMatch& m = matches.points[i];
    if (!all_finite(m.x1) || !all_finite(m.x2)) {
      ++rejected->points;
      continue;
    }
    DerivedPoint d;
    d.match = m;
    d.source = PointSource::kPoint;
    d.first = i;
    add_to_pool(p, d, &p);
  }

  const int num_lines = static_cast<int>(matches.lines.size());
  p.s1.resize(num_lines);
  p.s2.resize(num_lines);
  p.line_valid.assign(num_lines, 0);
  for (int i = 0; i < num_lines; ++i) {
    const LineMatch& m = matches.lines[i];
    if (!valid_segment(m.s1) || !valid_segment(m.s2)) {
      ++rejected->lines;
      continue;
    }
    p.line_valid[i] = 1;
    p.s1[i] = LineSegment(camera1.normalize(m.s1.p1), camera1.normalize(m.s1.p2));
    p.s2[i] = LineSegment(camera2.normalize(m.s2.p1), camera2.normalize(m.s2.p2));
  }

  std::vector<int> internal_vp(matches.vps.size(), -1);
  for (int k = 0; options.use_vps && k < static_cast<int>(matches.vps.size()); ++k) {
    const VpMatch& v = matches.vps[k];
    const double n1 = v.d1.norm(), n2 = v.d2.norm();
    if (!all_finite(v.d1) || !all_finite(v.d2) || !(n1 > 0.0) || !(n2 > 0.0)) {
      ++rejected->vps;
      continue;
    }
    internal_vp[k] = p.num_vps();
    p.d1.push_back(v.d1 / n1);
    p.d2.push_back(v.d2 / n2);
    p.vp_sign_known.push_back(v.sign_known);
    p.vp_index.push_back(k);
  }

  // Labels: only for valid lines and valid VPs; labels of another size are ignored as a whole.
  p.line_vp.assign(num_lines, -1);
  p.vp_lines.assign(p.num_vps(), {});
  if (matches.line_vp.size() == matches.lines.size()) {
    for (int i = 0; i < num_lines; ++i) {
      const int label = matches.line_vp[i];
      if (!p.line_valid[i] || label < 0 || label >= static_cast<int>(internal_vp.size()) ||
          internal_vp[label] < 0)
        continue;
      p.line_vp[i] = internal_vp[label];
      p.vp_lines[internal_vp[label]].push_back(i);
    }
  }

  const bool derive = options.use_lines || options.junction_points || options.endpoint_points;
  *junctions = derive ? find_junctions(matches.lines, options.junctions) : std::vector<DerivedPoint>();
  *endpoints = derive ? segment_endpoints(matches.lines) : std::vector<DerivedPoint>();
  p.line_neighbours.assign(num_lines, {});
  p.line_junctions.assign(num_lines, {});
  for (const DerivedPoint& j : *junctions) {
    p.line_neighbours[j.first].push_back(j.second);
    p.line_neighbours[j.second].push_back(j.first);
    const int index = static_cast<int>(p.junction_n1.size());
    p.junction_n1.push_back(camera1.normalize(j.match.x1));
    p.junction_n2.push_back(camera2.normalize(j.match.x2));
    p.junction_px1.push_back(j.match.x1);
    p.junction_px2.push_back(j.match.x2);
    p.junction_lines.emplace_back(j.first, j.second);
    p.line_junctions[j.first].push_back(index);
    p.line_junctions[j.second].push_back(index);
  }
  if (options.junction_points)
    for (const int j : distinct_junctions(*junctions, options.junctions.duplicate_px))
      add_to_pool(p, (*junctions)[j], &p);
  if (options.endpoint_points)
    for (const DerivedPoint& e : *endpoints) add_to_pool(p, e, &p);

  const double max_cos = std::sin(options.orthogonal_tolerance_deg * M_PI / 180.0);
  for (int k = 0; k < p.num_vps(); ++k)
    for (int j = 0; j < p.num_vps(); ++j)
      if (j != k && std::abs(p.d1[k].dot(p.d1[j])) <= max_cos) p.orthogonal_vps.emplace_back(k, j);
  return p;
}

}  // namespace hybrid_vo
