// Which folder may include which, checked on the sources themselves (doc/development.md, Layout).
//   - The core (geometry, solvers, estimation, lines, direction_map, synthetic) links Eigen and
//     Ceres only, and each layer includes only the layers before it (DESIGN.md: geometry <-
//     solvers <- estimation <- lines <- direction_map <- features <- odometry <- node); synthetic
//     data may use all of the core.
//   - The front end is the OpenCV layer, in two folders with a one-way arrow: features (the image
//     features: detection, description, matching, tracking, stereo, camera models) may use the
//     core and OpenCV; odometry (VisualOdometry and the policies that schedule the features) may
//     also use features. Nothing in features uses odometry.
//   - datasets, render and evaluation may use the core, the front end and OpenCV; conversion may
//     also use datasets, render (the bag's camera frames are the renderer's) and ROS (rosbag and
//     messages). Nothing in the core, the front end or the node uses any of the four.
//   - src/python binds the core and the front end; src/tools holds only mains, and may use
//     everything.
//   - Every folder under src/ and include/hybrid_vo/ has a rule: a new folder fails until it gets
//     one here.
// A quoted include without the hybrid_vo/ prefix must be a private header of the same folder.
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "file_test_utils.h"

namespace {

namespace fs = std::filesystem;
using hybrid_vo::testing::TempDir;
using hybrid_vo::testing::write_file;

// What an include is: a folder of ours ("geometry", ...), "messages" (our generated hybrid_vo/*.h),
// "own" (a private header beside the file), or a third party: "opencv", "ros", "pybind11",
// "opengv"; "always" for the standard library, Eigen and Ceres.
const std::set<std::string> kRos = {
    "ros", "rosbag", "roscpp", "nodelet", "pluginlib", "cv_bridge", "image_transport",
    "message_filters", "tf2", "tf2_ros", "tf2_msgs", "tf2_eigen", "tf2_geometry_msgs",
    "std_msgs", "std_srvs", "sensor_msgs", "geometry_msgs", "nav_msgs", "visualization_msgs",
    "diagnostic_updater", "diagnostic_msgs", "rosgraph_msgs", "xmlrpcpp"};

std::set<std::string> operator+(std::set<std::string> a, const std::set<std::string>& b) {
  a.insert(b.begin(), b.end());
  return a;
}

const std::set<std::string> kCore = {"geometry", "solvers",       "estimation",
                                      "lines",    "direction_map", "synthetic"};
// The front end: features, and odometry above it (odometry may use features, not the reverse).
const std::set<std::string> kFeatures = kCore + std::set<std::string>{"features", "opencv"};
const std::set<std::string> kOpenCvLibrary = kFeatures + std::set<std::string>{"odometry"};

// Per folder (under src/ and include/hybrid_vo/ alike), what its files may include.
const std::map<std::string, std::set<std::string>> kRules = {
    {"geometry", {"geometry"}},
    {"solvers", {"geometry", "solvers"}},
    {"estimation", {"geometry", "solvers", "estimation"}},
    {"lines", {"geometry", "solvers", "estimation", "lines"}},
    {"direction_map", {"geometry", "solvers", "estimation", "lines", "direction_map"}},
    {"synthetic", kCore},
    {"features", kFeatures},
    {"odometry", kOpenCvLibrary},
    {"node", kOpenCvLibrary + std::set<std::string>{"node", "messages", "ros"}},
    {"nodes", kOpenCvLibrary + std::set<std::string>{"node", "messages", "ros"}},
    {"datasets", kOpenCvLibrary + std::set<std::string>{"datasets"}},
    {"render", kOpenCvLibrary + std::set<std::string>{"render"}},
    {"evaluation", kOpenCvLibrary + std::set<std::string>{"evaluation"}},
    {"conversion",
     kOpenCvLibrary + std::set<std::string>{"datasets", "render", "conversion", "ros"}},
    {"python", kOpenCvLibrary + std::set<std::string>{"pybind11"}},
    {"tools", kOpenCvLibrary + std::set<std::string>{"node", "messages", "ros", "datasets",
                                                     "render", "evaluation", "conversion",
                                                     "opengv"}},
};

// Folders of executables and bindings: sources only, never public headers.
const std::set<std::string> kSourceOnly = {"nodes", "tools", "python"};

std::string kind_of(const std::string& target) {
  if (target.rfind("hybrid_vo/", 0) == 0) {
    const size_t slash = target.find('/', 10);
    return slash == std::string::npos ? "messages" : target.substr(10, slash - 10);
  }
  const std::string first = target.substr(0, target.find('/'));
  if (first == "opencv2" || first == "opencv") return "opencv";
  if (kRos.count(first)) return "ros";
  if (first == "pybind11" || first == "opengv") return first;
  return "always";
}

// Every violation in the tree at `root`, one readable line each; empty when the tree is clean.
std::vector<std::string> violations(const fs::path& root) {
  std::vector<std::string> found;
  const std::regex include_re(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"])");
  const std::regex main_re(R"(\bint\s+main\s*\()");
  for (const fs::path& base : {root / "src", root / "include" / "hybrid_vo"}) {
    if (!fs::exists(base)) continue;
    for (const auto& folder : fs::directory_iterator(base)) {
      const std::string name = folder.path().filename().string();
      if (!folder.is_directory()) {
        found.push_back(folder.path().string() + " is outside every folder");
        continue;
      }
      const auto rule = kRules.find(name);
      if (rule == kRules.end() || (base != root / "src" && kSourceOnly.count(name))) {
        found.push_back(folder.path().string() + " is a folder test_layers has no rule for");
        continue;
      }
      const bool mains_only = base == root / "src" && name == "tools";
      for (const auto& entry : fs::recursive_directory_iterator(folder.path())) {
        if (!entry.is_regular_file()) continue;
        const fs::path& file = entry.path();
        std::ifstream in(file);
        std::stringstream text;
        text << in.rdbuf();
        if (mains_only && (file.extension() != ".cc" || !std::regex_search(text.str(), main_re)))
          found.push_back(file.string() + " is not a main, and src/tools holds only mains");
        std::string line;
        std::smatch m;
        while (std::getline(text, line)) {
          if (!std::regex_search(line, m, include_re)) continue;
          const std::string target = m[2];
          const bool ours = target.rfind("hybrid_vo/", 0) == 0;
          const std::string kind = kind_of(target);
          if (!ours && m[1] == "\"") {
            // A private header: a plain name, beside the file.
            if (target.find('/') != std::string::npos ||
                !fs::exists(file.parent_path() / target))
              found.push_back(file.string() + " includes \"" + target +
                              "\", which is not beside it (ours are hybrid_vo/<folder>/...)");
            continue;
          }
          if (kind == "always" || rule->second.count(kind)) continue;
          if (ours && kind != "messages" && !kRules.count(kind))
            found.push_back(file.string() + " includes " + target + " of no known folder");
          else
            found.push_back(file.string() + " includes " + target + ": " + name +
                            " may not use " + kind);
        }
      }
    }
  }
  return found;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += "  " + line + "\n";
  return text;
}

TEST(Layers, SourceTreeKeepsTheRules) {
  const std::vector<std::string> found = violations(HYBRID_VO_SOURCE_DIR);
  EXPECT_TRUE(found.empty()) << found.size() << " violation(s):\n" << joined(found);
}

// The rules themselves: every folder of the source tree has one (an unknown folder fails above),
// and the ones the issue names hold.
TEST(Layers, RulesKeepTheLibrariesOutOfTheCoreAndTheFrontEnd) {
  for (const std::string& folder :
       kCore + std::set<std::string>{"features", "odometry", "node", "python"})
    for (const char* library : {"datasets", "render", "evaluation", "conversion", "tools"})
      EXPECT_FALSE(kRules.at(folder).count(library)) << folder << " may use " << library;
  for (const std::string& folder : kCore)
    for (const char* external : {"opencv", "ros", "messages"})
      EXPECT_FALSE(kRules.at(folder).count(external)) << folder << " may use " << external;
  for (const char* library : {"datasets", "render", "evaluation"})
    EXPECT_FALSE(kRules.at(library).count("ros")) << library << " may use ROS";
  // The arrow between the front end's two folders points one way only.
  EXPECT_TRUE(kRules.at("odometry").count("features"));
  EXPECT_FALSE(kRules.at("features").count("odometry"));
  EXPECT_TRUE(kRules.at("conversion").count("datasets"));
  EXPECT_TRUE(kRules.at("conversion").count("ros"));
}

// The checker on small trees written here: each forbidden include must be reported, and a tree
// that keeps the rules must not be.
struct BadTree {
  const char* what;
  const char* file;     // under the temporary root
  const char* content;
  const char* report;   // a part of the expected report
};

class LayersSelfCheck : public ::testing::TestWithParam<BadTree> {};

TEST_P(LayersSelfCheck, ReportsTheViolation) {
  const BadTree& bad = GetParam();
  TempDir dir("hybrid_vo_layers");
  // A clean base: a core header, the front end's sources (features, and odometry using them), a
  // conversion source and a main.
  write_file(dir.path() / "include/hybrid_vo/geometry/pose.h", "#include <Eigen/Core>\n");
  write_file(dir.path() / "src/features/frontend.cc",
             "#include <opencv2/core.hpp>\n#include \"hybrid_vo/geometry/pose.h\"\n");
  write_file(dir.path() / "src/odometry/visual_odometry.cc",
             "#include <opencv2/core.hpp>\n#include \"hybrid_vo/features/frontend.h\"\n");
  write_file(dir.path() / "src/conversion/bag.cc",
             "#include <rosbag/bag.h>\n#include \"hybrid_vo/datasets/kitti.h\"\n");
  write_file(dir.path() / "src/tools/tool.cc",
             "#include \"hybrid_vo/evaluation/plot.h\"\nint main(int argc, char** argv) {}\n");
  ASSERT_TRUE(violations(dir.path()).empty()) << joined(violations(dir.path()));

  write_file(dir.path() / bad.file, bad.content);
  const std::vector<std::string> found = violations(dir.path());
  ASSERT_EQ(found.size(), 1u) << bad.what << ":\n" << joined(found);
  // The report names the file (or, for a folder without a rule, the folder).
  EXPECT_TRUE(hybrid_vo::testing::contains(found[0], fs::path(bad.file).parent_path().string()));
  EXPECT_TRUE(hybrid_vo::testing::contains(found[0], bad.report));
}

INSTANTIATE_TEST_SUITE_P(
    Trees, LayersSelfCheck,
    ::testing::Values(
        BadTree{"core uses evaluation", "src/estimation/ransac.cc",
                "#include \"hybrid_vo/evaluation/statistics.h\"\n",
                "estimation may not use evaluation"},
        BadTree{"core uses a later layer", "include/hybrid_vo/geometry/camera.h",
                "#include \"hybrid_vo/solvers/relpose_5pt.h\"\n", "geometry may not use solvers"},
        BadTree{"core uses OpenCV", "src/lines/vp.cc", "#include <opencv2/core.hpp>\n",
                "lines may not use opencv"},
        BadTree{"features use datasets", "src/features/camera.cc",
                "#include \"hybrid_vo/datasets/sequence.h\"\n", "features may not use datasets"},
        BadTree{"odometry uses datasets", "src/odometry/keyframes.cc",
                "#include \"hybrid_vo/datasets/sequence.h\"\n", "odometry may not use datasets"},
        BadTree{"features use odometry", "include/hybrid_vo/features/klt_tracker.h",
                "#include \"hybrid_vo/odometry/cpu_budget.h\"\n", "features may not use odometry"},
        BadTree{"node uses render", "src/node/node.cc", "#include \"hybrid_vo/render/scene.h\"\n",
                "node may not use render"},
        BadTree{"evaluation uses ROS", "src/evaluation/plot.cc", "#include <ros/time.h>\n",
                "evaluation may not use ros"},
        BadTree{"datasets uses conversion", "include/hybrid_vo/datasets/kitti.h",
                "#include \"hybrid_vo/conversion/bag_writing.h\"\n",
                "datasets may not use conversion"},
        BadTree{"an unknown folder of ours", "src/render/scene.cc",
                "#include \"hybrid_vo/misc/helpers.h\"\n", "of no known folder"},
        BadTree{"a header reached from elsewhere", "src/render/scene.cc",
                "#include \"../evaluation/plot.h\"\n", "not beside it"},
        BadTree{"a folder without a rule", "src/misc/helpers.cc", "int helper() { return 1; }\n",
                "no rule for"},
        BadTree{"public headers of the tools", "include/hybrid_vo/tools/args.h", "#pragma once\n",
                "no rule for"},
        BadTree{"a header in src/tools", "src/tools/helpers.h", "#pragma once\n",
                "holds only mains"},
        BadTree{"a library source in src/tools", "src/tools/helpers.cc",
                "int helper() { return 1; }\n", "holds only mains"}),
    [](const ::testing::TestParamInfo<BadTree>& info) {
      std::string name = info.param.what;
      for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
      return name;
    });

}  // namespace
