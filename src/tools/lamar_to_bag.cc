// hybrid_vo_lamar_to_bag: a LaMAR Capture session to a bag (conversion/lamar_to_bag.h).
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "hybrid_vo/conversion/lamar_to_bag.h"

int main(int argc, char** argv) {
  using namespace hybrid_vo::conversion;
  const std::string program = argc > 0 ? argv[0] : "hybrid_vo_lamar_to_bag";
  LamarBagOptions options;
  const std::string usage_error =
      parse_lamar_args(std::vector<std::string>(argv + 1, argv + argc), &options);
  if (options.help) {
    std::cout << lamar_usage(program);
    return 0;
  }
  if (!usage_error.empty()) {
    std::cerr << "error: " << usage_error << "\n" << lamar_usage(program);
    return 2;
  }
  std::string error;
  LamarBagSummary summary;
  if (!convert_lamar(options, &error, &summary)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }
  for (size_t k = 0; k < summary.streams.size(); ++k)
    std::printf("%s: %d images on %s/image_raw%s\n", summary.streams[k].c_str(),
                summary.images[k], summary.topics[k].c_str(),
                options.images.kind == BagImageFormat::kRaw ? "" : "/compressed");
  std::printf("%d ground-truth poses of %s%s%s; time offset %.0f s -> %s\n", summary.ground_truth,
              summary.streams[0].c_str(), summary.poses_path.empty() ? "" : " from ",
              summary.poses_path.c_str(), summary.time_offset, options.out_bag.c_str());
  // The launch file's camera argument is the topic name under /camera/.
  std::printf("replay: roslaunch hybrid_vo lamar.launch bag:=%s camera:=%s%s\n",
              options.out_bag.c_str(), summary.topics[0].substr(8).c_str(),
              options.images.kind == BagImageFormat::kRaw ? "" : " image_transport:=compressed");
  return 0;
}
