#include "options.h"

namespace hybrid_vo::python {
namespace {

// Keywords renamed when the options were flattened (issue 33): old -> new.
const std::map<std::string, std::string> kRenamed = {
    {"final_refinement", "refinement_enabled"},  // RelativePoseEstimatorOptions::refinement.enabled
};

}  // namespace

void check_bounds(double value, const Bounds& bounds, const std::string& name) {
  if (!bounds.contains(value))
    throw_value_error(name,
                      bounds.requirement() + ", got " + std::string(py::str(py::float_(value))));
}

long long integer_option(py::handle value, const std::string& name, const Bounds& bounds,
                         long long min, unsigned long long max) {
  const long long v = integer_argument(value, name);
  if (v < 0 && min == 0) throw_value_error(name, "must be >= 0");
  if (v < min || (v > 0 && static_cast<unsigned long long>(v) > max))
    throw_value_error(name, "integer out of range");
  check_bounds(static_cast<double>(v), bounds, name);
  return v;
}

SolverId solver_argument(py::handle value, const std::string& name) {
  SolverId id;
  if (!py::isinstance<py::str>(value) || !find_solver(py::cast<std::string>(value), &id))
    throw_value_error(name, "unknown solver " + std::string(py::repr(value)) +
                                " (function names or paper codes, hybrid_vo.solvers())");
  return id;
}

py::sequence per_solver_sequence(py::handle value, const std::string& name) {
  if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value))
    throw_value_error(name, "expected a dict {solver: value} or a list of " +
                                std::to_string(kNumSolvers) + " values in the paper's order");
  const py::sequence values = py::reinterpret_borrow<py::sequence>(value);
  if (py::len(values) != kNumSolvers)
    throw_value_error(name, std::to_string(py::len(values)) + " values, expected one per solver (" +
                                std::to_string(kNumSolvers) + ")");
  return values;
}

std::string current_option_name(const std::string& name, const std::string& function) {
  const auto it = kRenamed.find(name);
  if (it == kRenamed.end()) return name;
  const std::string message =
      function + ": option '" + name + "' is deprecated, use '" + it->second + "'";
  if (PyErr_WarnEx(PyExc_DeprecationWarning, message.c_str(), 2) < 0) throw py::error_already_set();
  return it->second;
}

void throw_unknown_options(const std::vector<std::string>& unknown,
                           const std::vector<std::string>& known, const std::string& function) {
  const py::object close = py::module_::import("difflib").attr("get_close_matches");
  std::string message = function + ": unknown option" + (unknown.size() > 1 ? "s " : " "), hints;
  for (size_t i = 0; i < unknown.size(); ++i) {
    message += (i ? ", '" : "'") + unknown[i] + "'";
    for (const auto& match : close(unknown[i], py::cast(known), 1))
      hints += (hints.empty() ? " (did you mean '" : ", '") + std::string(py::str(match)) +
               "' for '" + unknown[i] + "'";
  }
  throw py::value_error(message + hints + (hints.empty() ? "" : "?)"));
}

TwoViewOptions preset_two_view_options(py::handle preset) {
  if (!py::isinstance<py::str>(preset))
    throw_value_error("preset", "expected a preset name, got " + std::string(py::repr(preset)));
  TwoViewOptions options;
  if (!preset_options(py::cast<std::string>(preset), &options)) {
    std::string names;
    for (const std::string& name : preset_names()) names += (names.empty() ? "" : ", ") + name;
    throw_value_error("preset", "unknown preset '" + py::cast<std::string>(preset) +
                                    "' (presets: " + names + ")");
  }
  return options;
}

}  // namespace hybrid_vo::python
