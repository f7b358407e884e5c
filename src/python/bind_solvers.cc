// The minimal solvers (paper Fig. 2) through the dispatcher the hybrid RANSAC uses (the package
// makes one function per solver from the table), the solver table, and pose errors.
#include <map>

#include "bindings.h"
#include "hybrid_vo/geometry/epipolar_error.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"

namespace hybrid_vo {
namespace python {
namespace {

using namespace pybind11::literals;

py::list poses_to_list(const RelativePoses& poses) {
  py::list out;
  for (const RelativePose& pose : poses) out.append(pose_to_tuple(pose));
  return out;
}

Eigen::Matrix3d rotation_argument(py::handle value, const char* name) {
  const MatrixArgument a(value, name, 3, 3);
  Eigen::Matrix3d out;
  for (int i = 0; i < 3; ++i) out.row(i) = a.vector3(i).transpose();
  return out;
}

Eigen::Vector3d translation_argument(py::handle value, const char* name) {
  return MatrixArgument(value, name, 3, 1).vector3(0);
}

// The minimal sample of `info` from its arguments by name (x1, x2, s1, s2, v1, v2), as the C++
// dispatcher takes it. For solve_minimal None means "not given"; a solver's own function reads
// None as a bad array.
MinimalSample read_sample(const SolverInfo& info, const std::map<std::string, py::handle>& given,
                          bool none_is_absent) {
  MinimalSample sample;
  auto read = [&](const char* name, int count, auto&& fill) {
    const auto it = given.find(name);
    const bool none = it == given.end() || (none_is_absent && it->second.is_none());
    if (count == 0) {
      if (!none)
        throw_value_error(name, std::string(info.function) + " takes no " +
                                    (name[0] == 'x' ? "points" : name[0] == 's' ? "segments" : "VPs"));
    } else if (none) {
      throw_value_error(name, "required by " + std::string(info.function));
    } else {
      fill(it->second, name, count);
    }
  };
  auto points = [](std::array<Eigen::Vector2d, 5>* out) {
    return [out](py::handle v, const char* name, int n) {
      const MatrixArgument a(v, name, 2, n);
      for (int i = 0; i < n; ++i) (*out)[i] = a.point(i);
    };
  };
  auto segments = [](std::array<LineSegment, 4>* out) {
    return [out](py::handle v, const char* name, int n) {
      const MatrixArgument a(v, name, 4, n);
      for (int i = 0; i < n; ++i) (*out)[i] = a.segment(i);
    };
  };
  auto vps = [](std::array<Eigen::Vector3d, 2>* out) {
    return [out](py::handle v, const char* name, int n) {
      const std::vector<Eigen::Vector3d> d = directions_argument(v, name, n);
      for (int i = 0; i < n; ++i) (*out)[i] = d[i];
    };
  };
  read("x1", info.num_points, points(&sample.x1));
  read("x2", info.num_points, points(&sample.x2));
  read("s1", info.num_lines, segments(&sample.s1));
  read("s2", info.num_lines, segments(&sample.s2));
  read("v1", info.num_vps, vps(&sample.v1));
  read("v2", info.num_vps, vps(&sample.v2));
  return sample;
}

py::list solve(const SolverInfo& info, const MinimalSample& sample) {
  RelativePoses poses;
  solve_minimal(info.id, sample, &poses);
  return poses_to_list(poses);
}

}  // namespace

void bind_solvers(py::module_& m) {
  // The solvers' own functions (python/hybrid_vo/__init__.py makes them from solvers()): their
  // arrays by keyword, None read as a bad array.
  m.def(
      "_solve",
      [](py::handle solver, const std::string& sign_keyword, py::handle known,
         const py::kwargs& arrays) {
        const SolverInfo& info = solver_info(solver_argument(solver, "solver"));
        std::map<std::string, py::handle> given;
        for (const auto& item : arrays) given[py::str(item.first)] = item.second;
        MinimalSample sample = read_sample(info, given, false);
        sample.vp_signs_known = bool_argument(known, sign_keyword);
        return solve(info, sample);
      },
      "_solve(solver, sign_keyword, known, **arrays)\n--\n\nA solver's own function.");

  m.def(
      "solve_minimal",
      [](py::handle solver, py::handle x1, py::handle x2, py::handle s1, py::handle s2,
         py::handle v1, py::handle v2, py::handle known) {
        const SolverInfo& info = solver_info(solver_argument(solver, "solver"));
        MinimalSample sample = read_sample(
            info, {{"x1", x1}, {"x2", x2}, {"s1", s1}, {"s2", s2}, {"v1", v1}, {"v2", v2}}, true);
        sample.vp_signs_known = bool_argument(known, "vp_signs_known");
        return solve(info, sample);
      },
      "solver"_a, "x1"_a = py::none(), "x2"_a = py::none(), "s1"_a = py::none(),
      "s2"_a = py::none(), "v1"_a = py::none(), "v2"_a = py::none(), "vp_signs_known"_a = false,
      "solve_minimal(solver, x1=None, x2=None, s1=None, s2=None, v1=None, v2=None, "
      "vp_signs_known=False)\n--\n\n"
      "Runs the minimal solver `solver` (function name such as 'relpose_1vp_3pt', or paper code "
      "such as\n'3-0-1' or '2-1-1p') through the C++ dispatcher that the hybrid RANSAC uses. "
      "Pass exactly the\ninputs the solver takes (hybrid_vo.solvers() lists them): x1, x2 as "
      "num_points x 2, s1, s2 as\nnum_lines x 4, v1, v2 as num_vps x 3 (or a 3-vector for one "
      "VP). Returns a list of (R, t) like\nthe solver's own function.");

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
            translation_error(translation_argument(t, "t"), translation_argument(t_true, "t_true")) *
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
        const MatrixArgument p1(points1, "points1", 2), p2(points2, "points2", 2);
        if (p1.rows() != p2.rows())
          throw_value_error("points2", std::to_string(p2.rows()) + " rows, but points1 has " +
                                           std::to_string(p1.rows()));
        py::array_t<double> out(p1.rows());
        auto e = out.mutable_unchecked<1>();
        for (py::ssize_t i = 0; i < p1.rows(); ++i)
          e(i) = sampson_error_px(c1, c2, pose, p1.point(i), p2.point(i));
        return out;
      },
      "camera1"_a, "camera2"_a, "R"_a, "t"_a, "points1"_a, "points2"_a,
      "sampson_errors_px(camera1, camera2, R, t, points1, points2)\n--\n\n"
      "Sampson error in pixels of every point match (row i of points1 with row i of points2, "
      "N x 2\nundistorted pixels) under the pose X2 = R X1 + t: the point residual that the "
      "estimator scores\nagainst its 1 px threshold. An (N,) array; all NaN when t is zero. "
      "With the true pose it\nmeasures the ground truth (how far a data set's truth can rank "
      "estimators); on matches an\nestimate did not see it scores the estimate without ground "
      "truth (hybrid_vo_eval_pairs\n--held-out).");
}

}  // namespace python
}  // namespace hybrid_vo
