#include "options.h"

#include <limits>

namespace hybrid_vo {
namespace python {
namespace {

void check_bounds(double value, const Bounds& bounds, const std::string& name) {
  if (!bounds.contains(value))
    throw_value_error(name, bounds.requirement() + ", got " + std::string(py::str(py::float_(value))));
}

// A per-solver option: {solver name or code: value} updates those solvers, a sequence of
// kNumSolvers values (the paper's order, hybrid_vo.solvers()) replaces all.
template <typename T>
void read_per_solver(py::handle value, const std::string& name, const Bounds& bounds,
                     std::array<T, kNumSolvers>* out) {
  if (py::isinstance<py::dict>(value)) {
    for (const auto& item : py::reinterpret_borrow<py::dict>(value)) {
      const std::string solver = py::str(item.first);
      SolverId id;
      if (!find_solver(solver, &id))
        throw_value_error(name, "unknown solver '" + solver +
                                    "' (function names or paper codes, hybrid_vo.solvers())");
      read_option(item.second, name + "['" + solver + "']", bounds, &(*out)[static_cast<int>(id)]);
    }
    return;
  }
  if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value))
    throw_value_error(name, "expected a dict {solver: value} or a list of " +
                                std::to_string(kNumSolvers) + " values in the paper's order");
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(value);
  if (py::len(seq) != kNumSolvers)
    throw_value_error(name, std::to_string(py::len(seq)) + " values, expected one per solver (" +
                                std::to_string(kNumSolvers) + ")");
  for (int k = 0; k < kNumSolvers; ++k)
    read_option(seq[k], name + "[" + std::to_string(k) + "]", bounds, &(*out)[k]);
}

template <typename T>
py::object per_solver_value(const std::array<T, kNumSolvers>& values) {
  py::dict d;
  for (const SolverInfo& info : solver_table()) d[info.function] = values[static_cast<int>(info.id)];
  return std::move(d);
}

// Keywords renamed when the options were flattened (issue 33): old -> new.
const std::map<std::string, std::string> kRenamed = {
    {"final_refinement", "refinement_enabled"},  // RelativePoseEstimatorOptions::refinement.enabled
};

}  // namespace

void read_option(py::handle value, const std::string& name, const Bounds& bounds, double* out) {
  *out = number_argument(value, name);
  check_bounds(*out, bounds, name);
}

void read_option(py::handle value, const std::string& name, const Bounds& bounds, int* out) {
  const long long v = integer_argument(value, name);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throw_value_error(name, "integer out of range");
  check_bounds(static_cast<double>(v), bounds, name);
  *out = static_cast<int>(v);
}

void read_option(py::handle value, const std::string& name, const Bounds&, uint64_t* out) {
  const long long v = integer_argument(value, name);
  if (v < 0) throw_value_error(name, "must be >= 0");
  *out = static_cast<uint64_t>(v);
}

void read_option(py::handle value, const std::string& name, const Bounds&, bool* out) {
  *out = bool_argument(value, name);
}

void read_option(py::handle value, const std::string& name, const Bounds& bounds, SolverFlags* out) {
  read_per_solver(value, name, bounds, out);
}

void read_option(py::handle value, const std::string& name, const Bounds& bounds,
                 SolverWeights* out) {
  read_per_solver(value, name, bounds, out);
}

py::object option_value(double value) { return py::float_(value); }
py::object option_value(int value) { return py::int_(value); }
py::object option_value(uint64_t value) { return py::int_(value); }
py::object option_value(bool value) { return py::bool_(value); }
py::object option_value(const SolverFlags& value) { return per_solver_value(value); }
py::object option_value(const SolverWeights& value) { return per_solver_value(value); }

std::string current_option_name(const std::string& name, const std::string& function) {
  const auto it = kRenamed.find(name);
  if (it == kRenamed.end()) return name;
  const std::string message = function + ": option '" + name + "' is deprecated, use '" +
                              it->second + "'";
  if (PyErr_WarnEx(PyExc_DeprecationWarning, message.c_str(), 2) < 0) throw py::error_already_set();
  return it->second;
}

void throw_unknown_options(const std::vector<std::string>& unknown,
                           const std::vector<std::string>& known, const std::string& function) {
  const py::object close = py::module_::import("difflib").attr("get_close_matches");
  std::string message = function + ": unknown option" + (unknown.size() > 1 ? "s " : " ");
  std::vector<std::string> hints;
  for (size_t i = 0; i < unknown.size(); ++i) {
    message += (i ? ", '" : "'") + unknown[i] + "'";
    for (const auto& match : close(unknown[i], py::cast(known), 1))
      hints.push_back("'" + std::string(py::str(match)) + "' for '" + unknown[i] + "'");
  }
  if (!hints.empty()) {
    message += " (did you mean ";
    for (size_t i = 0; i < hints.size(); ++i) message += (i ? ", " : "") + hints[i];
    message += "?)";
  }
  throw py::value_error(message);
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

}  // namespace python
}  // namespace hybrid_vo
