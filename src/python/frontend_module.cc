// hybrid_vo.frontend: the OpenCV image front end (hybrid_vo_frontend) for Python. A separate
// extension so that `import hybrid_vo` loads no OpenCV; images come as NumPy arrays, so cv2 is
// not needed either.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <opencv2/core.hpp>

#include "arguments.h"
#include "hybrid_vo/features/frontend.h"

namespace hybrid_vo::python {
namespace {

using namespace pybind11::literals;

// An 8-bit image (H x W grey, H x W x 3 BGR or H x W x 4 BGRA, C-contiguous) viewed as a
// cv::Mat without a copy; `keep` holds the array while the Mat is used.
cv::Mat image_argument(py::handle value, const std::string& name, py::array* keep) {
  if (!py::isinstance<py::array>(value))
    throw_value_error(name, "expected a NumPy uint8 image, got " +
                                std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  *keep = py::reinterpret_borrow<py::array>(value);
  const py::array& a = *keep;
  check_array(a, name, py::isinstance<py::array_t<uint8_t>>(a), "uint8");
  const bool grey = a.ndim() == 2 || (a.ndim() == 3 && a.shape(2) == 1);
  const bool colour = a.ndim() == 3 && (a.shape(2) == 3 || a.shape(2) == 4);
  if (!grey && !colour)
    throw_value_error(name, "expected H x W (grey), H x W x 3 (BGR) or H x W x 4 (BGRA)");
  if (a.shape(0) == 0 || a.shape(1) == 0) throw_value_error(name, "empty image");
  const int channels = a.ndim() == 3 ? static_cast<int>(a.shape(2)) : 1;
  return cv::Mat(static_cast<int>(a.shape(0)), static_cast<int>(a.shape(1)), CV_8UC(channels),
                 const_cast<void*>(a.data()));
}

CameraModel camera_model_argument(py::handle value, const std::string& name, const cv::Mat& image) {
  CameraModel camera;
  camera.pinhole = camera_argument(value, name, &camera.distortion);
  if (camera.pinhole.width == 0) camera.pinhole.width = image.cols;
  if (camera.pinhole.height == 0) camera.pinhole.height = image.rows;
  return camera;
}

py::dict match_image_pair(py::handle image1, py::handle image2, py::handle camera,
                          py::handle camera2, py::handle points, py::handle lines,
                          py::handle max_features) {
  py::array keep1, keep2;
  const cv::Mat im1 = image_argument(image1, "image1", &keep1);
  const cv::Mat im2 = image_argument(image2, "image2", &keep2);
  const CameraModel c1 = camera_model_argument(camera, "camera", im1);
  const CameraModel c2 = camera2.is_none() ? c1 : camera_model_argument(camera2, "camera2", im2);
  FrontendOptions options;
  const std::string p = choice_argument(points, "points", {"sift", "orb", "none"});
  const std::string l = choice_argument(lines, "lines", {"lsd", "fld", "none"});
  options.use_points = p != "none";
  if (p == "orb") options.points.type = PointFeatureType::kOrb;
  options.use_lines = l != "none";
  if (l == "fld") options.lines.detection.detector = LineDetector::kFld;
  const long long n = integer_argument(max_features, "max_features");
  if (n <= 0 || n > 1000000) throw_value_error("max_features", "expected 1 .. 1000000");
  options.points.max_features = static_cast<int>(n);
  const TwoViewMatches matches = without_gil([&] {
    const ImageFeatures f1 = extract_features(im1, options), f2 = extract_features(im2, options);
    return match_features(f1, f2, c1, c2, options);
  });
  py::dict out("camera1"_a = camera_to_dict(c1.pinhole), "camera2"_a = camera_to_dict(c2.pinhole));
  out.attr("update")(matches_to_dict(matches));
  return out;
}

}  // namespace
}  // namespace hybrid_vo::python

PYBIND11_MODULE(frontend, m) {
  using namespace pybind11::literals;
  pybind11::options options;
  options.disable_function_signatures();
  m.doc() = "The OpenCV image front end of hybrid_vo (needs no cv2).";
  m.def(
      "match_image_pair", &hybrid_vo::python::match_image_pair, "image1"_a, "image2"_a, "camera"_a,
      "camera2"_a = pybind11::none(), "points"_a = "sift", "lines"_a = "lsd",
      "max_features"_a = 4000,
      R"doc(match_image_pair(image1, image2, camera, camera2=None, points='sift', lines='lsd', max_features=4000)
--

Point and segment matches between two images, as estimate_relative_pose takes them: the front
end of hybrid_vo_pair and the pair evaluation. Returns a dict with 'camera1', 'camera2' (the
pinhole cameras of the undistorted pixels), 'points1', 'points2' (N x 2) and 'segments1',
'segments2' (M x 4), so that estimate_relative_pose(**matches) runs on it.

image1, image2: uint8 NumPy arrays, H x W grey or H x W x 3 BGR (as cv2.imread returns them).
camera: {'fx', 'fy', 'cx', 'cy'[, 'width', 'height', 'distortion': (k1, k2, p1, p2, k3)]} or
    fx, fy, cx, cy[, k1, k2, p1, p2, k3] (OpenCV's plumb bob); camera2 defaults to camera.
    Matched coordinates are undistorted.
points: 'sift' (Lowe's ratio test, mutual), 'orb' or 'none'; max_features per image.
lines: 'lsd' or 'fld' segments described with LBD and matched mutually with a geometric check,
    or 'none'.)doc");
}
