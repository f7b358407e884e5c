#pragma once

// Keyword options of the Python functions, mapped onto the C++ option structs by one table per
// struct (options.cc). A renamed C++ field is a one-line change there; the Python name stays or
// changes in the same line. Unknown names raise ValueError naming all of them.

#include <pybind11/pybind11.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "arguments.h"
#include "hybrid_vo/lines/two_view.h"
#include "hybrid_vo/synthetic/manhattan_scene.h"
#include "hybrid_vo/synthetic/minimal_instances.h"

namespace hybrid_vo {
namespace python {

// What values a numeric option takes; checked before the C++ code sees them.
enum class Range {
  kAny,
  kPositive,
  kNonNegative,
  kFraction /* [0, 1] */,
  kOpenFraction /* (0, 1) */
};

using SolverFlags = std::array<bool, kNumSolvers>;
using SolverWeights = std::array<double, kNumSolvers>;

// Conversions of one option value, by C++ type. Per-solver arrays take a dict {solver: value}
// (function name or paper code; other solvers keep their value) or a sequence in the paper's order.
void check_range(double value, Range range, const std::string& name);
void read_option(py::handle value, const std::string& name, Range range, double* out);
void read_option(py::handle value, const std::string& name, Range range, int* out);
void read_option(py::handle value, const std::string& name, Range range, uint64_t* out);
void read_option(py::handle value, const std::string& name, Range range, bool* out);
void read_option(py::handle value, const std::string& name, Range range, SolverFlags* out);
void read_option(py::handle value, const std::string& name, Range range, SolverWeights* out);
py::object option_value(double value);
py::object option_value(int value);
py::object option_value(uint64_t value);
py::object option_value(bool value);
py::object option_value(const SolverFlags& value);
py::object option_value(const SolverWeights& value);

// Raises ValueError listing `unknown` option names of `function`, with close matches.
[[noreturn]] void throw_unknown_options(const std::vector<std::string>& unknown,
                                        const std::vector<std::string>& known,
                                        const std::string& function);

template <typename Options>
class OptionTable {
 public:
  // `access` maps an Options& to the field's reference (see FIELD in options.cc).
  template <typename Access>
  OptionTable& add(const std::string& name, Access access, Range range = Range::kAny) {
    using T = std::remove_reference_t<decltype(access(std::declval<Options&>()))>;
    Row row;
    row.name = name;
    row.set = [access, range](Options& o, py::handle value, const std::string& full_name) {
      read_option(value, full_name, range, static_cast<T*>(&access(o)));
    };
    row.get = [access](const Options& o) {
      return option_value(static_cast<const T&>(access(const_cast<Options&>(o))));
    };
    return push(std::move(row));
  }

  // Every option of a nested struct, under `prefix`, except `excluded` (fields the enclosing
  // code overrides, which would be silent no-ops).
  template <typename Sub, typename Access>
  OptionTable& nest(const std::string& prefix, Access access, const OptionTable<Sub>& sub,
                    const std::vector<std::string>& excluded = {}) {
    for (const auto& inner : sub.rows()) {
      if (std::find(excluded.begin(), excluded.end(), inner.name) != excluded.end()) continue;
      Row row;
      row.name = prefix + inner.name;
      row.set = [access, set = inner.set](Options& o, py::handle value, const std::string& name) {
        set(access(o), value, name);
      };
      row.get = [access, get = inner.get](const Options& o) {
        return get(access(const_cast<Options&>(o)));
      };
      push(std::move(row));
    }
    return *this;
  }

  // Sets every entry of `values` (option name -> value); ValueError for unknown names or values.
  void apply(const py::dict& values, Options* options, const std::string& function) const {
    std::vector<std::string> unknown;
    for (const auto& item : values) {
      const std::string name = py::str(item.first);
      if (!index_.count(name)) unknown.push_back(name);
    }
    if (!unknown.empty()) throw_unknown_options(unknown, names(), function);
    for (const auto& item : values) {
      const std::string name = py::str(item.first);
      rows_[index_.at(name)].set(*options, item.second, name);
    }
  }

  py::dict to_dict(const Options& options) const {
    py::dict d;
    for (const Row& row : rows_) d[py::str(row.name)] = row.get(options);
    return d;
  }

  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const Row& row : rows_) out.push_back(row.name);
    return out;
  }

  struct Row {
    std::string name;
    std::function<void(Options&, py::handle, const std::string&)> set;
    std::function<py::object(const Options&)> get;
  };
  const std::vector<Row>& rows() const { return rows_; }

 private:
  OptionTable& push(Row row) {
    index_[row.name] = rows_.size();
    rows_.push_back(std::move(row));
    return *this;
  }

  std::vector<Row> rows_;
  std::map<std::string, size_t> index_;
};

// The tables. The estimator's options are those of TwoViewOptions: RelativePoseEstimatorOptions
// (its `ransac` fields and its own under their names, `junctions_*`, `refinement_*`), and the VP
// detection in front (`detect_vps`, `joint_vp_detection`, `vp_detection_*`).
const OptionTable<TwoViewOptions>& estimator_option_table();
const OptionTable<VpDetectionOptions>& vp_detection_option_table();
const OptionTable<ManhattanSceneOptions>& manhattan_scene_option_table();
const OptionTable<MinimalInstanceOptions>& minimal_instance_option_table();

// A preset applied to fresh options; ValueError naming the valid presets otherwise.
TwoViewOptions preset_two_view_options(py::handle preset);

}  // namespace python
}  // namespace hybrid_vo
