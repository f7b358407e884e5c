#include "arguments.h"

#include <cmath>
#include <limits>

namespace hybrid_vo::python {
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
  const std::string r = rows == kAnyRows ? "N" : std::to_string(rows);
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

// The rows of a matrix argument, each read by `row`.
template <typename T, typename Row>
std::vector<T> rows_of(const RowMatrix& m, Row row) {
  std::vector<T> out(m.rows());
  for (Eigen::Index i = 0; i < m.rows(); ++i) out[i] = row(m.row(i));
  return out;
}

}  // namespace

void throw_value_error(const std::string& argument, const std::string& message) {
  throw py::value_error(argument + ": " + message);
}

void check_array(const py::array& a, const std::string& name, bool dtype_ok,
                 const std::string& dtype, bool shape_ok, const std::string& shape) {
  if (!dtype_ok)
    throw_value_error(name, "dtype " + std::string(py::str(a.dtype())) + ", expected " + dtype);
  if (!shape_ok) throw_value_error(name, "shape " + shape_text(a) + ", expected " + shape);
  if (!(a.flags() & py::array::c_style))
    throw_value_error(name,
                      "not C-contiguous (a strided view or a transpose); pass "
                      "np.ascontiguousarray(" +
                          name + ")");
}

RowMatrix matrix_argument(py::handle value, const std::string& name, py::ssize_t cols,
                          py::ssize_t rows) {
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
  const bool vector_form = rows == 1 && a.ndim() == 1 && a.shape(0) == cols;
  const bool matrix_form = a.ndim() == 2 && a.shape(1) == cols && (rows < 0 || a.shape(0) == rows);
  check_array(a, name, py::isinstance<py::array_t<double>>(a),
              "float64 (np.ascontiguousarray(" + name + ", dtype=np.float64) converts it)",
              vector_form || matrix_form, expected_shape(rows, cols));
  const RowMatrix m = Eigen::Map<const RowMatrix>(static_cast<const double*>(a.data()),
                                                  vector_form ? 1 : a.shape(0), cols);
  if (m.allFinite()) return m;
  Eigen::Index k = 0;  // name the first value that is not finite
  while (std::isfinite(m.data()[k])) ++k;
  const std::string row = vector_form ? "" : std::to_string(k / cols) + ", ";
  throw_value_error(name, "value [" + row + std::to_string(k % cols) + "] is not finite (" +
                              std::string(py::str(py::float_(m.data()[k]))) + ")");
}

std::vector<Eigen::Vector2d> points_argument(py::handle value, const std::string& name,
                                             py::ssize_t rows) {
  return rows_of<Eigen::Vector2d>(matrix_argument(value, name, 2, rows),
                                  [](const auto& r) { return r.transpose(); });
}

std::vector<LineSegment> segments_argument(py::handle value, const std::string& name,
                                           py::ssize_t rows) {
  return rows_of<LineSegment>(matrix_argument(value, name, 4, rows), [](const auto& r) {
    return LineSegment{{r(0), r(1)}, {r(2), r(3)}};
  });
}

std::vector<Eigen::Vector3d> directions_argument(py::handle value, const std::string& name,
                                                 py::ssize_t rows) {
  const std::vector<Eigen::Vector3d> out = rows_of<Eigen::Vector3d>(
      matrix_argument(value, name, 3, rows), [](const auto& r) { return r.transpose(); });
  for (size_t i = 0; i < out.size(); ++i)
    if (out[i].squaredNorm() == 0.0)
      throw_value_error(name, "direction " + std::to_string(i) + " is zero");
  return out;
}

bool bool_argument(py::handle value, const std::string& name) {
  if (PyBool_Check(value.ptr())) return value.ptr() == Py_True;
  if (is_numpy_scalar_of(value, "bool_")) return PyObject_IsTrue(value.ptr()) == 1;
  throw_value_error(name, "expected True or False, got " + std::string(py::repr(value)));
}

double number_argument(py::handle value, const std::string& name) {
  const bool number =
      !PyBool_Check(value.ptr()) &&
      (PyFloat_Check(value.ptr()) || PyLong_Check(value.ptr()) ||
       is_numpy_scalar_of(value, "integer") || is_numpy_scalar_of(value, "floating"));
  if (!number) throw_value_error(name, "expected a number, got " + std::string(py::repr(value)));
  double v = PyFloat_AsDouble(value.ptr());
  if (PyErr_Occurred()) PyErr_Clear(), v = std::numeric_limits<double>::infinity();  // a huge int
  if (!std::isfinite(v))
    throw_value_error(name, "expected a finite number, got " + std::string(py::repr(value)));
  return v;
}

long long integer_argument(py::handle value, const std::string& name) {
  const bool integer = (PyLong_Check(value.ptr()) && !PyBool_Check(value.ptr())) ||
                       is_numpy_scalar_of(value, "integer");
  const py::object as_int =
      integer ? py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr())) : py::object();
  if (!as_int) {
    PyErr_Clear();
    throw_value_error(name, "expected an integer, got " + std::string(py::repr(value)));
  }
  int overflow = 0;
  const long long v = PyLong_AsLongLongAndOverflow(as_int.ptr(), &overflow);
  if (overflow != 0)
    throw_value_error(name, "integer out of range: " + std::string(py::repr(value)));
  return v;
}

std::vector<int> labels_argument(py::handle value, const std::string& name) {
  const py::array a = as_array(value, name, "a 1-D integer array");
  const bool empty_list = !py::isinstance<py::array>(value) && a.size() == 0;
  const char kind = a.dtype().kind();
  check_array(a, name, empty_list || kind == 'i' || kind == 'u', "integers", a.ndim() == 1, "(N,)");
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

std::string choice_argument(py::handle value, const std::string& name,
                            const std::vector<std::string>& choices) {
  const std::string s = py::isinstance<py::str>(value) ? py::cast<std::string>(value) : "";
  if (std::find(choices.begin(), choices.end(), s) != choices.end()) return s;
  std::string expected;
  for (size_t k = 0; k < choices.size(); ++k)
    expected += (k == 0 ? "'" : k + 1 < choices.size() ? ", '" : " or '") + choices[k] + "'";
  throw_value_error(name, "expected " + expected + ", got " + std::string(py::repr(value)));
}

PinholeCamera camera_argument(py::handle value, const std::string& name,
                              std::array<double, 5>* distortion) {
  const std::string forms = distortion ? "a dict {fx, fy, cx, cy[, width, height, distortion]} "
                                         "or a sequence fx, fy, cx, cy[, k1, k2, p1, p2, k3]"
                                       : "a dict {fx, fy, cx, cy[, width, height]} or a "
                                         "sequence fx, fy, cx, cy";
  std::array<double, 9> v{};  // fx, fy, cx, cy, then the distortion k1, k2, p1, p2, k3
  PinholeCamera camera;
  if (py::isinstance<py::dict>(value)) {
    const py::dict d = py::reinterpret_borrow<py::dict>(value);
    const std::vector<std::string> keys = {"fx", "fy", "cx", "cy", "width", "height", "distortion"};
    const auto allowed = keys.end() - (distortion ? 0 : 1);
    for (const auto& item : d) {
      const std::string key = py::str(item.first);
      if (std::find(keys.begin(), allowed, key) == allowed)
        throw_value_error(
            name, "unknown key '" + key + "' (expected " + forms + ")" +
                      (key == "distortion" ? "; the estimator takes undistorted pixels" : ""));
    }
    for (int k = 0; k < 6; ++k) {
      const std::string where = name + "['" + keys[k] + "']";
      if (!d.contains(keys[k])) {
        if (k < 4) throw_value_error(name, "missing key '" + keys[k] + "'");
      } else if (k < 4) {
        v[k] = number_argument(d[keys[k].c_str()], where);
      } else {
        const long long size = integer_argument(d[keys[k].c_str()], where);
        if (size < 0 || size > std::numeric_limits<int>::max())
          throw_value_error(where, "expected a size >= 0");
        (k == 4 ? camera.width : camera.height) = static_cast<int>(size);
      }
    }
    if (distortion && d.contains("distortion")) {
      const RowMatrix k = matrix_argument(d["distortion"], name + "['distortion']", 5, 1);
      std::copy(k.data(), k.data() + 5, v.begin() + 4);
    }
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value) ||
             (py::isinstance<py::array>(value) &&
              py::reinterpret_borrow<py::array>(value).ndim() == 1)) {
    const py::sequence seq = py::reinterpret_borrow<py::sequence>(value);
    const size_t n = py::len(seq);
    if (n != 4 && !(distortion && n == 9))
      throw_value_error(name, std::to_string(n) + " values, expected " + forms);
    for (size_t k = 0; k < n; ++k)
      v[k] = number_argument(seq[k], name + "[" + std::to_string(k) + "]");
  } else {
    throw_value_error(name, "expected " + forms + ", got " + type_name(value));
  }
  camera.fx = v[0], camera.fy = v[1], camera.cx = v[2], camera.cy = v[3];
  if (!(camera.fx > 0.0) || !(camera.fy > 0.0))
    throw_value_error(name, "focal lengths must be positive");
  if (distortion) std::copy(v.begin() + 4, v.end(), distortion->begin());
  return camera;
}

py::dict camera_to_dict(const PinholeCamera& camera) {
  return py::dict("fx"_a = camera.fx, "fy"_a = camera.fy, "cx"_a = camera.cx, "cy"_a = camera.cy,
                  "width"_a = camera.width, "height"_a = camera.height);
}

py::tuple pose_to_tuple(const RelativePose& pose) {
  return py::make_tuple(to_array(pose.R), to_array(pose.t));
}

py::dict matches_to_dict(const TwoViewMatches& m) {
  return py::dict(
      "points1"_a = rows_to_array<double, 2>(m.points, [](const PointMatch& p) { return p.x1; }),
      "points2"_a = rows_to_array<double, 2>(m.points, [](const PointMatch& p) { return p.x2; }),
      "segments1"_a = rows_to_array<double, 4>(m.lines, [](auto& l) { return segment_row(l.s1); }),
      "segments2"_a = rows_to_array<double, 4>(m.lines, [](auto& l) { return segment_row(l.s2); }));
}

py::dict vps_to_dict(const std::vector<VpMatch>& vps) {
  std::vector<char> known;
  for (const VpMatch& vp : vps) known.push_back(vp.sign_known);
  return py::dict("vps"_a = py::make_tuple(
                      rows_to_array<double, 3>(vps, [](const VpMatch& vp) { return vp.d1; }),
                      rows_to_array<double, 3>(vps, [](const VpMatch& vp) { return vp.d2; })),
                  "vp_signs_known"_a = array_of<bool>(known));
}

}  // namespace hybrid_vo::python
