// The core (geometry, solvers, estimation, lines, synthetic) links Eigen and Ceres only, and each
// layer includes only the layers before it (DESIGN.md: geometry <- solvers <- estimation <- lines
// <- frontend <- node). Checked on the sources themselves.
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

const std::vector<std::string> kLayers = {"geometry", "solvers", "estimation", "lines",
                                          "synthetic", "frontend", "node"};

int rank_of(const std::string& layer) {
  for (size_t i = 0; i < kLayers.size(); ++i)
    if (kLayers[i] == layer) return static_cast<int>(i);
  return -1;
}

struct Include {
  std::string file, target;
};

// Every #include of every file of a layer (header and source folders).
std::vector<Include> includes_of(const std::string& layer) {
  std::vector<Include> result;
  const fs::path root(HYBRID_VO_SOURCE_DIR);
  const std::regex include_re(R"(^\s*#\s*include\s*[<"]([^>"]+)[>"])");
  for (const fs::path& dir : {root / "include" / "hybrid_vo" / layer, root / "src" / layer}) {
    if (!fs::exists(dir)) continue;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
      if (!entry.is_regular_file()) continue;
      std::ifstream in(entry.path());
      std::string line;
      std::smatch m;
      while (std::getline(in, line))
        if (std::regex_search(line, m, include_re)) result.push_back({entry.path().string(), m[1]});
    }
  }
  return result;
}

class LayerTest : public ::testing::TestWithParam<std::string> {};

TEST_P(LayerTest, IncludesOnlyEarlierLayers) {
  const int own = rank_of(GetParam());
  for (const Include& inc : includes_of(GetParam())) {
    if (inc.target.rfind("hybrid_vo/", 0) != 0) continue;
    // hybrid_vo/<Msg>.h are the package's generated ROS messages: the node layer's own.
    if (inc.target.find('/', 10) == std::string::npos) {
      EXPECT_EQ(GetParam(), "node") << inc.file << " includes message " << inc.target;
      continue;
    }
    const std::string layer = inc.target.substr(10, inc.target.find('/', 10) - 10);
    const int other = rank_of(layer);
    ASSERT_GE(other, 0) << inc.file << " includes unknown layer " << inc.target;
    // synthetic data may use everything in the core; otherwise dependencies point backwards.
    if (GetParam() == "synthetic" && other <= rank_of("lines")) continue;
    EXPECT_LE(other, own) << inc.file << " includes " << inc.target;
  }
}

using CoreLayerTest = LayerTest;

TEST_P(CoreLayerTest, UsesNoRosAndNoOpenCv) {
  const std::regex forbidden(
      R"re(^(ros/|opencv|cv_bridge|tf2|sensor_msgs|geometry_msgs|image_transport|message_filters|nav_msgs|diagnostic_updater|rosbag))re");
  for (const Include& inc : includes_of(GetParam()))
    EXPECT_FALSE(std::regex_search(inc.target, forbidden)) << inc.file << " includes " << inc.target;
}

INSTANTIATE_TEST_SUITE_P(Layers, LayerTest, ::testing::ValuesIn(kLayers));
INSTANTIATE_TEST_SUITE_P(Core, CoreLayerTest,
                         ::testing::Values("geometry", "solvers", "estimation", "lines",
                                           "synthetic"));

}  // namespace
