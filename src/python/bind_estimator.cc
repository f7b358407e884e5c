// estimate_relative_pose: the hybrid estimator with VP detection in front (estimate_two_view),
// its options, and its result object.
#include "hybrid_vo/lines/two_view.h"
#include "options.h"

namespace hybrid_vo::python {
namespace {

using namespace pybind11::literals;

// Per VP match whether d2 = +R d1 is known: one bool for all, or one each.
void read_vp_signs_known(py::handle value, std::vector<VpMatch>* vps) {
  if (PyBool_Check(value.ptr()) ||
      py::isinstance(value, py::module_::import("numpy").attr("bool_"))) {
    for (VpMatch& vp : *vps) vp.sign_known = bool_argument(value, "vp_signs_known");
    return;
  }
  const bool array = py::isinstance<py::array>(value);
  if (!(array && py::reinterpret_borrow<py::array>(value).ndim() == 1) &&
      !py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value))
    throw_value_error("vp_signs_known", "expected a bool or one bool per VP");
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(value);
  if (py::len(seq) != vps->size())
    throw_value_error("vp_signs_known", std::to_string(py::len(seq)) + " values for " +
                                            std::to_string(vps->size()) + " VPs");
  for (size_t k = 0; k < vps->size(); ++k)
    (*vps)[k].sign_known = bool_argument(seq[k], "vp_signs_known[" + std::to_string(k) + "]");
}

TwoViewMatches read_matches(py::handle points1, py::handle points2, py::handle segments1,
                            py::handle segments2, py::handle vps, py::handle line_vp,
                            py::handle vp_signs_known) {
  TwoViewMatches matches;
  matches.points =
      matches_argument<PointMatch>(points1, points2, "points1", "points2", points_argument, true);
  matches.lines = matches_argument<LineMatch>(segments1, segments2, "segments1", "segments2",
                                              segments_argument, true);
  if (!vps.is_none()) {
    if (!(py::isinstance<py::tuple>(vps) || py::isinstance<py::list>(vps)) || py::len(vps) != 2)
      throw_value_error("vps", "expected a pair (directions1, directions2) of K x 3 arrays");
    const py::sequence pair = py::reinterpret_borrow<py::sequence>(vps);
    matches.vps =
        matches_argument<VpMatch>(pair[0], pair[1], "vps[0]", "vps[1]", directions_argument);
  }
  if (!vp_signs_known.is_none()) {
    if (vps.is_none()) throw_value_error("vp_signs_known", "given without vps");
    read_vp_signs_known(vp_signs_known, &matches.vps);
  }
  if (!line_vp.is_none()) {
    if (vps.is_none() || segments1.is_none())
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

// The estimate as the fields of hybrid_vo.RelativePoseEstimate (python/hybrid_vo/__init__.py).
py::dict estimate(py::handle camera1, py::handle camera2, py::handle points1, py::handle points2,
                  py::handle segments1, py::handle segments2, py::handle vps, py::handle preset,
                  py::handle line_vp, py::handle vp_signs_known, const py::dict& options) {
  const PinholeCamera c1 = camera_argument(camera1, "camera1");
  const PinholeCamera c2 = camera_argument(camera2, "camera2");
  TwoViewOptions two_view_options = preset_two_view_options(preset);
  apply_options(options, &two_view_options, "estimate_relative_pose");
  TwoViewMatches matches =
      read_matches(points1, points2, segments1, segments2, vps, line_vp, vp_signs_known);
  const TwoViewEstimate two_view =
      without_gil([&] { return estimate_two_view(c1, c2, matches, two_view_options); });
  const RelativePoseEstimate& e = two_view.estimate;
  const bool ok = e.status == EstimationStatus::kOk;
  py::dict solvers;
  for (const SolverInfo& info : solver_table()) {
    const SolverStatistics& s = e.solvers[static_cast<int>(info.id)];
    solvers[info.function] = py::dict("code"_a = info.code, "sampled"_a = s.sampled,
                                      "models"_a = s.models, "best"_a = s.best);
  }
  const py::object none = py::none();
  py::dict fields(
      "status"_a = to_string(e.status), "ok"_a = ok,
      "R"_a = ok ? py::object(to_array(e.pose.R)) : none,
      "t"_a = ok ? py::object(to_array(e.pose.t)) : none,
      "covariance"_a = ok && e.covariance_valid ? py::object(to_array(e.covariance)) : none,
      "point_inliers"_a = array_of<bool>(e.point_inliers),
      "line_inliers"_a = array_of<bool>(e.line_inliers),
      "vp_inliers"_a = array_of<bool>(e.vp_inliers),
      "junction_inliers"_a = array_of<bool>(e.junction_inliers),
      "endpoint_inliers"_a = array_of<bool>(e.endpoint_inliers),
      "num_point_inliers"_a = e.num_point_inliers, "num_line_inliers"_a = e.num_line_inliers,
      "num_vp_inliers"_a = e.num_vp_inliers, "num_junction_inliers"_a = e.num_junction_inliers,
      "num_endpoint_inliers"_a = e.num_endpoint_inliers,
      "line_vp"_a =
          array_of<int64_t>(two_view.vps_detected ? two_view.vps.labels : matches.line_vp),
      "vps_detected"_a = two_view.vps_detected, "solver_statistics"_a = solvers,
      "best_solver"_a = ok ? py::object(py::str(solver_info(e.best_solver).function)) : none,
      "iterations"_a = e.iterations, "local_optimizations"_a = e.local_optimizations,
      "refined"_a = e.refined,
      "rejected"_a = py::dict("points"_a = e.rejected_points, "lines"_a = e.rejected_lines,
                              "vps"_a = e.rejected_vps),
      "timings"_a =
          py::dict("vp_detection_ms"_a = two_view.vp_ms, "derive_ms"_a = e.derive_ms,
                   "ransac_ms"_a = e.ransac_ms, "refine_ms"_a = e.refine_ms,
                   "estimator_ms"_a = e.total_ms, "total_ms"_a = two_view.vp_ms + e.total_ms));
  // Derived point matches as rows (x1, y1, x2, y2), and their sources as rows (first, second).
  for (const auto& [kind, derived] :
       {std::pair{"junction", &e.junctions}, std::pair{"endpoint", &e.endpoints}}) {
    fields[py::str(kind + std::string("s"))] =
        rows_to_array<double, 4>(*derived, [](const DerivedPoint& d) {
          return (Eigen::Vector4d() << d.match.x1, d.match.x2).finished();
        });
    fields[py::str(kind + std::string("_segments"))] = rows_to_array<int64_t, 2>(
        *derived,
        [](const DerivedPoint& d) { return Eigen::Matrix<int64_t, 2, 1>(d.first, d.second); });
  }
  // The VP matches used: detected, or the given ones.
  fields.attr("update")(vps_to_dict(two_view.vps_detected ? two_view.vps.matches : matches.vps));
  return fields;
}

}  // namespace

void bind_estimator(py::module_& m) {
  // hybrid_vo.estimate_relative_pose passes every argument, and its keyword options as a dict.
  m.def("_estimate_relative_pose", &estimate, "The fields of a RelativePoseEstimate.");

  m.def(
      "estimator_options",
      [](py::handle preset) { return options_dict(preset_two_view_options(preset)); },
      "preset"_a = "hybrid+junc",
      "estimator_options(preset='hybrid+junc')\n--\n\n"
      "Every keyword option of estimate_relative_pose with its value under `preset`, as a dict: "
      "the fields\nof the C++ option structs (doc/python.md, Options). 'enabled' and 'prior' are "
      "per solver: pass\na dict {solver: value} or a list in the paper's order.");

  m.def(
      "presets", [] { return preset_names(); },
      "presets()\n--\n\nThe estimator presets (the paper's table rows).");
}

}  // namespace hybrid_vo::python
