#include "arguments.h"

#include <cmath>
#include <limits>
#include <set>

namespace hybrid_vo {
namespace python {
namespace {

using namespace pybind11::literals;

py::module_ numpy() { return py::module_::import("numpy"); }

std::string type_name(py::handle value) {
  return py::str(py::type::handle_of(value).attr("__name__"));
}

std::string shape_text(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) text += (k ? ", " : "") + std::to_string(a.shape(k));
  return text + (a.ndim() == 1 ? ",)" : ")");
}

std::string expected_shape(py::ssize_t rows, py::ssize_t cols) {
  const std::string r = rows == MatrixArgument::kAnyRows ? "N" : std::to_string(rows);
  std::string text = "(" + r + ", " + std::to_string(cols) + ")";
  if (rows == 1) text += " or (" + std::to_string(cols) + ",)";
  return text;
}

bool is_numpy_scalar_of(py::handle value, const char* kind) {
  return py::isinstance(value, numpy().attr(kind));
}

// Lists and tuples become arrays; NumPy arrays pass unchanged; anything else is refused. A
// masked array is refused too: its masked values would be read as if they were data.
py::array as_array(py::handle value, const std::string& name, const std::string& expected) {
  if (py::isinstance<py::array>(value)) {
    if (!py::type::handle_of(value).is(numpy().attr("ndarray")) &&
        py::isinstance(value, numpy().attr("ma").attr("MaskedArray")))
      throw_value_error(name, "a masked array; pass the valid rows as a plain array");
    return py::reinterpret_borrow<py::array>(value);
  }
  if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value))
    throw_value_error(name, "expected " + expected + ", got " + type_name(value));
  try {
    return numpy().attr("asarray")(value);
  } catch (py::error_already_set& e) {
    throw_value_error(name, "not a rectangular array of numbers (" + std::string(e.what()) + ")");
  }
}

}  // namespace

void throw_value_error(const std::string& argument, const std::string& message) {
  throw py::value_error(argument + ": " + message);
}

MatrixArgument::MatrixArgument(py::handle value, const std::string& name, py::ssize_t cols,
                               py::ssize_t rows)
    : cols_(cols) {
  const std::string expected = "a float64 array of shape " + expected_shape(rows, cols);
  const bool converted = !py::isinstance<py::array>(value);
  py::array a = as_array(value, name, expected);
  if (converted) {
    // A list of ints is as good as a list of floats; bools, strings and objects are not numbers.
    const char kind = a.dtype().kind();
    if (a.size() > 0 && kind != 'f' && kind != 'i' && kind != 'u')
      throw_value_error(
          name, "expected numbers, got elements of dtype " + std::string(py::str(a.dtype())));
    a = numpy().attr("ascontiguousarray")(a, "dtype"_a = "float64");
  }
  if (!py::isinstance<py::array_t<double>>(a))
    throw_value_error(name, "dtype " + std::string(py::str(a.dtype())) + ", expected float64 (" +
                                "np.ascontiguousarray(" + name +
                                ", dtype=np.float64) converts it)");
  const bool vector_form = rows == 1 && a.ndim() == 1 && a.shape(0) == cols;
  const bool matrix_form = a.ndim() == 2 && a.shape(1) == cols && (rows < 0 || a.shape(0) == rows);
  if (!vector_form && !matrix_form)
    throw_value_error(name, "shape " + shape_text(a) + ", expected " + expected_shape(rows, cols));
  if (!(a.flags() & py::array::c_style))
    throw_value_error(name,
                      "not C-contiguous (a strided view or a transpose); pass "
                      "np.ascontiguousarray(" +
                          name + ")");
  rows_ = vector_form ? 1 : a.shape(0);
  data_ = static_cast<const double*>(a.data());
  for (py::ssize_t i = 0; i < rows_ * cols_; ++i) {
    if (!std::isfinite(data_[i])) {
      const std::string where =
          vector_form ? "[" + std::to_string(i) + "]"
                      : "[" + std::to_string(i / cols_) + ", " + std::to_string(i % cols_) + "]";
      throw_value_error(name, "value " + where + " is not finite (" +
                                  std::string(py::str(py::float_(data_[i]))) + ")");
    }
  }
  owner_ = std::move(a);
}

std::vector<Eigen::Vector3d> directions_argument(py::handle value, const std::string& name,
                                                 py::ssize_t rows) {
  const MatrixArgument m(value, name, 3, rows);
  std::vector<Eigen::Vector3d> out;
  for (py::ssize_t i = 0; i < m.rows(); ++i) {
    out.push_back(m.vector3(i));
    if (out.back().squaredNorm() == 0.0)
      throw_value_error(name, "direction " + std::to_string(i) + " is zero");
  }
  return out;
}

bool bool_argument(py::handle value, const std::string& name) {
  if (PyBool_Check(value.ptr())) return value.ptr() == Py_True;
  if (is_numpy_scalar_of(value, "bool_")) return PyObject_IsTrue(value.ptr()) == 1;
  throw_value_error(name, "expected True or False, got " + std::string(py::repr(value)));
}

double number_argument(py::handle value, const std::string& name) {
  double v = std::numeric_limits<double>::quiet_NaN();
  const bool python_number =
      !PyBool_Check(value.ptr()) && (PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()));
  if (python_number || is_numpy_scalar_of(value, "integer") ||
      is_numpy_scalar_of(value, "floating")) {
    v = PyFloat_AsDouble(value.ptr());
    if (PyErr_Occurred()) {
      PyErr_Clear();
      v = std::numeric_limits<double>::infinity();
    }
  } else {
    throw_value_error(name, "expected a number, got " + std::string(py::repr(value)));
  }
  if (!std::isfinite(v))
    throw_value_error(name, "expected a finite number, got " + std::string(py::repr(value)));
  return v;
}

long long integer_argument(py::handle value, const std::string& name) {
  const bool python_int = PyLong_Check(value.ptr()) && !PyBool_Check(value.ptr());
  if (!python_int && !is_numpy_scalar_of(value, "integer"))
    throw_value_error(name, "expected an integer, got " + std::string(py::repr(value)));
  int overflow = 0;
  const py::object as_int = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()));
  if (!as_int) {
    PyErr_Clear();
    throw_value_error(name, "expected an integer, got " + std::string(py::repr(value)));
  }
  const long long v = PyLong_AsLongLongAndOverflow(as_int.ptr(), &overflow);
  if (overflow != 0)
    throw_value_error(name, "integer out of range: " + std::string(py::repr(value)));
  return v;
}

std::vector<int> labels_argument(py::handle value, const std::string& name) {
  const std::string expected = "a 1-D integer array";
  const bool converted = !py::isinstance<py::array>(value);
  py::array a = as_array(value, name, expected);
  const char kind = a.dtype().kind();
  const bool empty_list = converted && a.size() == 0;
  if (!empty_list && kind != 'i' && kind != 'u')
    throw_value_error(name, "dtype " + std::string(py::str(a.dtype())) + ", expected integers");
  if (a.ndim() != 1) throw_value_error(name, "shape " + shape_text(a) + ", expected (N,)");
  if (!(a.flags() & py::array::c_style))
    throw_value_error(name, "not contiguous; pass np.ascontiguousarray(" + name + ")");
  const auto values = py::array_t<int64_t, py::array::forcecast>::ensure(a);
  std::vector<int> out(static_cast<size_t>(a.size()));
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    const int64_t v = values.at(i);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      throw_value_error(name, "value [" + std::to_string(i) + "] out of range");
    out[i] = static_cast<int>(v);
  }
  return out;
}

PinholeCamera camera_argument(py::handle value, const std::string& name,
                              std::array<double, 5>* distortion) {
  const std::string forms = distortion ? "a dict {fx, fy, cx, cy[, width, height, distortion]} "
                                         "or a sequence fx, fy, cx, cy[, k1, k2, p1, p2, k3]"
                                       : "a dict {fx, fy, cx, cy[, width, height]} or a "
                                         "sequence fx, fy, cx, cy";
  PinholeCamera camera;
  std::array<double, 5> coefficients{};
  if (py::isinstance<py::dict>(value)) {
    const py::dict d = py::reinterpret_borrow<py::dict>(value);
    std::set<std::string> allowed = {"fx", "fy", "cx", "cy", "width", "height"};
    if (distortion) allowed.insert("distortion");
    for (const auto& item : d) {
      const std::string key = py::str(item.first);
      if (!allowed.count(key))
        throw_value_error(
            name, "unknown key '" + key + "' (expected " + forms + ")" +
                      (key == "distortion" ? "; the estimator takes undistorted pixels" : ""));
    }
    double* fields[] = {&camera.fx, &camera.fy, &camera.cx, &camera.cy};
    const char* keys[] = {"fx", "fy", "cx", "cy"};
    for (int k = 0; k < 4; ++k) {
      if (!d.contains(keys[k]))
        throw_value_error(name, std::string("missing key '") + keys[k] + "'");
      *fields[k] = number_argument(d[keys[k]], name + "['" + keys[k] + "']");
    }
    for (const char* key : {"width", "height"}) {
      if (!d.contains(key)) continue;
      const long long size = integer_argument(d[key], name + "['" + key + "']");
      if (size < 0 || size > std::numeric_limits<int>::max())
        throw_value_error(name + "['" + key + "']", "expected a size >= 0");
      (std::string(key) == "width" ? camera.width : camera.height) = static_cast<int>(size);
    }
    if (distortion && d.contains("distortion")) {
      const MatrixArgument k(d["distortion"], name + "['distortion']", 5, 1);
      for (int i = 0; i < 5; ++i) coefficients[i] = k(0, i);
    }
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
             (py::isinstance<py::array>(value) &&
              py::reinterpret_borrow<py::array>(value).ndim() == 1)) {
    const py::sequence seq = py::reinterpret_borrow<py::sequence>(value);
    const size_t n = py::len(seq);
    if (n != 4 && !(distortion && n == 9))
      throw_value_error(name, std::to_string(n) + " values, expected " + forms);
    double* fields[] = {&camera.fx, &camera.fy, &camera.cx, &camera.cy};
    for (size_t k = 0; k < n; ++k) {
      const double v = number_argument(seq[k], name + "[" + std::to_string(k) + "]");
      if (k < 4)
        *fields[k] = v;
      else
        coefficients[k - 4] = v;
    }
  } else {
    throw_value_error(name, "expected " + forms + ", got " + type_name(value));
  }
  if (!(camera.fx > 0.0) || !(camera.fy > 0.0))
    throw_value_error(name, "focal lengths must be positive");
  if (distortion) *distortion = coefficients;
  return camera;
}

py::dict camera_to_dict(const PinholeCamera& camera) {
  return py::dict("fx"_a = camera.fx, "fy"_a = camera.fy, "cx"_a = camera.cx, "cy"_a = camera.cy,
                  "width"_a = camera.width, "height"_a = camera.height);
}

py::array_t<bool> to_bool_array(const std::vector<char>& mask) {
  py::array_t<bool> a(static_cast<py::ssize_t>(mask.size()));
  bool* out = a.mutable_data();
  for (size_t i = 0; i < mask.size(); ++i) out[i] = mask[i] != 0;
  return a;
}

py::array_t<bool> to_bool_array(const std::vector<bool>& mask) {
  py::array_t<bool> a(static_cast<py::ssize_t>(mask.size()));
  bool* out = a.mutable_data();
  for (size_t i = 0; i < mask.size(); ++i) out[i] = mask[i];
  return a;
}

py::array_t<int64_t> to_int_array(const std::vector<int>& values) {
  py::array_t<int64_t> a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

py::array_t<double> points_to_array(const std::vector<Eigen::Vector2d>& points) {
  return rows_to_array<double, 2>(points, [](const Eigen::Vector2d& p) { return p; });
}

py::array_t<double> segments_to_array(const std::vector<LineSegment>& segments) {
  return rows_to_array<double, 4>(segments, [](const LineSegment& s) {
    return Eigen::Vector4d(s.p1.x(), s.p1.y(), s.p2.x(), s.p2.y());
  });
}

py::array_t<double> directions_to_array(const std::vector<Eigen::Vector3d>& directions) {
  return rows_to_array<double, 3>(directions, [](const Eigen::Vector3d& d) { return d; });
}

py::tuple pose_to_tuple(const RelativePose& pose) {
  return py::make_tuple(to_array(pose.R), to_array(pose.t));
}

}  // namespace python
}  // namespace hybrid_vo
