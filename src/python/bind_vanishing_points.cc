// VP detection: single image, and two-view (joint, or the per-image "standard" baseline).
// hybrid_vo.detect_vanishing_points (python/hybrid_vo/__init__.py) picks the mode by its
// arguments and calls these.
#include "bindings.h"
#include "hybrid_vo/lines/vp_detection.h"
#include "options.h"

namespace hybrid_vo::python {
namespace {

using namespace pybind11::literals;

py::list index_lists(const std::vector<std::vector<int>>& lists) {
  py::list out;
  for (const std::vector<int>& l : lists) out.append(to_int_array(l));
  return out;
}

}  // namespace

void bind_vanishing_points(py::module_& m) {
  // One image (camera2 and segments2 None) or two; hybrid_vo.detect_vanishing_points reads its
  // arguments and calls this with the options as a dict.
  m.def(
      "_detect_vanishing_points",
      [](py::handle camera1, py::handle segments1, py::handle camera2, py::handle segments2,
         py::handle mode, const py::dict& keywords) {
        const bool two = !camera2.is_none();
        const char* names[] = {two ? "camera1" : "camera", two ? "segments1" : "segments"};
        const PinholeCamera c1 = camera_argument(camera1, names[0]);
        const std::vector<LineSegment> s1 = segments_argument(segments1, names[1]);
        VpDetectionOptions options;
        apply_options(keywords, &options, "detect_vanishing_points");
        if (!two) {
          SingleImageVps vps;
          {
            py::gil_scoped_release release;
            vps = detect_vanishing_points(c1, s1, options);
          }
          std::vector<std::vector<int>> inliers;
          std::vector<double> scores;
          for (const ImageVp& vp : vps.vps)
            inliers.push_back(vp.inliers), scores.push_back(vp.score);
          return py::dict("directions"_a = rows_to_array<double, 3>(
                              vps.vps, [](const ImageVp& vp) { return vp.direction; }),
                          "labels"_a = to_int_array(vps.labels), "inliers"_a = index_lists(inliers),
                          "scores"_a = py::array_t<double>(scores.size(), scores.data()));
        }
        const PinholeCamera c2 = camera_argument(camera2, "camera2");
        const std::vector<LineSegment> s2 = segments_argument(segments2, "segments2");
        check_same_rows(s1.size(), "segments1", s2.size(), "segments2");
        const bool joint = choice_argument(mode, "mode", {"joint", "standard"}) == "joint";
        std::vector<LineMatch> lines(s1.size());
        for (size_t i = 0; i < s1.size(); ++i) lines[i] = {s1[i], s2[i]};
        MatchedVps vps;
        {
          py::gil_scoped_release release;
          vps = joint ? detect_vanishing_points_joint(c1, c2, lines, options)
                      : detect_vanishing_points_standard(c1, c2, lines, options);
        }
        py::dict out = vps_to_dict(vps.matches);
        out["line_vp"] = to_int_array(vps.labels);
        out["inliers"] = index_lists(vps.inliers);
        out["scores"] = py::array_t<double>(vps.scores.size(), vps.scores.data());
        return out;
      },
      "VP detection in one image or two.");

  m.def(
      "vp_detection_options", [] { return options_dict(VpDetectionOptions()); },
      "vp_detection_options()\n--\n\n"
      "Every keyword option of detect_vanishing_points (VpDetectionOptions) with its default.");
}

}  // namespace hybrid_vo::python
