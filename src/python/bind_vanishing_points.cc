// VP detection: single image, and two-view (joint, or the per-image "standard" baseline).
// hybrid_vo.detect_vanishing_points (python/hybrid_vo/__init__.py) picks the mode by its
// arguments and calls these.
#include "bindings.h"
#include "hybrid_vo/lines/vp_detection.h"
#include "options.h"

namespace hybrid_vo {
namespace python {
namespace {

using namespace pybind11::literals;

std::vector<LineSegment> read_segments(py::handle value, const std::string& name) {
  const MatrixArgument m(value, name, 4);
  std::vector<LineSegment> out(m.rows());
  for (py::ssize_t i = 0; i < m.rows(); ++i) out[i] = m.segment(i);
  return out;
}

VpDetectionOptions read_options(const py::kwargs& options, const char* function) {
  VpDetectionOptions out;
  apply_options(options, &out, function);
  return out;
}

py::list index_lists(const std::vector<std::vector<int>>& lists) {
  py::list out;
  for (const std::vector<int>& l : lists) out.append(to_int_array(l));
  return out;
}

}  // namespace

void bind_vanishing_points(py::module_& m) {
  // One image (camera2 and segments2 None) or two; hybrid_vo.detect_vanishing_points reads its
  // arguments and calls this.
  m.def(
      "_detect_vanishing_points",
      [](py::handle camera1, py::handle segments1, py::handle camera2, py::handle segments2,
         py::handle mode, const py::kwargs& kwargs) {
        const bool two = !camera2.is_none();
        const char* names[] = {two ? "camera1" : "camera", two ? "segments1" : "segments"};
        const PinholeCamera c1 = camera_argument(camera1, names[0]);
        const std::vector<LineSegment> s1 = read_segments(segments1, names[1]);
        const VpDetectionOptions options = read_options(kwargs, "detect_vanishing_points");
        std::vector<Eigen::Vector3d> d1, d2;
        std::vector<char> known;
        if (!two) {
          SingleImageVps vps;
          {
            py::gil_scoped_release release;
            vps = detect_vanishing_points(c1, s1, options);
          }
          std::vector<std::vector<int>> inliers;
          std::vector<double> scores;
          for (const ImageVp& vp : vps.vps)
            d1.push_back(vp.direction), inliers.push_back(vp.inliers), scores.push_back(vp.score);
          return py::dict("directions"_a = directions_to_array(d1),
                          "labels"_a = to_int_array(vps.labels), "inliers"_a = index_lists(inliers),
                          "scores"_a = py::array_t<double>(scores.size(), scores.data()));
        }
        const PinholeCamera c2 = camera_argument(camera2, "camera2");
        const std::vector<LineSegment> s2 = read_segments(segments2, "segments2");
        if (s1.size() != s2.size())
          throw_value_error("segments2", std::to_string(s2.size()) + " rows, but segments1 has " +
                                             std::to_string(s1.size()));
        const std::string m = py::isinstance<py::str>(mode) ? py::cast<std::string>(mode) : "";
        if (m != "joint" && m != "standard")
          throw_value_error("mode",
                            "expected 'joint' or 'standard', got " + std::string(py::repr(mode)));
        std::vector<LineMatch> lines(s1.size());
        for (size_t i = 0; i < s1.size(); ++i) lines[i] = {s1[i], s2[i]};
        MatchedVps vps;
        {
          py::gil_scoped_release release;
          vps = m == "joint" ? detect_vanishing_points_joint(c1, c2, lines, options)
                             : detect_vanishing_points_standard(c1, c2, lines, options);
        }
        for (const VpMatch& vp : vps.matches)
          d1.push_back(vp.d1), d2.push_back(vp.d2), known.push_back(vp.sign_known);
        return py::dict("vps"_a = py::make_tuple(directions_to_array(d1), directions_to_array(d2)),
                        "vp_signs_known"_a = to_bool_array(known),
                        "line_vp"_a = to_int_array(vps.labels),
                        "inliers"_a = index_lists(vps.inliers),
                        "scores"_a = py::array_t<double>(vps.scores.size(), vps.scores.data()));
      },
      "camera1"_a, "segments1"_a, "camera2"_a, "segments2"_a, "mode"_a,
      "_detect_vanishing_points(camera1, segments1, camera2, segments2, mode, **options)\n--\n\n"
      "VP detection; see hybrid_vo.detect_vanishing_points.");

  m.def(
      "vp_detection_options", [] { return options_dict(VpDetectionOptions()); },
      "vp_detection_options()\n--\n\n"
      "Every keyword option of detect_vanishing_points (VpDetectionOptions) with its default.");
}

}  // namespace python
}  // namespace hybrid_vo
