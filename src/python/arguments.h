#pragma once

// Checked conversions of Python arguments for the bindings, and of results back. Every failure
// raises ValueError naming the argument: the bindings never read an array with the wrong shape,
// dtype or strides and never pass NaN on to the core.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo::python {

namespace py = pybind11;

[[noreturn]] void throw_value_error(const std::string& argument, const std::string& message);
// "name: 39 rows, but other has 40" unless the row counts agree.
void check_same_rows(size_t other_rows, const std::string& other, size_t rows,
                     const std::string& name);

// A validated rows x cols float64 array argument, copied. NumPy arrays must already be float64
// and C-contiguous: the bindings refuse rather than copy a strided view or round a float32 behind
// the caller's back. Lists and tuples of numbers are converted (they have no layout to get wrong).
// With `rows` = 1 a 1-D array of `cols` values is accepted too. Every value must be finite.
constexpr py::ssize_t kAnyRows = -1;
using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
RowMatrix matrix_argument(py::handle value, const std::string& name, py::ssize_t cols,
                          py::ssize_t rows = kAnyRows);

// N x 2 points, N x 4 segments (x1, y1, x2, y2) and N x 3 directions, none of them zero (a
// 1-D array for N = 1).
std::vector<Eigen::Vector2d> points_argument(py::handle value, const std::string& name,
                                             py::ssize_t rows = kAnyRows);
std::vector<LineSegment> segments_argument(py::handle value, const std::string& name,
                                           py::ssize_t rows = kAnyRows);
std::vector<Eigen::Vector3d> directions_argument(py::handle value, const std::string& name,
                                                 py::ssize_t rows = kAnyRows);

// True or False (Python or NumPy bools; numbers are refused, so that 0.5 is not read as True).
bool bool_argument(py::handle value, const std::string& name);

// Integer labels: an integer array (any integer dtype, C-contiguous) or a list, 1-D.
std::vector<int> labels_argument(py::handle value, const std::string& name);

// Scalars: finite numbers (Python or NumPy, not bools) and integers (no floats).
double number_argument(py::handle value, const std::string& name);
long long integer_argument(py::handle value, const std::string& name);

// One of `choices`, a string.
std::string choice_argument(py::handle value, const std::string& name,
                            const std::vector<std::string>& choices);

// A pinhole camera: a dict with fx, fy, cx, cy (and optionally width, height) or a sequence fx,
// fy, cx, cy. With `distortion` non-null, OpenCV's plumb-bob coefficients are accepted too (dict
// key "distortion", or a 9-sequence); without it a distorted camera is refused, since the core
// takes undistorted pixels.
PinholeCamera camera_argument(py::handle value, const std::string& name,
                              std::array<double, 5>* distortion = nullptr);
// The inverse for results: {"fx", "fy", "cx", "cy", "width", "height"}.
py::dict camera_to_dict(const PinholeCamera& camera);

// Results: copies into new NumPy arrays.
// A fixed-size column vector becomes a 1-D array, anything else a C-contiguous 2-D array.
template <typename Derived>
py::array_t<double> to_array(const Eigen::MatrixBase<Derived>& m) {
  if constexpr (Derived::ColsAtCompileTime == 1) {
    py::array_t<double> a(static_cast<py::ssize_t>(m.rows()));
    for (Eigen::Index i = 0; i < m.rows(); ++i) a.mutable_data()[i] = m(i);
    return a;
  } else {
    py::array_t<double> a({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
    auto out = a.template mutable_unchecked<2>();
    for (Eigen::Index i = 0; i < m.rows(); ++i)
      for (Eigen::Index j = 0; j < m.cols(); ++j) out(i, j) = m(i, j);
    return a;
  }
}
// A mask (std::vector<char> or <bool>) as a bool array.
template <typename Mask>
py::array_t<bool> to_bool_array(const Mask& mask) {
  py::array_t<bool> a(static_cast<py::ssize_t>(mask.size()));
  for (size_t i = 0; i < mask.size(); ++i) a.mutable_data()[i] = mask[i] != 0;
  return a;
}
py::array_t<int64_t> to_int_array(const std::vector<int>& values);
// An N x cols array whose row i is row(items[i]), an Eigen vector of `cols` values.
template <typename Scalar, int Cols, typename T, typename Row>
py::array_t<Scalar> rows_to_array(const std::vector<T>& items, Row row) {
  py::array_t<Scalar> a({static_cast<py::ssize_t>(items.size()), py::ssize_t{Cols}});
  Scalar* out = a.mutable_data();
  for (const T& item : items) {
    const Eigen::Matrix<Scalar, Cols, 1> values = row(item);
    out = std::copy(values.data(), values.data() + Cols, out);
  }
  return a;
}
py::array_t<double> points_to_array(const std::vector<Eigen::Vector2d>& points);
py::array_t<double> segments_to_array(const std::vector<LineSegment>& segments);
py::array_t<double> directions_to_array(const std::vector<Eigen::Vector3d>& directions);
// A pose as the tuple (R, t).
py::tuple pose_to_tuple(const RelativePose& pose);
// Point and segment matches as estimate_relative_pose takes them: points1, points2 (N x 2),
// segments1, segments2 (M x 4).
py::dict matches_to_dict(const TwoViewMatches& matches);
// VP matches as estimate_relative_pose takes them: vps (K x 3 directions in each view) and
// vp_signs_known.
py::dict vps_to_dict(const std::vector<VpMatch>& vps);

}  // namespace hybrid_vo::python
