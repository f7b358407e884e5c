#pragma once

// Keyword options of the Python functions. Their names and bounds are the C++ structs' own
// declarations (visit_fields, next to each struct, see geometry/option_fields.h), and their values
// are checked by the structs' validate(), as the node's are: nothing here lists a field.

#include <pybind11/pybind11.h>

#include <map>
#include <string>
#include <type_traits>
#include <vector>

#include "arguments.h"
#include "hybrid_vo/geometry/option_fields.h"
#include "hybrid_vo/lines/two_view.h"

namespace hybrid_vo {
namespace python {

using SolverFlags = std::array<bool, kNumSolvers>;
using SolverWeights = std::array<double, kNumSolvers>;

// One option value by C++ type. Per-solver arrays take a dict {solver: value} (function name or
// paper code; the other solvers keep theirs) or a sequence in the paper's order, each value
// within `bounds`.
void read_option(py::handle value, const std::string& name, const Bounds& bounds, double* out);
void read_option(py::handle value, const std::string& name, const Bounds& bounds, int* out);
void read_option(py::handle value, const std::string& name, const Bounds& bounds, uint64_t* out);
void read_option(py::handle value, const std::string& name, const Bounds& bounds, bool* out);
void read_option(py::handle value, const std::string& name, const Bounds& bounds, SolverFlags* out);
void read_option(py::handle value, const std::string& name, const Bounds& bounds,
                 SolverWeights* out);
py::object option_value(double value);
py::object option_value(int value);
py::object option_value(uint64_t value);
py::object option_value(bool value);
py::object option_value(const SolverFlags& value);
py::object option_value(const SolverWeights& value);

// A keyword renamed since the last release, under its new name, after a DeprecationWarning;
// other names unchanged.
std::string current_option_name(const std::string& name, const std::string& function);
// ValueError listing the `unknown` options of `function`, with the closest valid names.
[[noreturn]] void throw_unknown_options(const std::vector<std::string>& unknown,
                                        const std::vector<std::string>& known,
                                        const std::string& function);

template <typename Options>
std::vector<std::string> option_names() {
  std::vector<std::string> names;
  Options options;
  visit_fields(options, [&](const std::string& name, auto&, const Bounds& = {}) {
    names.push_back(name);
  });
  return names;
}

// Sets every option of `values` (keyword -> value) and validates the result; ValueError naming
// the option for an unknown name, a value of the wrong type or one out of bounds.
template <typename Options>
void apply_options(const py::dict& values, Options* options, const std::string& function) {
  const std::vector<std::string> known = option_names<Options>();
  std::map<std::string, std::pair<std::string, py::handle>> given;  // name -> (keyword, value)
  std::vector<std::string> unknown;
  for (const auto& item : values) {
    const std::string keyword = py::str(item.first);
    const std::string name = current_option_name(keyword, function);
    if (std::find(known.begin(), known.end(), name) == known.end()) unknown.push_back(keyword);
    given[name] = {keyword, item.second};
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

}  // namespace python
}  // namespace hybrid_vo
