// hybrid_vo_to_kitti_layout: a TUM RGB-D (or Strecha, or KITTI) sequence in the KITTI odometry
// layout, its images grey and undistorted (datasets/undistorted_kitti.h), so that
// hybrid_vo_bench_frontend, scripts/eval_kitti and scripts/eval_real run it as they run KITTI.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

#include "hybrid_vo/datasets/readers.h"
#include "hybrid_vo/datasets/undistorted_kitti.h"

namespace {

int usage(const char* program, int code) {
  (code == 0 ? std::cout : std::cerr)
      << "Usage: " << program
      << " --format tum|strecha|kitti SOURCE --out ROOT [--name NAME] [--frames N]\n"
         "  Writes ROOT/sequences/NAME/{image_0, calib.txt, times.txt} and ROOT/poses/NAME.txt\n"
         "  (NAME default 00): each image grey and undistorted into its own K, times since the\n"
         "  first frame, the ground truth at each image's stamp (TUM: interpolated, frames\n"
         "  without it left out and counted). --frames N: the first N frames only.\n";
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  std::string format, source, out, name = "00";
  int frames = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage(argv[0], 0);
    if (i + 1 >= argc) return usage(argv[0], 2);
    if (a == "--format") format = argv[++i], source = i + 1 < argc ? argv[++i] : "";
    else if (a == "--out") out = argv[++i];
    else if (a == "--name") name = argv[++i];
    else if (a == "--frames") {
      char* end = nullptr;
      frames = static_cast<int>(std::strtol(argv[++i], &end, 10));
      if (*end || frames < 1) {
        std::cerr << "--frames: expected a count >= 1, got '" << argv[i] << "'\n";
        return 2;
      }
    } else {
      return usage(argv[0], 2);
    }
  }
  if (format.empty() || source.empty() || out.empty()) return usage(argv[0], 2);
  hybrid_vo::datasets::Sequence sequence;
  std::string error;
  if (!hybrid_vo::datasets::read_sequence(format, source, &sequence, &error)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }
  if (frames > 0 && frames < sequence.size()) sequence.frames.resize(frames);
  hybrid_vo::datasets::UndistortedKittiSummary summary;
  if (!hybrid_vo::datasets::write_undistorted_kitti(sequence, out, name, &summary, &error)) {
    std::cerr << "error: " << error << "\n";
    return 1;
  }
  std::printf("wrote %d frames (%dx%d, %s; %d without ground truth left out) to %s/sequences/%s\n",
              summary.frames, summary.width, summary.height,
              summary.undistorted ? "undistorted" : "no distortion", sequence.skipped_frames,
              out.c_str(), name.c_str());
  return 0;
}
