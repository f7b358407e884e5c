#include "options.h"

#include <limits>

namespace hybrid_vo {
namespace python {

void check_range(double value, Range range, const std::string& name) {
  const char* requirement = nullptr;
  switch (range) {
    case Range::kAny:
      return;
    case Range::kPositive:
      if (!(value > 0.0)) requirement = "> 0";
      break;
    case Range::kNonNegative:
      if (!(value >= 0.0)) requirement = ">= 0";
      break;
    case Range::kFraction:
      if (!(value >= 0.0 && value <= 1.0)) requirement = "in [0, 1]";
      break;
    case Range::kOpenFraction:
      if (!(value > 0.0 && value < 1.0)) requirement = "in (0, 1)";
      break;
  }
  if (requirement)
    throw_value_error(name, std::string("must be ") + requirement + ", got " +
                                std::string(py::str(py::float_(value))));
}

void read_option(py::handle value, const std::string& name, Range range, double* out) {
  const double v = number_argument(value, name);
  check_range(v, range, name);
  *out = v;
}

void read_option(py::handle value, const std::string& name, Range range, int* out) {
  const long long v = integer_argument(value, name);
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
    throw_value_error(name, "integer out of range");
  check_range(static_cast<double>(v), range, name);
  *out = static_cast<int>(v);
}

void read_option(py::handle value, const std::string& name, Range, uint64_t* out) {
  const long long v = integer_argument(value, name);
  if (v < 0) throw_value_error(name, "must be >= 0");
  *out = static_cast<uint64_t>(v);
}

void read_option(py::handle value, const std::string& name, Range, bool* out) {
  *out = bool_argument(value, name);
}

namespace {

// A per-solver option: {solver name or code: value} updates those solvers, a sequence of
// kNumSolvers values (the paper's order, hybrid_vo.solvers()) replaces all.
template <typename T>
void read_per_solver(py::handle value, const std::string& name, Range range,
                     std::array<T, kNumSolvers>* out) {
  auto read_one = [&](py::handle item, const std::string& item_name, T* target) {
    if constexpr (std::is_same_v<T, bool>) {
      *target = bool_argument(item, item_name);
    } else {
      read_option(item, item_name, range, target);
    }
  };
  if (py::isinstance<py::dict>(value)) {
    for (const auto& item : py::reinterpret_borrow<py::dict>(value)) {
      const std::string solver = py::str(item.first);
      SolverId id;
      if (!find_solver(solver, &id))
        throw_value_error(name, "unknown solver '" + solver +
                                    "' (function names or paper codes, hybrid_vo.solvers())");
      read_one(item.second, name + "['" + solver + "']", &(*out)[static_cast<int>(id)]);
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
    read_one(seq[k], name + "[" + std::to_string(k) + "]", &(*out)[k]);
}

template <typename T>
py::object per_solver_value(const std::array<T, kNumSolvers>& values) {
  py::dict d;
  for (const SolverInfo& info : solver_table())
    d[info.function] = values[static_cast<int>(info.id)];
  return std::move(d);
}

}  // namespace

void read_option(py::handle value, const std::string& name, Range range, SolverFlags* out) {
  read_per_solver(value, name, range, out);
}
void read_option(py::handle value, const std::string& name, Range range, SolverWeights* out) {
  read_per_solver(value, name, range, out);
}

py::object option_value(double value) { return py::float_(value); }
py::object option_value(int value) { return py::int_(value); }
py::object option_value(uint64_t value) { return py::int_(value); }
py::object option_value(bool value) { return py::bool_(value); }
py::object option_value(const SolverFlags& value) { return per_solver_value(value); }
py::object option_value(const SolverWeights& value) { return per_solver_value(value); }

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

// The option tables: one line per option, Python name -> C++ field. FIELD(path) is the accessor
// of `path` in the table's struct.
#define FIELD(path) \
  [](auto& o) -> auto& { return o.path; }

const OptionTable<VpDetectionOptions>& vp_detection_option_table() {
  static const OptionTable<VpDetectionOptions> table = [] {
    OptionTable<VpDetectionOptions> t;
    t.add("inlier_threshold_px", FIELD(inlier_threshold_px), Range::kPositive)
        .add("min_segment_length_px", FIELD(min_segment_length_px), Range::kNonNegative)
        .add("max_vps", FIELD(max_vps), Range::kNonNegative)
        .add("min_inliers", FIELD(min_inliers), Range::kNonNegative)
        .add("max_iterations", FIELD(max_iterations), Range::kNonNegative)
        .add("confidence", FIELD(confidence), Range::kOpenFraction)
        .add("merge_angle_deg", FIELD(merge_angle_deg), Range::kNonNegative)
        .add("refine", FIELD(refine))
        .add("manhattan", FIELD(manhattan))
        .add("manhattan_tolerance_deg", FIELD(manhattan_tolerance_deg), Range::kNonNegative)
        .add("sign_agreement", FIELD(sign_agreement), Range::kFraction)
        .add("seed", FIELD(seed));
    return t;
  }();
  return table;
}

const OptionTable<TwoViewOptions>& estimator_option_table() {
  static const OptionTable<TwoViewOptions> table = [] {
    OptionTable<TwoViewOptions> t;
    // RelativePoseEstimatorOptions::ransac (HybridRansacOptions)
    t.add("enabled", FIELD(estimator.ransac.enabled))
        .add("prior", FIELD(estimator.ransac.prior), Range::kNonNegative)
        .add("point_threshold_px", FIELD(estimator.ransac.point_threshold_px), Range::kPositive)
        .add("vp_threshold_deg", FIELD(estimator.ransac.vp_threshold_deg), Range::kPositive)
        .add("line_inlier_ratio", FIELD(estimator.ransac.line_inlier_ratio), Range::kFraction)
        .add("initial_point_inlier_ratio", FIELD(estimator.ransac.initial_point_inlier_ratio),
             Range::kFraction)
        .add("initial_vp_inlier_ratio", FIELD(estimator.ransac.initial_vp_inlier_ratio),
             Range::kFraction)
        .add("exploration", FIELD(estimator.ransac.exploration), Range::kFraction)
        .add("five_point_share", FIELD(estimator.ransac.five_point_share), Range::kFraction)
        .add("confidence", FIELD(estimator.ransac.confidence), Range::kOpenFraction)
        .add("min_iterations", FIELD(estimator.ransac.min_iterations), Range::kNonNegative)
        .add("max_iterations", FIELD(estimator.ransac.max_iterations), Range::kPositive)
        .add("local_optimization", FIELD(estimator.ransac.local_optimization))
        .add("lo_max_points", FIELD(estimator.ransac.lo_max_points), Range::kPositive)
        .add("lo_rounds", FIELD(estimator.ransac.lo_rounds), Range::kNonNegative)
        .add("orthogonal_tolerance_deg", FIELD(estimator.ransac.orthogonal_tolerance_deg),
             Range::kNonNegative)
        .add("seed", FIELD(estimator.ransac.seed))
        // RelativePoseEstimatorOptions
        .add("use_junction_points", FIELD(estimator.use_junction_points))
        .add("use_endpoint_points", FIELD(estimator.use_endpoint_points))
        .add("junctions_tolerance_px", FIELD(estimator.junctions.tolerance_px), Range::kNonNegative)
        .add("junctions_duplicate_px", FIELD(estimator.junctions.duplicate_px), Range::kNonNegative)
        .add("junctions_min_angle_deg", FIELD(estimator.junctions.min_angle_deg),
             Range::kNonNegative)
        .add("final_refinement", FIELD(estimator.final_refinement))
        .add("scales_enabled", FIELD(estimator.scales.enabled))
        .add("scales_min_points", FIELD(estimator.scales.min_points), Range::kNonNegative)
        .add("scales_min_junctions", FIELD(estimator.scales.min_junctions), Range::kNonNegative)
        .add("scales_min_lines", FIELD(estimator.scales.min_lines), Range::kNonNegative)
        .add("scales_min_vps", FIELD(estimator.scales.min_vps), Range::kNonNegative)
        .add("scales_inlier_multiple", FIELD(estimator.scales.inlier_multiple), Range::kPositive)
        .add("scales_line_threshold_px", FIELD(estimator.scales.line_threshold_px),
             Range::kPositive)
        .add("scales_default_fraction", FIELD(estimator.scales.default_fraction), Range::kPositive)
        .add("vp_prior_gate_chi2", FIELD(estimator.vp_prior_gate_chi2), Range::kNonNegative)
        .add("refinement_refine_vp_directions", FIELD(estimator.refinement.refine_vp_directions))
        .add("refinement_max_iterations", FIELD(estimator.refinement.max_iterations),
             Range::kNonNegative)
        .add("refinement_compute_covariance", FIELD(estimator.refinement.compute_covariance))
        .add("refinement_function_tolerance", FIELD(estimator.refinement.function_tolerance),
             Range::kPositive)
        .add("refinement_parameter_tolerance", FIELD(estimator.refinement.parameter_tolerance),
             Range::kPositive)
        .add("min_point_inliers", FIELD(estimator.min_point_inliers), Range::kNonNegative)
        // TwoViewOptions: VP detection when no VPs are given (its seed is the RANSAC seed).
        .add("detect_vps", FIELD(detect_vps))
        .add("joint_vp_detection", FIELD(joint_vp_detection))
        .nest("vp_detection_", FIELD(vp_detection), vp_detection_option_table(), {"seed"});
    return t;
  }();
  return table;
}

const OptionTable<ManhattanSceneOptions>& manhattan_scene_option_table() {
  static const OptionTable<ManhattanSceneOptions> table = [] {
    OptionTable<ManhattanSceneOptions> t;
    t.add("num_points", FIELD(num_points), Range::kNonNegative)
        .add("planar_point_fraction", FIELD(planar_point_fraction), Range::kFraction)
        .add("num_segments", FIELD(num_segments), Range::kNonNegative)
        .add("noise_px", FIELD(noise_px), Range::kNonNegative)
        .add("point_outlier_ratio", FIELD(point_outlier_ratio), Range::kFraction)
        .add("line_outlier_ratio", FIELD(line_outlier_ratio), Range::kFraction)
        .add("num_vps", FIELD(num_vps), Range::kNonNegative)
        .add("lines_per_vp_fit", FIELD(lines_per_vp_fit), Range::kNonNegative)
        .add("vp_noise_deg", FIELD(vp_noise_deg), Range::kNonNegative)
        .add("orient_vps", FIELD(orient_vps))
        .add("focal_px", FIELD(focal_px), Range::kPositive)
        .add("width", FIELD(width), Range::kPositive)
        .add("height", FIELD(height), Range::kPositive)
        .add("baseline", FIELD(baseline), Range::kNonNegative)
        .add("max_rotation_deg", FIELD(max_rotation_deg), Range::kNonNegative)
        .add("junction_fraction", FIELD(junction_fraction), Range::kFraction)
        .add("min_segment_px", FIELD(min_segment_px), Range::kPositive)
        .add("max_segment_px", FIELD(max_segment_px), Range::kPositive);
    return t;
  }();
  return table;
}

const OptionTable<MinimalInstanceOptions>& minimal_instance_option_table() {
  static const OptionTable<MinimalInstanceOptions> table = [] {
    OptionTable<MinimalInstanceOptions> t;
    t.add("noise", FIELD(noise), Range::kNonNegative)
        .add("lines_per_vp", FIELD(lines_per_vp), Range::kPositive)
        .add("orient_vps", FIELD(orient_vps))
        .add("scene_spread", FIELD(scene_spread), Range::kPositive)
        .add("extra_points", FIELD(extra_points), Range::kNonNegative);
    return t;
  }();
  return table;
}

#undef FIELD

TwoViewOptions preset_two_view_options(py::handle preset) {
  if (!py::isinstance<py::str>(preset))
    throw_value_error("preset", "expected a preset name, got " + std::string(py::repr(preset)));
  TwoViewOptions options;
  if (!preset_options(py::cast<std::string>(preset), &options.estimator)) {
    std::string names;
    for (const std::string& name : preset_names()) names += (names.empty() ? "" : ", ") + name;
    throw_value_error("preset", "unknown preset '" + py::cast<std::string>(preset) +
                                    "' (presets: " + names + ")");
  }
  return options;
}

}  // namespace python
}  // namespace hybrid_vo
