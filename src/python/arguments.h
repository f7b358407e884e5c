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
#include <cstdint>
#include <string>
#include <vector>

#include "hybrid_vo/estimation/matches.h"
#include "hybrid_vo/geometry/camera.h"
#include "hybrid_vo/geometry/pose.h"

namespace hybrid_vo::python {

namespace py = pybind11;

[[noreturn]] void throw_value_error(const std::string& argument, const std::string& message);

// ValueError naming `name` unless `a` has the expected dtype and shape and is C-contiguous.
void check_array(const py::array& a, const std::string& name, bool dtype_ok,
                 const std::string& dtype, bool shape_ok = true, const std::string& shape = "");

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
// Matches {first[i], second[i]} (PointMatch, LineMatch, VpMatch) of two arguments, each read by
// `read` (one of the three above); ValueError unless both have the same rows. With `optional`,
// both None are no matches, and one None is a ValueError.
template <typename Match, typename Read>
std::vector<Match> matches_argument(py::handle first, py::handle second, const std::string& name1,
                                    const std::string& name2, Read read, bool optional = false) {
  if (optional && first.is_none() != second.is_none())
    throw_value_error(
        first.is_none() ? name1 : name2,
        "None while " + (first.is_none() ? name2 : name1) + " is given (pass both or neither)");
  if (optional && first.is_none()) return {};
  const auto a = read(first, name1, kAnyRows), b = read(second, name2, kAnyRows);
  if (a.size() != b.size())
    throw_value_error(name2, std::to_string(b.size()) + " rows, but " + name1 + " has " +
                                 std::to_string(a.size()));
  std::vector<Match> out(a.size());
  for (size_t i = 0; i < a.size(); ++i) out[i] = {a[i], b[i]};
  return out;
}

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

// f() with the GIL released, for the core's work (which touches no Python object).
template <typename F>
auto without_gil(F f) {
  py::gil_scoped_release release;
  return f();
}

// Results: copies into new NumPy arrays.
// A fixed-size column vector becomes a 1-D array, anything else a C-contiguous 2-D array.
template <typename Derived>
py::array_t<double> to_array(const Eigen::MatrixBase<Derived>& m) {
  std::vector<py::ssize_t> shape = {m.rows()};
  if (Derived::ColsAtCompileTime != 1) shape.push_back(m.cols());
  py::array_t<double> a(shape);
  Eigen::Map<RowMatrix>(a.mutable_data(), m.rows(), m.cols()) = m;
  return a;
}
// A 1-D array of `values`: a mask (std::vector<char> or <bool>) as bool, labels as int64.
template <typename Scalar, typename Values>
py::array_t<Scalar> array_of(const Values& values) {
  py::array_t<Scalar> a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}
// Rows for rows_to_array: an Eigen vector as it is, a segment as (x1, y1, x2, y2).
inline constexpr auto same_row = [](const auto& v) { return v; };
inline Eigen::Vector4d segment_row(const LineSegment& s) {
  return {s.p1.x(), s.p1.y(), s.p2.x(), s.p2.y()};
}
// An N x Cols array whose row i is row(items[i]), an Eigen vector of Cols values, for the first
// `n` items (all by default).
template <typename Scalar, int Cols, typename Items, typename Row = decltype(same_row)>
py::array_t<Scalar> rows_to_array(const Items& items, Row row = same_row, size_t n = SIZE_MAX) {
  n = std::min(n, items.size());
  py::array_t<Scalar> a({static_cast<py::ssize_t>(n), py::ssize_t{Cols}});
  Scalar* out = a.mutable_data();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Matrix<Scalar, Cols, 1> values = row(items[i]);
    out = std::copy(values.data(), values.data() + Cols, out);
  }
  return a;
}
// A pose as the tuple (R, t).
py::tuple pose_to_tuple(const RelativePose& pose);
// Point and segment matches as estimate_relative_pose takes them: points1, points2 (N x 2),
// segments1, segments2 (M x 4).
py::dict matches_to_dict(const TwoViewMatches& matches);
// VP matches as estimate_relative_pose takes them: vps (K x 3 directions in each view) and
// vp_signs_known.
py::dict vps_to_dict(const std::vector<VpMatch>& vps);

}  // namespace hybrid_vo::python
