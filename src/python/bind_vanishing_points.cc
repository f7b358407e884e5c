// VP detection: single image, and two-view (joint, or the per-image "standard" baseline).
// hybrid_vo.detect_vanishing_points (python/hybrid_vo/__init__.py) picks the mode by its
// arguments and calls these.
#include "hybrid_vo/lines/vp_detection.h"
#include "options.h"

namespace hybrid_vo::python {

void bind_vanishing_points(py::module_& m) {
  using namespace pybind11::literals;
  // One image (camera2 and segments2 None) or two; hybrid_vo.detect_vanishing_points reads its
  // arguments and calls this with the options as a dict.
  m.def(
      "_detect_vanishing_points",
      [](py::handle camera1, py::handle segments1, py::handle camera2, py::handle segments2,
         py::handle mode, const py::dict& keywords) {
        const bool two = !camera2.is_none();
        const PinholeCamera c1 = camera_argument(camera1, two ? "camera1" : "camera");
        VpDetectionOptions options;
        py::list inliers;
        if (!two) {
          const std::vector<LineSegment> segments = segments_argument(segments1, "segments");
          apply_options(keywords, &options, "detect_vanishing_points");
          const SingleImageVps vps =
              without_gil([&] { return detect_vanishing_points(c1, segments, options); });
          std::vector<double> scores;
          for (const ImageVp& vp : vps.vps)
            inliers.append(array_of<int64_t>(vp.inliers)), scores.push_back(vp.score);
          return py::dict("directions"_a = rows_to_array<double, 3>(
                              vps.vps, [](const ImageVp& vp) { return vp.direction; }),
                          "labels"_a = array_of<int64_t>(vps.labels), "inliers"_a = inliers,
                          "scores"_a = array_of<double>(scores));
        }
        const PinholeCamera c2 = camera_argument(camera2, "camera2");
        const std::vector<LineMatch> lines = matches_argument<LineMatch>(
            segments1, segments2, "segments1", "segments2", segments_argument);
        const bool joint = choice_argument(mode, "mode", {"joint", "standard"}) == "joint";
        apply_options(keywords, &options, "detect_vanishing_points");
        const MatchedVps vps = without_gil([&] {
          return (joint ? detect_vanishing_points_joint : detect_vanishing_points_standard)(
              c1, c2, lines, options);
        });
        for (const std::vector<int>& l : vps.inliers) inliers.append(array_of<int64_t>(l));
        py::dict out = vps_to_dict(vps.matches);
        out["line_vp"] = array_of<int64_t>(vps.labels);
        out["inliers"] = inliers;
        out["scores"] = array_of<double>(vps.scores);
        return out;
      },
      "VP detection in one image or two.");

  m.def(
      "vp_detection_options", [] { return options_dict(VpDetectionOptions()); },
      "vp_detection_options()\n--\n\n"
      "Every keyword option of detect_vanishing_points (VpDetectionOptions) with its default.");
}

}  // namespace hybrid_vo::python
