// hybrid_vo.synthetic: the C++ generators of random minimal instances and Manhattan two-view
// scenes, so that Python tests and benchmarks run on exactly the data the C++ ones use.
#include <random>

#include "hybrid_vo/synthetic/manhattan_scene.h"
#include "hybrid_vo/synthetic/minimal_instances.h"
#include "options.h"

namespace hybrid_vo::python {
namespace {

using namespace pybind11::literals;

// The inputs of the solver's own function, by its parameter names.
py::dict solver_inputs(const SolverInfo& info, const MinimalSample& s) {
  py::dict inputs;
  const int np = info.num_points, nl = info.num_lines, nv = info.num_vps;
  for (const auto& [name, points] : {std::pair{"x1", &s.x1}, std::pair{"x2", &s.x2}})
    if (np > 0) inputs[name] = rows_to_array<double, 2>(*points, same_row, np);
  for (const auto& [name, lines] : {std::pair{"s1", &s.s1}, std::pair{"s2", &s.s2}})
    if (nl > 0) inputs[name] = rows_to_array<double, 4>(*lines, segment_row, nl);
  for (const auto& [name, vps] : {std::pair{"v1", &s.v1}, std::pair{"v2", &s.v2}})
    if (nv > 0) inputs[name] = nv == 1 ? to_array((*vps)[0]) : rows_to_array<double, 3>(*vps);
  if (nv > 0) inputs[nv == 1 ? "vp_sign_known" : "vp_signs_known"] = s.vp_signs_known;
  return inputs;
}

py::dict scene_to_dict(const ManhattanScene& scene) {
  const TwoViewMatches& m = scene.matches;
  py::dict inputs("camera1"_a = camera_to_dict(scene.camera1),
                  "camera2"_a = camera_to_dict(scene.camera2));
  inputs.attr("update")(matches_to_dict(m));
  if (!m.vps.empty()) {
    inputs.attr("update")(vps_to_dict(m.vps));
    if (!m.line_vp.empty()) inputs["line_vp"] = array_of<int64_t>(m.line_vp);
  }
  return py::dict("inputs"_a = inputs, "R"_a = to_array(scene.truth.R),
                  "t"_a = to_array(scene.truth.t), "baseline_m"_a = scene.baseline_m,
                  "directions"_a = to_array(scene.directions),
                  "point_inlier"_a = array_of<bool>(scene.point_inlier),
                  "line_inlier"_a = array_of<bool>(scene.line_inlier),
                  "line_direction"_a = array_of<int64_t>(scene.line_direction));
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
        std::mt19937_64 rng(integer_option(seed, "seed", Bounds(), 0, UINT64_MAX));
        const MinimalInstance instance = generate_minimal_instance(info.id, rng, options);
        return py::dict("solver"_a = info.function,
                        "inputs"_a = solver_inputs(info, instance.sample),
                        "R"_a = to_array(instance.truth.R), "t"_a = to_array(instance.truth.t),
                        "extra_x1"_a = rows_to_array<double, 2>(instance.extra_x1),
                        "extra_x2"_a = rows_to_array<double, 2>(instance.extra_x2));
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
        std::mt19937_64 rng(integer_option(seed, "seed", Bounds(), 0, UINT64_MAX));
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

}  // namespace hybrid_vo::python
