// The minimal solvers (paper Fig. 2) through the dispatcher the hybrid RANSAC uses (the package
// makes one function per solver from the table), the solver table, and pose errors.
#include "hybrid_vo/geometry/epipolar_error.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"
#include "options.h"

namespace hybrid_vo::python {
namespace {

using namespace pybind11::literals;

Eigen::Matrix3d rotation_argument(py::handle value, const char* name) {
  return matrix_argument(value, name, 3, 3);
}

Eigen::Vector3d translation_argument(py::handle value, const char* name) {
  return matrix_argument(value, name, 3, 1).row(0).transpose();
}

// The minimal sample of `info` from its arrays by name (x1, x2, s1, s2, v1, v2), as the C++
// dispatcher takes it: exactly the arrays the solver takes, each with the rows it uses.
MinimalSample read_sample(const SolverInfo& info, const py::kwargs& arrays) {
  MinimalSample sample;
  auto read = [&](const char* name, int count, const char* what, auto* out, auto convert) {
    if (count == 0 && arrays.contains(name))
      throw_value_error(name, std::string(info.function) + " takes no " + what);
    if (count > 0 && !arrays.contains(name))
      throw_value_error(name, "required by " + std::string(info.function));
    if (count == 0) return;
    const auto rows = convert(arrays[name], name, count);
    std::copy(rows.begin(), rows.end(), out->begin());
  };
  read("x1", info.num_points, "points", &sample.x1, points_argument);
  read("x2", info.num_points, "points", &sample.x2, points_argument);
  read("s1", info.num_lines, "segments", &sample.s1, segments_argument);
  read("s2", info.num_lines, "segments", &sample.s2, segments_argument);
  read("v1", info.num_vps, "VPs", &sample.v1, directions_argument);
  read("v2", info.num_vps, "VPs", &sample.v2, directions_argument);
  return sample;
}

}  // namespace

void bind_solvers(py::module_& m) {
  // The solvers' own functions and solve_minimal (python/hybrid_vo/__init__.py makes them): the
  // arrays the solver takes by keyword, and whether the VP signs are known (`sign_keyword`).
  m.def(
      "_solve",
      [](py::handle solver, const std::string& sign_keyword, py::handle known,
         const py::kwargs& arrays) {
        const SolverInfo& info = solver_info(solver_argument(solver, "solver"));
        MinimalSample sample = read_sample(info, arrays);
        sample.vp_signs_known = bool_argument(known, sign_keyword);
        RelativePoses poses;
        solve_minimal(info.id, sample, &poses);
        py::list out;
        for (const RelativePose& pose : poses) out.append(pose_to_tuple(pose));
        return out;
      },
      "_solve(solver, sign_keyword, known, **arrays)\n--\n\nA solver's own function.");

  m.def(
      "solvers",
      [] {
        py::list out;
        for (const SolverInfo& info : solver_table())
          out.append(py::dict(
              "code"_a = info.code, "ascii_code"_a = ascii_code(info), "function"_a = info.function,
              "num_points"_a = info.num_points, "num_lines"_a = info.num_lines,
              "num_vps"_a = info.num_vps, "coplanar"_a = info.coplanar,
              "lines_coplanar"_a = info.lines_coplanar, "orthogonal"_a = info.orthogonal,
              "well_posed"_a = info.well_posed, "inputs"_a = info.inputs));
        return out;
      },
      "solvers()\n--\n\n"
      "The thirteen minimal configurations of the paper's Fig. 2, in its order: a list of dicts "
      "with\n'code' (X-Y-Z: points-lines-VPs, with the orthogonality sign), 'ascii_code' ('p' "
      "for it),\n'function' (the hybrid_vo function), 'num_points', 'num_lines', 'num_vps', "
      "'coplanar',\n'lines_coplanar', 'orthogonal', 'well_posed' (False for 2-2-0) and 'inputs' "
      "(in words).");

  m.def(
      "pose_error_deg",
      [](py::handle R, py::handle t, py::handle R_true, py::handle t_true) {
        const double deg = 180.0 / M_PI;
        return py::make_tuple(
            rotation_error(rotation_argument(R, "R"), rotation_argument(R_true, "R_true")) * deg,
            translation_error(translation_argument(t, "t"),
                              translation_argument(t_true, "t_true")) *
                deg);
      },
      "R"_a, "t"_a, "R_true"_a, "t_true"_a,
      "pose_error_deg(R, t, R_true, t_true)\n--\n\n"
      "Errors of a relative pose against the truth, in degrees: (rotation, translation), the "
      "angle of\nR^T R_true and the angle between the translation directions (90 when exactly "
      "one t is zero).\nThe pose error of the AUC@5/10/20 tables is their maximum. R: 3 x 3, t: "
      "3-vector (any scale).");

  m.def(
      "sampson_errors_px",
      [](py::handle camera1, py::handle camera2, py::handle R, py::handle t, py::handle points1,
         py::handle points2) {
        const PinholeCamera c1 = camera_argument(camera1, "camera1");
        const PinholeCamera c2 = camera_argument(camera2, "camera2");
        const RelativePose pose(rotation_argument(R, "R"), translation_argument(t, "t"));
        std::vector<double> errors;
        for (const PointMatch& m :
             matches_argument<PointMatch>(points1, points2, "points1", "points2", points_argument))
          errors.push_back(sampson_error_px(c1, c2, pose, m.x1, m.x2));
        return array_of<double>(errors);
      },
      "camera1"_a, "camera2"_a, "R"_a, "t"_a, "points1"_a, "points2"_a,
      "sampson_errors_px(camera1, camera2, R, t, points1, points2)\n--\n\n"
      "Sampson error in pixels of every point match (row i of points1 with row i of points2, "
      "N x 2\nundistorted pixels) under the pose X2 = R X1 + t: the point residual that the "
      "estimator scores\nagainst its 1 px threshold. An (N,) array; all NaN when t is zero. "
      "With the true pose it\nmeasures the ground truth; on held-out matches it scores an estimate "
      "(hybrid_vo_eval_pairs\n--held-out).");
}

}  // namespace hybrid_vo::python
