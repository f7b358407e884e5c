#pragma once

// Fuzz targets of every reader of outside input: the data set parsers (KITTI calib/times/poses,
// TUM, Strecha, SuperGlue pairs, LaMAR sessions, all from files) and the node's message
// conversions (FeaturePoints, FeatureLines, VINS PointCloud points and lines, CameraInfo, Image,
// CompressedImage).
// One input runs one target; the outcome says whether the input was accepted, the error it was
// rejected with, and any broken promise ("violation"): a rejection without a clear error (for
// files: "path[:line]: message" naming the file), or an accepted result with a non-finite value,
// a non-rotation, sizes that disagree. Crashes and sanitizer reports are the fuzzer's to catch.
//
// The same targets run under libFuzzer (fuzz_main.cc, scripts/fuzz) and as a deterministic
// random-mutation gtest (test_fuzz_parsers.cc) in CI.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace hybrid_vo {
namespace fuzz {

struct Outcome {
  bool accepted = false;
  std::string error;      // why it was rejected
  std::string violation;  // empty unless the target broke a promise
};

struct Target {
  const char* name;
  Outcome (*run)(const uint8_t* data, size_t size);
  // Valid inputs (and a few near misses) that mutations start from.
  std::vector<std::string> (*seeds)();
  bool text;  // a text format (the gtest's mutator then also works on tokens and lines)
};

// Every target, in a fixed order.
const std::vector<Target>& targets();
const Target* find_target(const std::string& name);

// Multi-file targets (TUM, Strecha, LaMAR) take one file per part, in the order of their
// documentation in fuzz_targets.cc, separated by this line; a missing part is a missing file.
extern const char kPartSeparator[];

}  // namespace fuzz
}  // namespace hybrid_vo
