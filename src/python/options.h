#pragma once

// Keyword options of the Python functions. Their names and bounds are the C++ structs' own
// declarations (visit_fields, next to each struct, see geometry/option_fields.h), and their values
// are checked by the structs' validate(), as the node's are: nothing here lists a field.

#include <pybind11/pybind11.h>

#include <limits>
#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "arguments.h"
#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/lines/two_view.h"

namespace hybrid_vo::python {

// ValueError naming `name` unless `value` is within `bounds`.
void check_bounds(double value, const Bounds& bounds, const std::string& name);
// An integer within `bounds` and [min, max], the range of the option's C++ type.
long long integer_option(py::handle value, const std::string& name, const Bounds& bounds,
                         long long min, unsigned long long max);
// A solver named by function name or paper code ("3-0-1", "2-1-1p", "2-1-1⊥").
SolverId solver_argument(py::handle value, const std::string& name);
// A per-solver option's sequence: one value per solver, in the paper's order.
py::sequence per_solver_sequence(py::handle value, const std::string& name);

// One option value by its C++ type; ValueError naming `name` for a wrong type or a value outside
// `bounds`. Per-solver arrays take a dict {solver: value} (function name or paper code; the other
// solvers keep theirs) or a sequence in the paper's order, each value within `bounds`.
template <typename T>
void read_option(py::handle value, const std::string& name, const Bounds& bounds, T* out) {
  if constexpr (std::is_same_v<T, bool>) {
    *out = bool_argument(value, name);
  } else if constexpr (std::is_floating_point_v<T>) {
    *out = number_argument(value, name);
    check_bounds(*out, bounds, name);
  } else if constexpr (std::is_integral_v<T>) {
    *out = static_cast<T>(integer_option(value, name, bounds, std::numeric_limits<T>::min(),
                                         std::numeric_limits<T>::max()));
  } else if (py::isinstance<py::dict>(value)) {  // per solver
    for (const auto& [solver, v] : py::reinterpret_borrow<py::dict>(value))
      read_option(v, name + "['" + std::string(py::str(solver)) + "']", bounds,
                  &(*out)[static_cast<int>(solver_argument(solver, name))]);
  } else {
    const py::sequence values = per_solver_sequence(value, name);
    for (int k = 0; k < kNumSolvers; ++k)
      read_option(values[k], name + "[" + std::to_string(k) + "]", bounds, &(*out)[k]);
  }
}

// The Python value of an option: a number or bool, or a dict {solver function: value}.
template <typename T>
py::object option_value(const T& value) {
  if constexpr (std::is_arithmetic_v<T>) {
    return py::cast(value);
  } else {
    py::dict d;
    for (const SolverInfo& info : solver_table())
      d[info.function] = value[static_cast<int>(info.id)];
    return std::move(d);
  }
}

// A keyword renamed since the last release, under its new name, after a DeprecationWarning;
// other names unchanged.
std::string current_option_name(const std::string& name, const std::string& function);
// ValueError listing the `unknown` options of `function`, with the closest valid names.
[[noreturn]] void throw_unknown_options(const std::vector<std::string>& unknown,
                                        const std::vector<std::string>& known,
                                        const std::string& function);

// Sets every option of `values` (keyword -> value) and validates the result; ValueError naming
// the option for an unknown name, a value of the wrong type or one out of bounds.
template <typename Options>
void apply_options(const py::dict& values, Options* options, const std::string& function) {
  if (values.empty()) return;  // the defaults and the presets are valid
  std::vector<std::string> known;
  visit_fields(*options,
               [&](const std::string& name, auto&, const Bounds& = {}) { known.push_back(name); });
  std::map<std::string, std::pair<std::string, py::handle>> given;  // name -> (keyword, value)
  std::vector<std::string> unknown;
  for (const auto& [key, value] : values) {
    const std::string keyword = py::str(key), name = current_option_name(keyword, function);
    if (std::find(known.begin(), known.end(), name) == known.end()) unknown.push_back(keyword);
    given[name] = {keyword, value};
  }
  if (!unknown.empty()) throw_unknown_options(unknown, known, function);
  visit_fields(*options, [&](const std::string& name, auto& field, const Bounds& bounds = {}) {
    const auto it = given.find(name);
    if (it != given.end()) read_option(it->second.second, it->second.first, bounds, &field);
  });
  const std::string problem = validate(*options);
  if (!problem.empty()) throw py::value_error(problem);
}

// Every option of `options` by name, as a dict.
template <typename Options>
py::dict options_dict(Options options) {
  py::dict out;
  visit_fields(options, [&](const std::string& name, auto& field, const Bounds& = {}) {
    out[py::str(name)] = option_value(field);
  });
  return out;
}

// A preset applied to fresh options; ValueError naming the valid presets otherwise.
TwoViewOptions preset_two_view_options(py::handle preset);

}  // namespace hybrid_vo::python
