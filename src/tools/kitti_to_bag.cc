// hybrid_vo_kitti_to_bag: a KITTI odometry sequence to a bag (conversion/kitti_to_bag.h).
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "hybrid_vo/conversion/kitti_to_bag.h"

int main(int argc, char** argv) {
  using namespace hybrid_vo::conversion;
  const std::string program = argc > 0 ? argv[0] : "hybrid_vo_kitti_to_bag";
  KittiBagOptions options;
  const std::string usage_error =
      parse_kitti_args(std::vector<std::string>(argv + 1, argv + argc), &options);
  if (options.help) {
    std::cout << kitti_usage(program);
    return 0;
  }
  if (!usage_error.empty()) {
    std::cerr << "error: " << usage_error << "\n" << kitti_usage(program);
    return 2;
  }
  std::string error;
  KittiBagSummary summary;
  if (!convert_kitti(options, &error, &summary)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }
  std::printf("converted %d frames (%s, %dx%d, %s images), %s -> %s\n", summary.frames,
              options.stereo ? "stereo" : "mono", summary.width, summary.height,
              to_string(options.images.kind),
              summary.poses_path.empty() ? "no ground truth"
                                         : ("ground truth from " + summary.poses_path).c_str(),
              options.out_bag.c_str());
  return 0;
}
