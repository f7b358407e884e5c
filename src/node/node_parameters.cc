#include "hybrid_vo/node/node_parameters.h"

#include <cmath>
#include <functional>
#include <set>

namespace hybrid_vo {
namespace {

using XmlRpc::XmlRpcValue;

// As roscpp's NodeHandle::param reads them: a double from an int too, an int from a double
// rounded to the nearest.
bool read_value(const XmlRpcValue& v, bool* out) {
  if (v.getType() != XmlRpcValue::TypeBoolean) return false;
  *out = static_cast<bool>(const_cast<XmlRpcValue&>(v));
  return true;
}
bool read_value(const XmlRpcValue& v, int* out) {
  XmlRpcValue& value = const_cast<XmlRpcValue&>(v);
  if (v.getType() == XmlRpcValue::TypeInt) {
    *out = static_cast<int>(value);
  } else if (v.getType() == XmlRpcValue::TypeDouble) {
    *out = static_cast<int>(std::lround(static_cast<double>(value)));
  } else {
    return false;
  }
  return true;
}
bool read_value(const XmlRpcValue& v, double* out) {
  XmlRpcValue& value = const_cast<XmlRpcValue&>(v);
  if (v.getType() == XmlRpcValue::TypeDouble)
    *out = static_cast<double>(value);
  else if (v.getType() == XmlRpcValue::TypeInt)
    *out = static_cast<int>(value);
  else
    return false;
  return true;
}
bool read_value(const XmlRpcValue& v, std::string* out) {
  if (v.getType() != XmlRpcValue::TypeString) return false;
  *out = static_cast<std::string>(const_cast<XmlRpcValue&>(v));
  return true;
}

const char* type_name(bool*) { return "a boolean"; }
const char* type_name(int*) { return "an integer"; }
const char* type_name(double*) { return "a number"; }
const char* type_name(std::string*) { return "a string"; }

// One parameter: sets its field(s) of NodeParameters from a value, or says why it cannot.
struct Parameter {
  std::string name;
  std::function<std::string(const XmlRpcValue&, NodeParameters*)> set;
};

// A parameter that is one field.
template <typename T>
Parameter field(const std::string& name, std::function<T&(NodeParameters&)> target) {
  return {name, [target](const XmlRpcValue& v, NodeParameters* p) {
            T value;
            if (!read_value(v, &value)) return std::string("expected ") + type_name(&value);
            target(*p) = value;
            return std::string();
          }};
}

// A parameter that takes one of `choices` (a string) and applies it.
Parameter choice(const std::string& name, const std::vector<std::string>& choices,
                 std::function<void(const std::string&, NodeParameters*)> apply) {
  return {name, [choices, apply](const XmlRpcValue& v, NodeParameters* p) {
            std::string value;
            std::string list;
            for (const std::string& c : choices) list += (list.empty() ? "" : ", ") + c;
            if (!read_value(v, &value)) return "expected one of " + list;
            for (const std::string& c : choices)
              if (value == c) return apply(value, p), std::string();
            return "'" + value + "' unknown (" + list + ")";
          }};
}

#define NODE_FIELD(type, path) \
  std::function<type&(NodeParameters&)>([](NodeParameters& p) -> type& { return p.path; })

// Every parameter, in the order they are applied: the preset first, so that the thresholds
// after it override it.
const std::vector<Parameter>& parameters() {
  static const std::vector<Parameter> table = {
      choice("preset", preset_names(),
             [](const std::string& v, NodeParameters* p) {
               preset_options(v, &p->odometry.estimator);
               p->preset = v;
             }),
      field<std::string>("odom_frame", NODE_FIELD(std::string, odom_frame)),
      field<std::string>("base_frame", NODE_FIELD(std::string, base_frame)),
      field<bool>("publish_tf", NODE_FIELD(bool, publish_tf)),
      field<bool>("stereo", NODE_FIELD(bool, stereo)),
      field<bool>("approximate_sync", NODE_FIELD(bool, approximate_sync)),
      choice("image_transport", {"raw", "compressed"},
             [](const std::string& v, NodeParameters* p) { p->compressed = v == "compressed"; }),
      field<bool>("rectify_fisheye", NODE_FIELD(bool, rectify_fisheye)),
      field<double>("rectified_fov_deg", NODE_FIELD(double, rectified_fov_deg)),
      field<int>("queue_size", NODE_FIELD(int, queue_size)),
      field<double>("camera_info_timeout", NODE_FIELD(double, camera_info_timeout)),
      field<int>("frame_queue_size", NODE_FIELD(int, frame_queue_size)),
      field<int>("frame_queue_spare", NODE_FIELD(int, frame_queue_spare)),
      field<double>("max_frame_gap", NODE_FIELD(double, stream.max_gap_s)),
      field<bool>("feature_points", NODE_FIELD(bool, feature_points)),
      field<bool>("feature_lines", NODE_FIELD(bool, feature_lines)),
      choice("feature_format", {"native", "vins"},
             [](const std::string& v, NodeParameters* p) { p->vins_format = v == "vins"; }),
      choice("points", {"klt", "sift", "orb"},
             [](const std::string& v, NodeParameters* p) {
               VisualOdometryOptions& o = p->odometry;
               if (v != "klt") {
                 o.point_source = PointFeatureSource::kDescriptors;
                 o.features.points.type =
                     v == "orb" ? PointFeatureType::kOrb : PointFeatureType::kSift;
               }
               p->points = v;
             }),
      choice("lines", {"fld", "lsd", "none"},
             [](const std::string& v, NodeParameters* p) {
               VisualOdometryOptions& o = p->odometry;
               o.use_lines = v != "none";
               if (v == "lsd") o.features.lines.detection.detector = LineDetector::kLsd;
               p->lines = v;
             }),
      field<int>("max_features", NODE_FIELD(int, odometry.features.points.max_features)),
      field<double>("min_parallax_px", NODE_FIELD(double, odometry.min_parallax_px)),
      field<bool>("rotation_only_pairs", NODE_FIELD(bool, odometry.rotation_only_pairs)),
      field<double>("keyframe_parallax_px", NODE_FIELD(double, odometry.keyframe_parallax_px)),
      field<double>("previous_keyframe_parallax_px",
                    NODE_FIELD(double, odometry.previous_keyframe_parallax_px)),
      field<double>("keyframe_overlap", NODE_FIELD(double, odometry.keyframe_overlap)),
      field<double>("keyframe_max_turn_deg", NODE_FIELD(double, odometry.keyframe_max_turn_deg)),
      field<int>("keyframe_min_points", NODE_FIELD(int, odometry.keyframe_min_points)),
      field<bool>("track_lines", NODE_FIELD(bool, odometry.track_lines)),
      field<bool>("line_flow", NODE_FIELD(bool, odometry.line_flow)),
      field<bool>("concurrent_frontend", NODE_FIELD(bool, odometry.concurrent)),
      field<double>("max_cpu_ms", NODE_FIELD(double, odometry.budget.max_cpu_ms)),
      field<int>("min_work_level", NODE_FIELD(int, odometry.budget.min_work_level)),
      field<int>("opencv_threads", NODE_FIELD(int, opencv_threads)),
      field<bool>("klt_predict_motion", NODE_FIELD(bool, odometry.klt.predict_motion)),
      field<int>("klt_window_px", NODE_FIELD(int, odometry.klt.window_px)),
      field<bool>("klt_redetect_alternate", NODE_FIELD(bool, odometry.klt.redetect_alternate)),
      field<bool>("klt_redetect_lost_cells",
                  NODE_FIELD(bool, odometry.klt.redetect_lost_cells)),
      field<bool>("klt_correct_vignetting",
                  NODE_FIELD(bool, odometry.klt.correct_vignetting)),
      field<double>("klt_min_corner_gradient",
                    NODE_FIELD(double, odometry.klt.min_corner_gradient)),
      field<double>("klt_min_corner_isotropy",
                    NODE_FIELD(double, odometry.klt.min_corner_isotropy)),
      // As bench_frontend's --seed: a run is repeatable, and results can be shown over seeds.
      {"ransac_seed",
       [](const XmlRpcValue& v, NodeParameters* p) {
         int value = 0;
         if (!read_value(v, &value) || value < 0) return std::string("expected an integer >= 0");
         p->odometry.estimator.ransac.seed = static_cast<uint64_t>(value);
         return std::string();
       }},
      field<double>("point_threshold_px",
                    NODE_FIELD(double, odometry.estimator.ransac.point_threshold_px)),
      field<double>("vp_threshold_deg",
                    NODE_FIELD(double, odometry.estimator.ransac.vp_threshold_deg)),
      field<double>("vp_inlier_threshold_px",
                    NODE_FIELD(double, odometry.estimator.vp_detection.inlier_threshold_px)),
      field<int>("vp_min_inliers", NODE_FIELD(int, odometry.estimator.vp_detection.min_inliers)),
      field<bool>("direction_map", NODE_FIELD(bool, odometry.use_direction_map)),
      field<bool>("anchor_orientation", NODE_FIELD(bool, odometry.anchor_orientation)),
      field<bool>("coast_blank_walls", NODE_FIELD(bool, odometry.orientation.coast_blank_walls)),
      field<bool>("translation_given_rotation",
                  NODE_FIELD(bool, odometry.orientation.translation_given_rotation)),
      field<double>("rotation_calibration_sigma",
                    NODE_FIELD(double, odometry.rotation_calibration_sigma)),
      field<double>("mono_scale", NODE_FIELD(double, odometry.mono_scale)),
      field<int>("mono_window_keyframes", NODE_FIELD(int, odometry.mono_window_keyframes)),
      field<double>("stereo_max_depth_baselines",
                    NODE_FIELD(double, odometry.stereo_scale.max_depth_baselines)),
      field<bool>("stereo_offset_calibration", NODE_FIELD(bool, odometry.stereo_offset.enabled)),
      field<bool>("stereo_refine_tracks", NODE_FIELD(bool, odometry.stereo_refine_tracks)),
      field<bool>("publish_debug_image", NODE_FIELD(bool, publish_debug_image)),
      field<bool>("publish_markers", NODE_FIELD(bool, publish_markers)),
      field<int>("path_max_poses", NODE_FIELD(int, path_max_poses)),
      field<double>("min_frequency", NODE_FIELD(double, min_frequency)),
      field<double>("max_frequency", NODE_FIELD(double, max_frequency)),
  };
  return table;
}

#undef NODE_FIELD

// Old names that still work, each for the parameter that replaced it.
struct Renamed {
  std::string old_name, name;
};
const std::vector<Renamed>& renamed_parameters() {
  // Issue 43: the VP tracker became the map of world directions; issue 53: the keyframe's
  // overlap rule holds for every frame that keeps it, not only for a rotation alone.
  static const std::vector<Renamed> table = {{"vp_tracker", "direction_map"},
                                             {"rotation_keyframe_overlap", "keyframe_overlap"}};
  return table;
}

// The name under which `params` holds the parameter `name`: its own, else an old one (empty:
// neither). Old names are reported, and ignored beside the new one.
std::string given_name(const XmlRpcValue& params, const std::string& name,
                       std::vector<std::string>* warnings) {
  const bool given = params.hasMember(name);
  for (const Renamed& r : renamed_parameters()) {
    if (r.name != name || !params.hasMember(r.old_name)) continue;
    warnings->push_back(r.old_name + ": deprecated, use " + r.name +
                        (given ? " (ignored: " + r.name + " is set too)"
                               : " (taken as " + r.name + ")"));
    if (!given) return r.old_name;
  }
  return given ? name : std::string();
}

}  // namespace

NodeParameters::NodeParameters() {
  preset_options(preset, &odometry.estimator);
  // 6, not the pair tools' 15: the video front end's FLD segments are fewer and shorter, and the
  // VP tracker already keeps only VPs that persist (KITTI and demo AUC@10 +1.5 and +1.2 at 6).
  odometry.estimator.vp_detection.min_inliers = 6;
}

NodeParameters read_node_parameters(const XmlRpcValue& params, std::vector<std::string>* warnings) {
  NodeParameters out;
  const bool have = params.getType() == XmlRpcValue::TypeStruct;
  std::set<std::string> known;
  for (const Renamed& r : renamed_parameters()) known.insert(r.old_name);
  for (const Parameter& parameter : parameters()) {
    known.insert(parameter.name);
    const std::string name = have ? given_name(params, parameter.name, warnings) : "";
    if (name.empty()) continue;
    NodeParameters candidate = out;
    std::string problem = parameter.set(params[name], &candidate);
    if (problem.empty()) problem = validate(candidate);
    if (problem.empty()) {
      out = candidate;
    } else {
      warnings->push_back(name + ": " + problem + "; keeping the default");
    }
  }
  if (have) {
    XmlRpcValue all = params;  // XmlRpcValue iterates only when mutable
    for (auto it = all.begin(); it != all.end(); ++it)
      if (!known.count(it->first)) warnings->push_back(it->first + ": not a parameter of the node");
  }
  return out;
}

std::vector<std::string> node_parameter_names() {
  std::vector<std::string> names;
  for (const Parameter& parameter : parameters()) names.push_back(parameter.name);
  return names;
}

}  // namespace hybrid_vo
