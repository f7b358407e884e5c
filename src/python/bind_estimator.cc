// estimate_relative_pose: the hybrid estimator with VP detection in front (estimate_two_view),
// its options, and its result object.
#include <cstdio>

#include "bindings.h"
#include "hybrid_vo/lines/two_view.h"
#include "options.h"

namespace hybrid_vo {
namespace python {
namespace {

using namespace pybind11::literals;

// The estimate and the VP matches it used (given, or detected in front of the estimator).
struct Estimate {
  TwoViewEstimate two_view;
  std::vector<VpMatch> vps;
  std::vector<int> line_vp;

  const RelativePoseEstimate& est() const { return two_view.estimate; }
  bool ok() const { return est().status == EstimationStatus::kOk; }
};

void read_match_pair(py::handle a, py::handle b, const char* name_a, const char* name_b, int cols,
                     std::vector<MatrixArgument>* out) {
  if (a.is_none() != b.is_none())
    throw_value_error(a.is_none() ? name_a : name_b, std::string("None while ") +
                                                         (a.is_none() ? name_b : name_a) +
                                                         " is given (pass both or neither)");
  if (a.is_none()) return;
  out->emplace_back(a, name_a, cols);
  out->emplace_back(b, name_b, cols);
  if ((*out)[0].rows() != (*out)[1].rows())
    throw_value_error(name_b, std::to_string((*out)[1].rows()) + " rows, but " + name_a + " has " +
                                  std::to_string((*out)[0].rows()));
}

TwoViewMatches read_matches(py::handle points1, py::handle points2, py::handle segments1,
                            py::handle segments2, py::handle vps, py::handle line_vp,
                            py::handle vp_signs_known) {
  TwoViewMatches matches;
  std::vector<MatrixArgument> points, segments;
  read_match_pair(points1, points2, "points1", "points2", 2, &points);
  read_match_pair(segments1, segments2, "segments1", "segments2", 4, &segments);
  if (!points.empty()) {
    matches.points.resize(points[0].rows());
    for (py::ssize_t i = 0; i < points[0].rows(); ++i)
      matches.points[i] = {points[0].point(i), points[1].point(i)};
  }
  if (!segments.empty()) {
    matches.lines.resize(segments[0].rows());
    for (py::ssize_t i = 0; i < segments[0].rows(); ++i)
      matches.lines[i] = {segments[0].segment(i), segments[1].segment(i)};
  }
  if (!vps.is_none()) {
    if (!(py::isinstance<py::tuple>(vps) || py::isinstance<py::list>(vps)) || py::len(vps) != 2)
      throw_value_error("vps", "expected a pair (directions1, directions2) of K x 3 arrays");
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(vps);
    const auto d1 = directions_argument(pair[0], "vps[0]", MatrixArgument::kAnyRows);
    const auto d2 = directions_argument(pair[1], "vps[1]", MatrixArgument::kAnyRows);
    if (d1.size() != d2.size())
      throw_value_error("vps[1]", std::to_string(d2.size()) + " rows, but vps[0] has " +
                                      std::to_string(d1.size()));
    matches.vps.resize(d1.size());
    for (size_t k = 0; k < d1.size(); ++k) matches.vps[k] = {d1[k], d2[k], false};
  }
  if (!vp_signs_known.is_none()) {
    if (vps.is_none()) throw_value_error("vp_signs_known", "given without vps");
    if (PyBool_Check(vp_signs_known.ptr()) ||
        py::isinstance(vp_signs_known, py::module_::import("numpy").attr("bool_"))) {
      const bool known = bool_argument(vp_signs_known, "vp_signs_known");
      for (VpMatch& vp : matches.vps) vp.sign_known = known;
    } else {
      const bool array = py::isinstance<py::array>(vp_signs_known);
      if (!(array && py::reinterpret_borrow<py::array>(vp_signs_known).ndim() == 1) &&
          !py::isinstance<py::list>(vp_signs_known) && !py::isinstance<py::tuple>(vp_signs_known))
        throw_value_error("vp_signs_known", "expected a bool or one bool per VP");
      const py::sequence seq = py::reinterpret_borrow<py::sequence>(vp_signs_known);
      if (py::len(seq) != matches.vps.size())
        throw_value_error("vp_signs_known", std::to_string(py::len(seq)) + " values for " +
                                                std::to_string(matches.vps.size()) + " VPs");
      for (size_t k = 0; k < matches.vps.size(); ++k)
        matches.vps[k].sign_known =
            bool_argument(seq[k], "vp_signs_known[" + std::to_string(k) + "]");
    }
  }
  if (!line_vp.is_none()) {
    if (vps.is_none() || segments.empty())
      throw_value_error("line_vp", "labels segments with VPs: needs segments1/2 and vps");
    matches.line_vp = labels_argument(line_vp, "line_vp");
    if (matches.line_vp.size() != matches.lines.size())
      throw_value_error("line_vp", std::to_string(matches.line_vp.size()) + " labels for " +
                                       std::to_string(matches.lines.size()) + " segments");
    for (size_t i = 0; i < matches.line_vp.size(); ++i) {
      const int k = matches.line_vp[i];
      if (k < -1 || k >= static_cast<int>(matches.vps.size()))
        throw_value_error("line_vp", "label [" + std::to_string(i) + "] = " + std::to_string(k) +
                                         " is neither -1 nor a VP index below " +
                                         std::to_string(matches.vps.size()));
    }
  }
  return matches;
}

Estimate estimate(py::handle camera1, py::handle camera2, py::handle points1, py::handle points2,
                  py::handle segments1, py::handle segments2, py::handle vps, py::handle preset,
                  py::handle line_vp, py::handle vp_signs_known, const py::kwargs& options) {
  const PinholeCamera c1 = camera_argument(camera1, "camera1");
  const PinholeCamera c2 = camera_argument(camera2, "camera2");
  TwoViewOptions two_view_options = preset_two_view_options(preset);
  estimator_option_table().apply(options, &two_view_options, "estimate_relative_pose");
  Estimate out;
  TwoViewMatches matches =
      read_matches(points1, points2, segments1, segments2, vps, line_vp, vp_signs_known);
  {
    py::gil_scoped_release release;
    out.two_view = estimate_two_view(c1, c2, matches, two_view_options);
  }
  if (out.two_view.vps_detected) {
    out.vps = out.two_view.vps.matches;
    out.line_vp = out.two_view.vps.labels;
  } else {
    out.vps = std::move(matches.vps);
    out.line_vp = std::move(matches.line_vp);
  }
  return out;
}

// Derived point matches as rows (x1, y1, x2, y2), and their sources as rows (first, second).
py::array_t<double> derived_points(const std::vector<DerivedPoint>& derived) {
  return rows_to_array<double, 4>(derived, [](const DerivedPoint& d) {
    return Eigen::Vector4d(d.match.x1.x(), d.match.x1.y(), d.match.x2.x(), d.match.x2.y());
  });
}

py::array_t<int64_t> derived_sources(const std::vector<DerivedPoint>& derived) {
  return rows_to_array<int64_t, 2>(derived, [](const DerivedPoint& d) {
    return Eigen::Matrix<int64_t, 2, 1>(d.first, d.second);
  });
}

std::string repr(const Estimate& e) {
  const RelativePoseEstimate& est = e.est();
  char text[256];
  std::snprintf(text, sizeof(text),
                "<RelativePoseEstimate status='%s': %d point, %d junction, %d line, %d VP inliers; "
                "best solver %s; %d iterations; %.2f ms>",
                to_string(est.status), est.num_point_inliers, est.num_junction_inliers,
                est.num_line_inliers, est.num_vp_inliers,
                e.ok() ? solver_info(est.best_solver).function : "-", est.iterations,
                e.two_view.vp_ms + est.total_ms);
  return text;
}

}  // namespace

SolverId solver_argument(py::handle value, const std::string& name) {
  SolverId id;
  if (!py::isinstance<py::str>(value) || !find_solver(py::cast<std::string>(value), &id))
    throw_value_error(name, "unknown solver " + std::string(py::repr(value)) +
                                " (function names or paper codes, hybrid_vo.solvers())");
  return id;
}

void bind_estimator(py::module_& m) {
  py::class_<Estimate>(m, "RelativePoseEstimate",
                       "Result of estimate_relative_pose. The pose maps camera-1 to camera-2 "
                       "coordinates,\nX2 = R X1 + t, with unit t. Masks are NumPy bool arrays "
                       "aligned with the inputs.")
      .def_property_readonly(
          "status", [](const Estimate& e) { return to_string(e.est().status); },
          "'ok', 'invalid input', 'too little data', 'degenerate' or 'no model'.")
      .def_property_readonly("ok", &Estimate::ok, "status == 'ok'.")
      .def_property_readonly(
          "R",
          [](const Estimate& e) -> py::object {
            return e.ok() ? py::object(to_array(e.est().pose.R)) : py::none();
          },
          "3 x 3 rotation, or None when status is not 'ok'.")
      .def_property_readonly(
          "t",
          [](const Estimate& e) -> py::object {
            return e.ok() ? py::object(to_array(e.est().pose.t)) : py::none();
          },
          "Unit translation (3,), or None when status is not 'ok'.")
      .def_property_readonly(
          "covariance",
          [](const Estimate& e) -> py::object {
            if (!e.ok() || !e.est().covariance_valid) return py::none();
            return to_array(e.est().covariance);
          },
          "6 x 6 covariance of [w, t] after the final refinement: w (radians) the left rotation\n"
          "increment R <- exp([w]x) R, t the unit translation (rank 5). None when not "
          "available.")
      .def_property_readonly(
          "point_inliers", [](const Estimate& e) { return to_bool_array(e.est().point_inliers); },
          "Per point match (points1/points2).")
      .def_property_readonly(
          "line_inliers", [](const Estimate& e) { return to_bool_array(e.est().line_inliers); },
          "Per segment match: it meets another at an inlier junction, or agrees "
          "with the rotation\nthrough its VP.")
      .def_property_readonly(
          "vp_inliers", [](const Estimate& e) { return to_bool_array(e.est().vp_inliers); },
          "Per VP match (given, or detected: see vps).")
      .def_property_readonly(
          "junction_inliers",
          [](const Estimate& e) { return to_bool_array(e.est().junction_inliers); },
          "Per junction (see junctions).")
      .def_property_readonly(
          "endpoint_inliers",
          [](const Estimate& e) { return to_bool_array(e.est().endpoint_inliers); },
          "Per segment endpoint match (see endpoints).")
      .def_property_readonly(
          "num_point_inliers", [](const Estimate& e) { return e.est().num_point_inliers; },
          "Number of point inliers.")
      .def_property_readonly(
          "num_line_inliers", [](const Estimate& e) { return e.est().num_line_inliers; },
          "Number of line inliers.")
      .def_property_readonly(
          "num_vp_inliers", [](const Estimate& e) { return e.est().num_vp_inliers; },
          "Number of VP inliers.")
      .def_property_readonly(
          "num_junction_inliers", [](const Estimate& e) { return e.est().num_junction_inliers; },
          "Number of junction inliers.")
      .def_property_readonly(
          "num_endpoint_inliers", [](const Estimate& e) { return e.est().num_endpoint_inliers; },
          "Number of endpoint inliers.")
      .def_property_readonly(
          "junctions", [](const Estimate& e) { return derived_points(e.est().junctions); },
          "J x 4 junction matches in pixels (x1, y1, x2, y2), from segment pairs "
          "that intersect\nin both images.")
      .def_property_readonly(
          "junction_segments", [](const Estimate& e) { return derived_sources(e.est().junctions); },
          "J x 2: the two segment matches of each junction.")
      .def_property_readonly(
          "endpoints", [](const Estimate& e) { return derived_points(e.est().endpoints); },
          "E x 4 endpoint matches in pixels (only with use_endpoint_points).")
      .def_property_readonly(
          "endpoint_segments", [](const Estimate& e) { return derived_sources(e.est().endpoints); },
          "E x 2: segment index and which end (0 or 1).")
      .def_property_readonly(
          "vps",
          [](const Estimate& e) {
            std::vector<Eigen::Vector3d> d1, d2;
            for (const VpMatch& vp : e.vps) d1.push_back(vp.d1), d2.push_back(vp.d2);
            return py::make_tuple(directions_to_array(d1), directions_to_array(d2));
          },
          "(directions1, directions2): the K x 3 VP matches used, given or detected.")
      .def_property_readonly(
          "vp_signs_known",
          [](const Estimate& e) {
            std::vector<char> known;
            for (const VpMatch& vp : e.vps) known.push_back(vp.sign_known);
            return to_bool_array(known);
          },
          "Per VP match: d2 = +R d1 known (else +-R d1).")
      .def_property_readonly(
          "line_vp", [](const Estimate& e) { return to_int_array(e.line_vp); },
          "Per segment match: index of its VP in vps, or -1 (empty without "
          "labels).")
      .def_property_readonly(
          "vps_detected", [](const Estimate& e) { return e.two_view.vps_detected; },
          "True when the VPs were detected from the segments.")
      .def_property_readonly(
          "solver_statistics",
          [](const Estimate& e) {
            py::dict out;
            for (const SolverInfo& info : solver_table()) {
              const SolverStatistics& s = e.est().solvers[static_cast<int>(info.id)];
              out[info.function] = py::dict("code"_a = info.code, "sampled"_a = s.sampled,
                                            "models"_a = s.models, "best"_a = s.best);
            }
            return out;
          },
          "Per solver (function name): its paper code, how often it was drawn ('sampled'), "
          "poses it\nproduced ('models') and how often one became the best model ('best').")
      .def_property_readonly(
          "best_solver",
          [](const Estimate& e) -> py::object {
            if (!e.ok()) return py::none();
            return py::str(solver_info(e.est().best_solver).function);
          },
          "Function name of the solver behind the best model, or None.")
      .def_property_readonly(
          "iterations", [](const Estimate& e) { return e.est().iterations; }, "RANSAC iterations.")
      .def_property_readonly(
          "local_optimizations", [](const Estimate& e) { return e.est().local_optimizations; },
          "Local optimisations of new best models.")
      .def_property_readonly(
          "refined", [](const Estimate& e) { return e.est().refined; },
          "True when the final Ceres refinement was kept.")
      .def_property_readonly(
          "rejected",
          [](const Estimate& e) {
            return py::dict("points"_a = e.est().rejected_points,
                            "lines"_a = e.est().rejected_lines, "vps"_a = e.est().rejected_vps);
          },
          "Inputs skipped as invalid (zero-length segments, ...), per modality.")
      .def_property_readonly(
          "timings",
          [](const Estimate& e) {
            const RelativePoseEstimate& est = e.est();
            return py::dict("vp_detection_ms"_a = e.two_view.vp_ms, "derive_ms"_a = est.derive_ms,
                            "ransac_ms"_a = est.ransac_ms, "refine_ms"_a = est.refine_ms,
                            "estimator_ms"_a = est.total_ms,
                            "total_ms"_a = e.two_view.vp_ms + est.total_ms);
          },
          "Milliseconds: VP detection, derived data (junctions), RANSAC, final refinement, the "
          "whole\nestimator, and VP detection plus estimator.")
      .def("__repr__", &repr, "Status, inliers, best solver, iterations and time in one line.");

  m.def(
      "estimate_relative_pose", &estimate, "camera1"_a, "camera2"_a, "points1"_a, "points2"_a,
      "segments1"_a = py::none(), "segments2"_a = py::none(), "vps"_a = py::none(),
      "preset"_a = "hybrid+junc", py::kw_only(), "line_vp"_a = py::none(),
      "vp_signs_known"_a = py::none(),
      R"doc(estimate_relative_pose(camera1, camera2, points1, points2, segments1=None, segments2=None, vps=None, preset='hybrid+junc', *, line_vp=None, vp_signs_known=None, **options)
--

Relative pose between two calibrated views from point, segment and VP matches: the hybrid
RANSAC over the minimal solvers with Ceres refinement (paper Sec. 4), with VP detection in
front when segments but no VPs are given and a VP solver is enabled.

camera1, camera2: {'fx', 'fy', 'cx', 'cy'[, 'width', 'height']} or (fx, fy, cx, cy).
points1, points2: N x 2 undistorted pixels (float64, C-contiguous), row i of each a match; None
    for none.
segments1, segments2: M x 4 segment matches in pixels (x1, y1, x2, y2); endpoints need not
    correspond.
vps: (directions1, directions2), K x 3 VP matches as directions K^-1 v (any scale, either sign).
    None: detected from the segments (joint two-view detection) when a VP solver is enabled.
preset: '5pc', '5pc+junc', '5pc+4pc', '5pc+4pc+junc', 'hybrid' or 'hybrid+junc' (the paper's
    rows); the options below override it.
line_vp: per segment match, the index of its VP in vps or -1 (labels for the refinement).
vp_signs_known: bool, or one per VP: d2 = +R d1 is known (else both signs are tried).
**options: fields of RelativePoseEstimatorOptions and TwoViewOptions by name, e.g.
    point_threshold_px=1.0, seed=0, min_iterations=150, enabled={'relpose_2vp_2pt': False};
    hybrid_vo.estimator_options() lists every name with its default. Unknown names raise
    ValueError.

Returns a RelativePoseEstimate: R, t (None unless status == 'ok'), covariance, inlier masks per
modality, junctions, the VPs used, per-solver statistics, iterations and timings.
Raises ValueError for malformed input (shapes, dtypes, strides, NaN, unknown options); data the
estimator cannot use gives a status instead.)doc");

  m.def(
      "estimator_options",
      [](py::handle preset) {
        return estimator_option_table().to_dict(preset_two_view_options(preset));
      },
      "preset"_a = "hybrid+junc",
      "estimator_options(preset='hybrid+junc')\n--\n\n"
      "Every keyword option of estimate_relative_pose with its value under `preset`, as a dict. "
      "Names\nfollow the C++ structs: HybridRansacOptions and RelativePoseEstimatorOptions "
      "fields by their own\nnames, JunctionOptions as junctions_*, FinalRefinementOptions as "
      "refinement_*, and the VP\ndetection in front (TwoViewOptions) as detect_vps, "
      "joint_vp_detection and vp_detection_*.\n'enabled' and 'prior' are per solver: pass a dict "
      "{solver: value} or a list in the paper's order.");

  m.def(
      "presets", [] { return preset_names(); },
      "presets()\n--\n\nThe estimator presets (the paper's table rows).");
}

}  // namespace python
}  // namespace hybrid_vo
