// The minimal solvers (paper Fig. 2), one Python function per C++ function, plus the dispatcher
// solve_minimal and the solver table.
#include "bindings.h"
#include "hybrid_vo/geometry/epipolar_error.h"
#include "hybrid_vo/geometry/pose_error.h"
#include "hybrid_vo/solvers/minimal_solver.h"
#include "hybrid_vo/solvers/relpose_1vp_2line_1pt.h"
#include "hybrid_vo/solvers/relpose_1vp_2pt_orth.h"
#include "hybrid_vo/solvers/relpose_1vp_3line.h"
#include "hybrid_vo/solvers/relpose_1vp_3pt.h"
#include "hybrid_vo/solvers/relpose_1vp_orthline_2pt.h"
#include "hybrid_vo/solvers/relpose_2pt_3line.h"
#include "hybrid_vo/solvers/relpose_2vp_2pt.h"
#include "hybrid_vo/solvers/relpose_5pt.h"
#include "hybrid_vo/solvers/relpose_homography.h"

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

Eigen::Vector3d vp_argument(py::handle value, const std::string& name) {
  return directions_argument(value, name, 1)[0];
}

std::array<Eigen::Vector3d, 2> two_vps_argument(py::handle value, const std::string& name) {
  const std::vector<Eigen::Vector3d> d = directions_argument(value, name, 2);
  return {d[0], d[1]};
}

// The docstring of a solver: signature, configuration, inputs, and the shared conventions.
std::string solver_doc(SolverId id, const std::string& signature, const std::string& details) {
  const SolverInfo& info = solver_info(id);
  return info.function + signature + "\n--\n\n" + info.code + ": " + info.inputs +
         " (paper Fig. 2).\n\n" + details +
         "\nPoints are normalised image coordinates (K^-1 x) as N x 2 float64 arrays, segments "
         "their two\nendpoints as N x 4 (x1, y1, x2, y2), VPs directions (K^-1 v, any scale) as "
         "3-vectors; index 1\nis the first image, 2 the second. Returns a list of (R, t) with X2 = "
         "R X1 + t and unit t\n(t = 0 for a pure rotation), every real solution with all points "
         "and segments in front of\nboth cameras; an empty list for degenerate input. Raises "
         "ValueError for wrong shapes,\ndtypes, strides or non-finite values.";
}

const char* kVpSign =
    "With vp_sign_known, v2 = +R v1; otherwise the sign v2 = -R v1 is tried too.\n";

// Binds the solver `id` under its C++ name: `solve` reads the Python arguments (named by
// `names`) and runs the C++ function; the docstring comes from solver_doc.
template <typename... Handles, typename... Names>
void def_solver(py::module_& m, SolverId id, const std::string& signature,
                const std::string& details, void (*solve)(RelativePoses*, Handles...),
                Names... names) {
  m.def(
      solver_info(id).function,
      [solve](Handles... arguments) {
        RelativePoses poses;
        solve(&poses, arguments...);
        return poses_to_list(poses);
      },
      names..., solver_doc(id, signature, details).c_str());
}

using H = py::handle;

}  // namespace

void bind_solvers(py::module_& m) {
  def_solver(
      m, SolverId::k5pt, "(x1, x2)",
      "x1, x2: 5 x 2 point matches. Nister's five-point essential matrix, decomposed.\n",
      +[](RelativePoses* p, H x1, H x2) {
        relpose_5pt(points_argument<5>(x1, "x1"), points_argument<5>(x2, "x2"), p);
      },
      "x1"_a, "x2"_a);

  def_solver(
      m, SolverId::kHomography4pt, "(x1, x2)",
      "x1, x2: 4 x 2 matches of coplanar points. Homography by DLT, decomposed.\n",
      +[](RelativePoses* p, H x1, H x2) {
        relpose_homography_4pt(points_argument<4>(x1, "x1"), points_argument<4>(x2, "x2"), p);
      },
      "x1"_a, "x2"_a);

  def_solver(
      m, SolverId::kHomography3pt1l, "(x1, x2, s1, s2)",
      "x1, x2: 3 x 2 point matches; s1, s2: one segment match (1 x 4 or 4,), all on one plane.\n"
      "Lines map as l1 ~ H^T l2; the endpoints need not correspond.\n",
      +[](RelativePoses* p, H x1, H x2, H s1, H s2) {
        relpose_homography_3pt_1line(points_argument<3>(x1, "x1"), points_argument<3>(x2, "x2"),
                                     segments_argument<1>(s1, "s1")[0],
                                     segments_argument<1>(s2, "s2")[0], p);
      },
      "x1"_a, "x2"_a, "s1"_a, "s2"_a);

  def_solver(
      m, SolverId::kHomography2pt2l, "(x1, x2, s1, s2)",
      "x1, x2: 2 x 2 point matches; s1, s2: 2 x 4 segment matches, coplanar.\n"
      "Degenerate for every input (a one-parameter family of homographies fits; README): it "
      "always\nreturns an empty list, and is listed for completeness.\n",
      +[](RelativePoses* p, H x1, H x2, H s1, H s2) {
        relpose_homography_2pt_2line(points_argument<2>(x1, "x1"), points_argument<2>(x2, "x2"),
                                     segments_argument<2>(s1, "s1"), segments_argument<2>(s2, "s2"),
                                     p);
      },
      "x1"_a, "x2"_a, "s1"_a, "s2"_a);

  def_solver(
      m, SolverId::kHomography1pt3l, "(x1, x2, s1, s2)",
      "x1, x2: one point match (1 x 2 or 2,); s1, s2: 3 x 4 segment matches, all on one plane.\n",
      +[](RelativePoses* p, H x1, H x2, H s1, H s2) {
        relpose_homography_1pt_3line(
            points_argument<1>(x1, "x1")[0], points_argument<1>(x2, "x2")[0],
            segments_argument<3>(s1, "s1"), segments_argument<3>(s2, "s2"), p);
      },
      "x1"_a, "x2"_a, "s1"_a, "s2"_a);

  def_solver(
      m, SolverId::kHomography4l, "(s1, s2)", "s1, s2: 4 x 4 matches of coplanar segments.\n",
      +[](RelativePoses* p, H s1, H s2) {
        relpose_homography_4line(segments_argument<4>(s1, "s1"), segments_argument<4>(s2, "s2"), p);
      },
      "s1"_a, "s2"_a);

  def_solver(
      m, SolverId::k2pt3line, "(x1, x2, s1, s2)",
      "x1, x2: 2 x 2 point matches; s1, s2: 3 x 4 matches of coplanar segments, whose three\n"
      "junctions complete five points for the five-point solver.\n",
      +[](RelativePoses* p, H x1, H x2, H s1, H s2) {
        relpose_2pt_3line(points_argument<2>(x1, "x1"), points_argument<2>(x2, "x2"),
                          segments_argument<3>(s1, "s1"), segments_argument<3>(s2, "s2"), p);
      },
      "x1"_a, "x2"_a, "s1"_a, "s2"_a);

  def_solver(
      m, SolverId::k1vp3pt, "(v1, v2, x1, x2, vp_sign_known=False)",
      std::string("v1, v2: one VP match; x1, x2: 3 x 2 point matches. Upright three-point after "
                  "rotating the VP\nonto the y-axis.\n") +
          kVpSign,
      +[](RelativePoses* p, H v1, H v2, H x1, H x2, H known) {
        relpose_1vp_3pt(vp_argument(v1, "v1"), vp_argument(v2, "v2"), points_argument<3>(x1, "x1"),
                        points_argument<3>(x2, "x2"), p, bool_argument(known, "vp_sign_known"));
      },
      "v1"_a, "v2"_a, "x1"_a, "x2"_a, "vp_sign_known"_a = false);

  def_solver(
      m, SolverId::k1vp3line, "(v1, v2, s1, s2, vp_sign_known=False)",
      std::string("v1, v2: one VP match; s1, s2: 3 x 4 matches of coplanar segments (their "
                  "junctions are the\npoints of 3-0-1).\n") +
          kVpSign,
      +[](RelativePoses* p, H v1, H v2, H s1, H s2, H known) {
        relpose_1vp_3line(vp_argument(v1, "v1"), vp_argument(v2, "v2"),
                          segments_argument<3>(s1, "s1"), segments_argument<3>(s2, "s2"), p,
                          bool_argument(known, "vp_sign_known"));
      },
      "v1"_a, "v2"_a, "s1"_a, "s2"_a, "vp_sign_known"_a = false);

  def_solver(
      m, SolverId::k2vp2pt, "(v1, v2, x1, x2, vp_signs_known=False)",
      "v1, v2: two VP matches (2 x 3, row k of v1 matches row k of v2); x1, x2: 2 x 2 point "
      "matches.\nWith vp_signs_known, v2 = +R v1 for both; otherwise every sign is tried.\n",
      +[](RelativePoses* p, H v1, H v2, H x1, H x2, H known) {
        relpose_2vp_2pt(two_vps_argument(v1, "v1"), two_vps_argument(v2, "v2"),
                        points_argument<2>(x1, "x1"), points_argument<2>(x2, "x2"), p,
                        bool_argument(known, "vp_signs_known"));
      },
      "v1"_a, "v2"_a, "x1"_a, "x2"_a, "vp_signs_known"_a = false);

  def_solver(
      m, SolverId::k1vpOrthline2pt, "(v1, v2, s1, s2, x1, x2, vp_sign_known=False)",
      std::string("v1, v2: one VP match; s1, s2: one segment match (1 x 4 or 4,) whose 3D line "
                  "is orthogonal\nto the VP; x1, x2: 2 x 2 point matches.\n") +
          kVpSign,
      +[](RelativePoses* p, H v1, H v2, H s1, H s2, H x1, H x2, H known) {
        relpose_1vp_orthline_2pt(
            vp_argument(v1, "v1"), vp_argument(v2, "v2"), segments_argument<1>(s1, "s1")[0],
            segments_argument<1>(s2, "s2")[0], points_argument<2>(x1, "x1"),
            points_argument<2>(x2, "x2"), p, bool_argument(known, "vp_sign_known"));
      },
      "v1"_a, "v2"_a, "s1"_a, "s2"_a, "x1"_a, "x2"_a, "vp_sign_known"_a = false);

  def_solver(
      m, SolverId::k1vp2line1pt, "(v1, v2, s1, s2, x1, x2, vp_sign_known=False)",
      std::string("v1, v2: one VP match; s1, s2: 2 x 4 matches of intersecting segments, the "
                  "first orthogonal\nto the VP; x1, x2: one point match (1 x 2 or 2,).\n") +
          kVpSign,
      +[](RelativePoses* p, H v1, H v2, H s1, H s2, H x1, H x2, H known) {
        relpose_1vp_2line_1pt(vp_argument(v1, "v1"), vp_argument(v2, "v2"),
                              segments_argument<2>(s1, "s1"), segments_argument<2>(s2, "s2"),
                              points_argument<1>(x1, "x1")[0], points_argument<1>(x2, "x2")[0], p,
                              bool_argument(known, "vp_sign_known"));
      },
      "v1"_a, "v2"_a, "s1"_a, "s2"_a, "x1"_a, "x2"_a, "vp_sign_known"_a = false);

  def_solver(
      m, SolverId::k1vp2ptOrth, "(v1, v2, x1, x2, vp_sign_known=False)",
      std::string("v1, v2: one VP match; x1, x2: 2 x 2 point matches whose 3D points span a line "
                  "orthogonal\nto the VP.\n") +
          kVpSign,
      +[](RelativePoses* p, H v1, H v2, H x1, H x2, H known) {
        relpose_1vp_2pt_orth(vp_argument(v1, "v1"), vp_argument(v2, "v2"),
                             points_argument<2>(x1, "x1"), points_argument<2>(x2, "x2"), p,
                             bool_argument(known, "vp_sign_known"));
      },
      "v1"_a, "v2"_a, "x1"_a, "x2"_a, "vp_sign_known"_a = false);

  m.def(
      "solve_minimal",
      [](py::handle solver, py::handle x1, py::handle x2, py::handle s1, py::handle s2,
         py::handle v1, py::handle v2, py::handle known) {
        const SolverInfo& info = solver_info(solver_argument(solver, "solver"));
        MinimalSample sample;
        auto read = [&](py::handle value, const char* name, int count, auto&& fill) {
          if (count == 0) {
            if (!value.is_none())
              throw_value_error(name, std::string(info.function) + " takes no " +
                                          (name[0] == 'x'   ? "points"
                                           : name[0] == 's' ? "segments"
                                                            : "VPs"));
            return;
          }
          if (value.is_none()) throw_value_error(name, "required by " + std::string(info.function));
          fill(value, count);
        };
        auto points = [&](py::handle value, const char* name, std::array<Eigen::Vector2d, 5>* out) {
          read(value, name, info.num_points, [&](py::handle v, int n) {
            const MatrixArgument a(v, name, 2, n);
            for (int i = 0; i < n; ++i) (*out)[i] = a.point(i);
          });
        };
        auto segments = [&](py::handle value, const char* name, std::array<LineSegment, 4>* out) {
          read(value, name, info.num_lines, [&](py::handle v, int n) {
            const MatrixArgument a(v, name, 4, n);
            for (int i = 0; i < n; ++i) (*out)[i] = a.segment(i);
          });
        };
        auto vps = [&](py::handle value, const char* name, std::array<Eigen::Vector3d, 2>* out) {
          read(value, name, info.num_vps, [&](py::handle v, int n) {
            const std::vector<Eigen::Vector3d> d = directions_argument(v, name, n);
            for (int i = 0; i < n; ++i) (*out)[i] = d[i];
          });
        };
        points(x1, "x1", &sample.x1);
        points(x2, "x2", &sample.x2);
        segments(s1, "s1", &sample.s1);
        segments(s2, "s2", &sample.s2);
        vps(v1, "v1", &sample.v1);
        vps(v2, "v2", &sample.v2);
        sample.vp_signs_known = bool_argument(known, "vp_signs_known");
        RelativePoses poses;
        solve_minimal(info.id, sample, &poses);
        return poses_to_list(poses);
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
