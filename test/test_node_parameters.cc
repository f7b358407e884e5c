// The node's ROS parameters: every one that config/default.yaml lists is read, each set to a value
// other than its default changes what the node runs with, bad values and misspelt names are
// reported and leave the default, and the options validate themselves (validate()).
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "hybrid_vo/node/node_parameters.h"
#include "hybrid_vo/node/parameters_file.h"

namespace hybrid_vo {
namespace {

using XmlRpc::XmlRpcValue;

std::string read_text(const std::string& relative) {
  std::ifstream in(std::string(HYBRID_VO_SOURCE_DIR) + "/" + relative);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The top-level keys of a YAML file of parameters (`name: value` at the start of a line).
std::set<std::string> yaml_keys(const std::string& relative) {
  std::set<std::string> keys;
  std::istringstream lines(read_text(relative));
  const std::regex key(R"(^([a-z_0-9]+):)");
  std::smatch m;
  for (std::string line; std::getline(lines, line);)
    if (std::regex_search(line, m, key)) keys.insert(m[1]);
  return keys;
}

NodeParameters read_one(const std::string& name, const XmlRpcValue& value,
                        std::vector<std::string>* warnings) {
  XmlRpcValue params;
  params[name] = value;
  return read_node_parameters(params, warnings);
}

// One parameter set to a value other than its default, and what must then differ.
struct Case {
  std::string name;
  XmlRpcValue value;
  std::function<bool(const NodeParameters&)> took_effect;
};

std::vector<Case> every_parameter() {
  using P = const NodeParameters&;
  return {
      {"preset", "5pc",
       [](P p) { return !p.odometry.estimator.ransac.enabled[7] && p.preset == "5pc"; }},
      {"odom_frame", "world", [](P p) { return p.odom_frame == "world"; }},
      {"base_frame", "robot", [](P p) { return p.base_frame == "robot"; }},
      {"publish_tf", false, [](P p) { return !p.publish_tf; }},
      {"stereo", true, [](P p) { return p.stereo; }},
      {"approximate_sync", true, [](P p) { return p.approximate_sync; }},
      {"image_transport", "compressed", [](P p) { return p.compressed; }},
      {"rectify_fisheye", false, [](P p) { return !p.rectify_fisheye; }},
      {"rectified_fov_deg", 120.0, [](P p) { return p.rectified_fov_deg == 120.0; }},
      {"queue_size", 3, [](P p) { return p.queue_size == 3; }},
      {"camera_info_timeout", 5.0, [](P p) { return p.camera_info_timeout == 5.0; }},
      {"frame_queue_size", 4, [](P p) { return p.frame_queue_size == 4; }},
      {"frame_queue_spare", 0, [](P p) { return p.frame_queue_spare == 0; }},
      {"max_frame_gap", 2.5, [](P p) { return p.stream.max_gap_s == 2.5; }},
      {"feature_points", true, [](P p) { return p.feature_points; }},
      {"feature_lines", true, [](P p) { return p.feature_lines; }},
      {"feature_format", "vins", [](P p) { return p.vins_format; }},
      {"points", "orb",
       [](P p) {
         return p.odometry.point_source == PointFeatureSource::kDescriptors &&
                p.odometry.features.points.type == PointFeatureType::kOrb;
       }},
      {"lines", "lsd",
       [](P p) { return p.odometry.features.lines.detection.detector == LineDetector::kLsd; }},
      {"max_features", 321, [](P p) { return p.odometry.features.points.max_features == 321; }},
      {"min_parallax_px", 3.5, [](P p) { return p.odometry.min_parallax_px == 3.5; }},
      {"rotation_only_pairs", false, [](P p) { return !p.odometry.rotation_only_pairs; }},
      {"keyframe_overlap", 0.5, [](P p) { return p.odometry.keyframe_overlap == 0.5; }},
      {"keyframe_max_turn_deg", 15.0, [](P p) { return p.odometry.keyframe_max_turn_deg == 15.0; }},
      {"keyframe_parallax_px", 9.0, [](P p) { return p.odometry.keyframe_parallax_px == 9.0; }},
      {"keyframe_min_points", 50, [](P p) { return p.odometry.keyframe_min_points == 50; }},
      {"previous_keyframe_parallax_px", 4.5,
       [](P p) { return p.odometry.previous_keyframe_parallax_px == 4.5; }},
      {"track_lines", false, [](P p) { return !p.odometry.track_lines; }},
      {"line_flow", true, [](P p) { return p.odometry.line_flow; }},
      {"concurrent_frontend", false, [](P p) { return !p.odometry.concurrent; }},
      {"max_cpu_ms", 8.5, [](P p) { return p.odometry.budget.max_cpu_ms == 8.5; }},
      {"min_work_level", 2, [](P p) { return p.odometry.budget.min_work_level == 2; }},
      {"opencv_threads", -1, [](P p) { return p.opencv_threads == -1; }},
      {"klt_predict_motion", false, [](P p) { return !p.odometry.klt.predict_motion; }},
      {"klt_window_px", 21, [](P p) { return p.odometry.klt.window_px == 21; }},
      {"klt_redetect_alternate", true, [](P p) { return p.odometry.klt.redetect_alternate; }},
      {"klt_redetect_lost_cells", true,
       [](P p) { return p.odometry.klt.redetect_lost_cells; }},
      {"klt_correct_vignetting", false,
       [](P p) { return !p.odometry.klt.correct_vignetting; }},
      {"klt_min_corner_gradient", 1.5,
       [](P p) { return p.odometry.klt.min_corner_gradient == 1.5; }},
      {"klt_min_corner_isotropy", 0.3,
       [](P p) { return p.odometry.klt.min_corner_isotropy == 0.3; }},
      {"ransac_seed", 4, [](P p) { return p.odometry.estimator.ransac.seed == 4u; }},
      {"point_threshold_px", 2.0,
       [](P p) { return p.odometry.estimator.ransac.point_threshold_px == 2.0; }},
      {"vp_threshold_deg", 3.0,
       [](P p) { return p.odometry.estimator.ransac.vp_threshold_deg == 3.0; }},
      {"vp_inlier_threshold_px", 1.0,
       [](P p) { return p.odometry.estimator.vp_detection.inlier_threshold_px == 1.0; }},
      {"vp_min_inliers", 15,
       [](P p) { return p.odometry.estimator.vp_detection.min_inliers == 15; }},
      {"direction_map", false, [](P p) { return !p.odometry.use_direction_map; }},
      {"anchor_orientation", false, [](P p) { return !p.odometry.anchor_orientation; }},
      {"coast_blank_walls", true, [](P p) { return p.odometry.orientation.coast_blank_walls; }},
      {"translation_given_rotation", true,
       [](P p) { return p.odometry.orientation.translation_given_rotation; }},
      {"rotation_calibration_sigma", 0.02,
       [](P p) { return p.odometry.rotation_calibration_sigma == 0.02; }},
      {"mono_scale", 0.5, [](P p) { return p.odometry.mono_scale == 0.5; }},
      {"mono_window_keyframes", 0, [](P p) { return p.odometry.mono_window_keyframes == 0; }},
      {"stereo_max_depth_baselines", 60.0,
       [](P p) { return p.odometry.stereo_scale.max_depth_baselines == 60.0; }},
      {"stereo_offset_calibration", false, [](P p) { return !p.odometry.stereo_offset.enabled; }},
      {"stereo_refine_tracks", false, [](P p) { return !p.odometry.stereo_refine_tracks; }},
      {"publish_debug_image", false, [](P p) { return !p.publish_debug_image; }},
      {"publish_markers", false, [](P p) { return !p.publish_markers; }},
      {"path_max_poses", 10, [](P p) { return p.path_max_poses == 10; }},
      {"min_frequency", 5.0, [](P p) { return p.min_frequency == 5.0; }},
      {"max_frequency", 15.0, [](P p) { return p.max_frequency == 15.0; }},
  };
}

TEST(NodeParameters, EveryParameterOfTheConfigIsReadAndNoOther) {
  const std::vector<std::string> names = node_parameter_names();
  const std::set<std::string> read(names.begin(), names.end());
  EXPECT_EQ(read.size(), names.size()) << "a parameter is read twice";
  EXPECT_EQ(yaml_keys("config/default.yaml"), read);
  std::set<std::string> tested;
  for (const Case& c : every_parameter()) tested.insert(c.name);
  EXPECT_EQ(tested, read) << "every parameter needs a case below";
  // The documentation's parameter table names each one.
  const std::string doc = read_text("doc/node.md");
  for (const std::string& name : names)
    EXPECT_NE(doc.find("`" + name + "`"), std::string::npos) << name << " is not in doc/node.md";
}

TEST(NodeParameters, EachParameterChangesWhatTheNodeRunsWith) {
  std::vector<std::string> warnings;
  const NodeParameters defaults = read_node_parameters(XmlRpcValue(), &warnings);
  EXPECT_TRUE(warnings.empty());
  for (const Case& c : every_parameter()) {
    EXPECT_FALSE(c.took_effect(defaults)) << c.name << ": the default already passes the check";
    const NodeParameters p = read_one(c.name, c.value, &warnings);
    EXPECT_TRUE(c.took_effect(p)) << c.name;
    EXPECT_TRUE(warnings.empty()) << c.name << ": " << (warnings.empty() ? "" : warnings[0]);
    EXPECT_EQ(validate(p), "") << c.name;
  }
}

TEST(NodeParameters, TheDefaultsAreTheNodesOwn) {
  std::vector<std::string> warnings;
  const NodeParameters p = read_node_parameters(XmlRpcValue(), &warnings);
  EXPECT_EQ(p.odometry.estimator.vp_detection.min_inliers, 6);  // not the pair tools' 15
  EXPECT_EQ(p.odometry.features.points.max_features, 1000);
  RelativePoseEstimatorOptions hybrid;
  preset_options("hybrid", &hybrid);
  EXPECT_EQ(p.odometry.estimator.ransac.enabled, hybrid.ransac.enabled);
  EXPECT_EQ(p.preset, "hybrid");
  // A threshold set beside a preset overrides it, in whichever order the server lists them.
  XmlRpcValue params;
  params["point_threshold_px"] = 2.0;
  params["preset"] = "hybrid+junc";
  const NodeParameters both = read_node_parameters(params, &warnings);
  EXPECT_EQ(both.odometry.estimator.ransac.point_threshold_px, 2.0);
  EXPECT_TRUE(both.odometry.estimator.use_junction_points);
}

TEST(NodeParameters, BadValuesAndUnknownNamesAreReportedAndKeepTheDefault) {
  const NodeParameters defaults;
  struct Bad {
    std::string name;
    XmlRpcValue value;
    std::string says;
  };
  const std::vector<Bad> bad = {
      {"vp_min_inliers", 1, "must be >= 2"},
      {"klt_window_px", 3, "must be in [5, 401]"},
      {"klt_window_px", 402, "must be in [5, 401]"},
      {"frame_queue_size", 0, "must be >= 1"},
      {"frame_queue_spare", -1, "must be >= 0"},
      {"rectified_fov_deg", 5.0, "must be in [10, 170]"},
      {"max_frame_gap", 0.0, "must be > 0"},
      {"point_threshold_px", -1.0, "must be > 0"},
      {"ransac_seed", -3, "expected an integer >= 0"},
      {"image_transport", "theora", "'theora' unknown"},
      {"preset", "6pc", "'6pc' unknown"},
      {"stereo", "yes", "expected a boolean"},
      {"max_features", "many", "expected an integer"},
  };
  for (const Bad& b : bad) {
    std::vector<std::string> warnings;
    const NodeParameters p = read_one(b.name, b.value, &warnings);
    ASSERT_EQ(warnings.size(), 1u) << b.name;
    EXPECT_EQ(warnings[0].rfind(b.name + ": ", 0), 0u) << warnings[0];
    EXPECT_NE(warnings[0].find(b.says), std::string::npos) << warnings[0];
    EXPECT_EQ(p.odometry.estimator.vp_detection.min_inliers, 6);
    EXPECT_EQ(p.odometry.klt.window_px, defaults.odometry.klt.window_px);
    EXPECT_EQ(p.frame_queue_size, 1);
    EXPECT_EQ(p.frame_queue_spare, 2);
    EXPECT_EQ(p.rectified_fov_deg, 100.0);
    EXPECT_FALSE(p.stereo || p.compressed);
    EXPECT_EQ(p.preset, "hybrid");
  }
  std::vector<std::string> warnings;
  read_one("point_treshold_px", 2.0, &warnings);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "point_treshold_px: not a parameter of the node");
  // As roscpp reads them: an integer where a number is expected, a number rounded to an integer.
  warnings.clear();
  EXPECT_EQ(read_one("mono_scale", 2, &warnings).odometry.mono_scale, 2.0);
  EXPECT_EQ(read_one("max_features", 499.6, &warnings).odometry.features.points.max_features, 500);
  EXPECT_TRUE(warnings.empty());
}

// A renamed parameter's old name still takes effect, with a warning that names the new one (the
// node logs each warning once, at start-up); beside the new name it is ignored.
TEST(NodeParameters, OldNamesStillWorkAndWarn) {
  std::vector<std::string> warnings;
  const NodeParameters p = read_one("vp_tracker", false, &warnings);
  EXPECT_FALSE(p.odometry.use_direction_map);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], "vp_tracker: deprecated, use direction_map (taken as direction_map)");
  XmlRpcValue both;
  both["vp_tracker"] = false;
  both["direction_map"] = true;
  warnings.clear();
  EXPECT_TRUE(read_node_parameters(both, &warnings).odometry.use_direction_map);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("ignored"), std::string::npos) << warnings[0];
  // A bad value under the old name is named under it.
  warnings.clear();
  EXPECT_TRUE(read_one("vp_tracker", "no", &warnings).odometry.use_direction_map);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_EQ(warnings[1], "vp_tracker: expected a boolean; keeping the default");
  // No config file uses it any more.
  for (const char* config : {"default", "kitti", "lamar", "low_texture"})
    EXPECT_EQ(yaml_keys(std::string("config/") + config + ".yaml").count("vp_tracker"), 0u)
        << config;
}

// The tools read config/*.yaml without a parameter server (hybrid_vo_bench_frontend --config): the
// same types rosparam gives, the same node options, and a clear error for what is not flat.
TEST(ParametersFile, FlatYamlTypesAsRosparamGivesThem) {
  XmlRpcValue p;
  std::string error;
  ASSERT_TRUE(parse_flat_yaml("# a comment\n---\na: true   # why\nb: 3\nc: -2.5e-1\nd: .5\n"
                              "e: hybrid+junc\nf: \"x # y\"\ng: 'q'\nh: Off\n\r\n",
                              &p, &error))
      << error;
  EXPECT_EQ(p["a"].getType(), XmlRpcValue::TypeBoolean);
  EXPECT_TRUE(static_cast<bool>(p["a"]));
  EXPECT_EQ(p["b"].getType(), XmlRpcValue::TypeInt);
  EXPECT_EQ(static_cast<int>(p["b"]), 3);
  EXPECT_EQ(p["c"].getType(), XmlRpcValue::TypeDouble);
  EXPECT_DOUBLE_EQ(static_cast<double>(p["c"]), -0.25);
  EXPECT_DOUBLE_EQ(static_cast<double>(p["d"]), 0.5);
  EXPECT_EQ(static_cast<std::string>(p["e"]), "hybrid+junc");
  EXPECT_EQ(static_cast<std::string>(p["f"]), "x # y");
  EXPECT_EQ(static_cast<std::string>(p["g"]), "q");
  EXPECT_FALSE(static_cast<bool>(p["h"]));
  // An empty file is an empty namespace, not an error.
  ASSERT_TRUE(parse_flat_yaml("", &p, &error));
  EXPECT_EQ(p.getType(), XmlRpcValue::TypeStruct);
  EXPECT_EQ(p.size(), 0);
}

TEST(ParametersFile, WhatIsNotAFlatEntryIsRefusedWithItsLine) {
  XmlRpcValue p;
  for (const char* bad : {"a: 1\nnested:\n  b: 2\n", "a: 1\n  b: 2\n", "a: [1, 2]\n",
                          "a: 1\na: 2\n", "just text\n", "a: \"open\n", "a: 99999999999\n",
                          "a: |\n"}) {
    std::string error;
    EXPECT_FALSE(parse_flat_yaml(bad, &p, &error)) << bad;
    EXPECT_NE(error.find("line "), std::string::npos) << bad << " -> " << error;
  }
}

TEST(ParametersFile, EveryShippedConfigIsReadAsTheNodeReadsIt) {
  for (const char* config : {"default", "kitti", "lamar", "low_texture"}) {
    NodeParameters p;
    std::vector<std::string> warnings;
    std::string error;
    const std::string path = std::string(HYBRID_VO_SOURCE_DIR) + "/config/" + config + ".yaml";
    ASSERT_TRUE(read_node_parameters_file(path, {}, &p, &warnings, &error)) << error;
    EXPECT_TRUE(warnings.empty()) << config << ": " << warnings.front();
  }
  // default.yaml holds the node's defaults; an override replaces the file's value before the
  // file is read, so the preset's thresholds still come after it.
  NodeParameters file, overridden;
  std::vector<std::string> warnings;
  std::string error;
  const std::string path = std::string(HYBRID_VO_SOURCE_DIR) + "/config/default.yaml";
  ASSERT_TRUE(read_node_parameters_file(path, {}, &file, &warnings, &error)) << error;
  const NodeParameters defaults = read_node_parameters(XmlRpcValue(), &warnings);
  EXPECT_EQ(file.preset, defaults.preset);
  EXPECT_EQ(file.odometry.features.points.max_features,
            defaults.odometry.features.points.max_features);
  EXPECT_EQ(file.odometry.keyframe_parallax_px, defaults.odometry.keyframe_parallax_px);
  EXPECT_EQ(file.odometry.estimator.ransac.enabled, defaults.odometry.estimator.ransac.enabled);
  ASSERT_TRUE(read_node_parameters_file(
      path, {{"preset", "hybrid+junc"}, {"max_features", "700"}, {"ransac_seed", "3"}},
      &overridden, &warnings, &error))
      << error;
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ(overridden.preset, "hybrid+junc");
  EXPECT_TRUE(overridden.odometry.estimator.use_junction_points);
  EXPECT_EQ(overridden.odometry.features.points.max_features, 700);
  EXPECT_EQ(overridden.odometry.estimator.ransac.seed, 3u);
  EXPECT_EQ(overridden.odometry.estimator.ransac.point_threshold_px,
            file.odometry.estimator.ransac.point_threshold_px);
  // A missing file and a bad override are errors, not the defaults.
  EXPECT_FALSE(read_node_parameters_file(path + ".missing", {}, &file, &warnings, &error));
  EXPECT_NE(error.find("cannot be read"), std::string::npos);
  EXPECT_FALSE(read_node_parameters_file(path, {{"max_features", "[1]"}}, &file, &warnings, &error));
}

TEST(OptionFields, ValidateNamesTheFirstFieldOutOfBounds) {
  TwoViewOptions options;
  EXPECT_EQ(validate(options), "");
  options.ransac.confidence = 1.0;
  EXPECT_EQ(validate(options), "confidence: must be in (0, 1), got 1");
  options.ransac.confidence = 0.99;
  options.junctions.tolerance_px = -1.0;
  EXPECT_EQ(validate(options), "junctions_tolerance_px: must be >= 0, got -1");
  options.junctions.tolerance_px = 3.0;
  options.ransac.prior[3] = -2.0;
  EXPECT_EQ(validate(options), "prior[3]: must be >= 0, got -2");
  options.ransac.prior[3] = 1.0;
  options.vp_detection.inlier_threshold_px = std::nan("");
  EXPECT_EQ(validate(options), "vp_detection_inlier_threshold_px: must be > 0, got nan");
}

}  // namespace
}  // namespace hybrid_vo
