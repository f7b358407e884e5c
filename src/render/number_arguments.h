#pragma once

// The numbers of the renderers' command lines (hybrid_vo_render_sequence, hybrid_vo_render_pan):
// the whole argument must be the number, finite and within its range, or it is refused.

#include <cstdint>
#include <string>

namespace hybrid_vo {
namespace render {

bool parse_int(const std::string& s, int lo, int hi, int* out);
// In [lo, hi], or (lo, hi] when open_lo.
bool parse_double(const std::string& s, double lo, double hi, bool open_lo, double* out);
bool parse_u64(const std::string& s, uint64_t* out);

}  // namespace render
}  // namespace hybrid_vo
