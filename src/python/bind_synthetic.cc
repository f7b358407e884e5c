// hybrid_vo.synthetic: the C++ generators of random minimal instances and Manhattan two-view
// scenes, so that Python tests and benchmarks run on exactly the data the C++ ones use.
#include <random>

#include "bindings.h"
#include "hybrid_vo/synthetic/manhattan_scene.h"
#include "hybrid_vo/synthetic/minimal_instances.h"
#include "options.h"

namespace hybrid_vo {
namespace python {
namespace {

using namespace pybind11::literals;

uint64_t seed_argument(py::handle value) {
  uint64_t seed = 0;
  read_option(value, "seed", Bounds(), &seed);
  return seed;
}

// The inputs of the solver's own function, by its parameter names.
py::dict solver_inputs(const SolverInfo& info, const MinimalSample& s) {
  py::dict inputs;
  const int np = info.num_points, nl = info.num_lines, nv = info.num_vps;
  if (np > 0) {
    inputs["x1"] = points_to_array({s.x1.begin(), s.x1.begin() + np});
    inputs["x2"] = points_to_array({s.x2.begin(), s.x2.begin() + np});
  }
  if (nl > 0) {
    inputs["s1"] = segments_to_array({s.s1.begin(), s.s1.begin() + nl});
    inputs["s2"] = segments_to_array({s.s2.begin(), s.s2.begin() + nl});
  }
  if (nv == 1) {
    inputs["v1"] = to_array(s.v1[0]);
    inputs["v2"] = to_array(s.v2[0]);
    inputs["vp_sign_known"] = s.vp_signs_known;
  } else if (nv == 2) {
    inputs["v1"] = directions_to_array({s.v1[0], s.v1[1]});
    inputs["v2"] = directions_to_array({s.v2[0], s.v2[1]});
    inputs["vp_signs_known"] = s.vp_signs_known;
  }
  return inputs;
}

py::dict scene_to_dict(const ManhattanScene& scene) {
  const TwoViewMatches& m = scene.matches;
  std::vector<Eigen::Vector2d> p1, p2;
  std::vector<LineSegment> s1, s2;
  std::vector<Eigen::Vector3d> d1, d2;
  std::vector<char> known;
  for (const PointMatch& p : m.points) p1.push_back(p.x1), p2.push_back(p.x2);
  for (const LineMatch& l : m.lines) s1.push_back(l.s1), s2.push_back(l.s2);
  for (const VpMatch& vp : m.vps)
    d1.push_back(vp.d1), d2.push_back(vp.d2), known.push_back(vp.sign_known);
  py::dict inputs("camera1"_a = camera_to_dict(scene.camera1),
                  "camera2"_a = camera_to_dict(scene.camera2), "points1"_a = points_to_array(p1),
                  "points2"_a = points_to_array(p2), "segments1"_a = segments_to_array(s1),
                  "segments2"_a = segments_to_array(s2));
  if (!m.vps.empty()) {
    inputs["vps"] = py::make_tuple(directions_to_array(d1), directions_to_array(d2));
    inputs["vp_signs_known"] = to_bool_array(known);
    if (!m.line_vp.empty()) inputs["line_vp"] = to_int_array(m.line_vp);
  }
  return py::dict("inputs"_a = inputs, "R"_a = to_array(scene.truth.R),
                  "t"_a = to_array(scene.truth.t), "baseline_m"_a = scene.baseline_m,
                  "directions"_a = to_array(scene.directions),
                  "point_inlier"_a = to_bool_array(scene.point_inlier),
                  "line_inlier"_a = to_bool_array(scene.line_inlier),
                  "line_direction"_a = to_int_array(scene.line_direction));
}

}  // namespace

void bind_synthetic(py::module_& parent) {
  py::module_ m = parent.def_submodule(
      "synthetic",
      "The C++ generators of synthetic data: random minimal problems after the paper's Sec. 5.1 "
      "and\nManhattan two-view scenes (the data of the C++ tests and of "
      "hybrid_vo_bench_estimator).");

  m.def(
      "minimal_instance",
      [](py::handle solver, py::handle seed, const py::kwargs& kwargs) {
        const SolverInfo& info = solver_info(solver_argument(solver, "solver"));
        MinimalInstanceOptions options;
        apply_options(kwargs, &options, "minimal_instance");
        std::mt19937_64 rng(seed_argument(seed));
        const MinimalInstance instance = generate_minimal_instance(info.id, rng, options);
        return py::dict("solver"_a = info.function,
                        "inputs"_a = solver_inputs(info, instance.sample),
                        "R"_a = to_array(instance.truth.R), "t"_a = to_array(instance.truth.t),
                        "extra_x1"_a = points_to_array(instance.extra_x1),
                        "extra_x2"_a = points_to_array(instance.extra_x2));
      },
      "solver"_a, "seed"_a = 0,
      "minimal_instance(solver, seed=0, *, noise=0.0, lines_per_vp=2, orient_vps=False, "
      "scene_spread=1.0, extra_points=0)\n--\n\n"
      "A random minimal problem for `solver` (function name or paper code) from the C++ "
      "generator\n(generate_minimal_instance, seeded by `seed`): a dict with 'inputs' (keyword "
      "arguments of the\nsolver's function: x1, x2, s1, s2, v1, v2, vp_sign_known or "
      "vp_signs_known, in normalised\ncoordinates), the true pose 'R', 't' (unit t) and "
      "'extra_x1', 'extra_x2' (extra_points more\npoint matches). noise is the standard "
      "deviation on every coordinate (normalised units).");

  m.def(
      "manhattan_scenes",
      [](py::handle count, py::handle seed, const py::kwargs& kwargs) {
        int n = 0;
        read_option(count, "count", non_negative(), &n);
        ManhattanSceneOptions options;
        apply_options(kwargs, &options, "manhattan_scenes");
        std::mt19937_64 rng(seed_argument(seed));
        py::list out;
        for (int i = 0; i < n; ++i)
          out.append(scene_to_dict(generate_manhattan_scene(rng, options)));
        return out;
      },
      "count"_a, "seed"_a = 0,
      "manhattan_scenes(count, seed=0, **options)\n--\n\n"
      "`count` two-view scenes of a box-shaped Manhattan world, drawn one after the other from "
      "one\nstd::mt19937_64(seed) as hybrid_vo_bench_estimator does (its scenes for P points "
      "and outlier\nratio r are manhattan_scenes(S, seed + P + int(100 r), num_points=P, "
      "point_outlier_ratio=r,\nline_outlier_ratio=0.3, noise_px=0.5)). Each is a dict with "
      "'inputs' (keyword arguments of\nestimate_relative_pose, in pixels), the truth 'R', 't', "
      "'baseline_m', the Manhattan 'directions'\n(columns, camera 1), and 'point_inlier', "
      "'line_inlier', 'line_direction'. Options are the fields\nof ManhattanSceneOptions "
      "(scene_options() lists them with their defaults).");

  m.def(
      "scene_options", [] { return options_dict(ManhattanSceneOptions()); },
      "scene_options()\n--\n\nThe options of manhattan_scenes with their defaults.");
}

}  // namespace python
}  // namespace hybrid_vo
