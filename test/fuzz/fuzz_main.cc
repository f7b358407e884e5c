// libFuzzer entry point of one target of fuzz_targets.h, chosen at build time
// (HYBRID_VO_FUZZ_TARGET); scripts/fuzz builds and runs one per target. A broken promise aborts,
// so that libFuzzer keeps the input like a crash.
#include <cstdio>
#include <cstdlib>

#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const hybrid_vo::fuzz::Target* target =
      hybrid_vo::fuzz::find_target(HYBRID_VO_FUZZ_TARGET);
  if (!target) std::abort();
  const hybrid_vo::fuzz::Outcome o = target->run(data, size);
  if (!o.violation.empty()) {
    std::fprintf(stderr, "%s: %s\n", target->name, o.violation.c_str());
    std::abort();
  }
  return 0;
}
