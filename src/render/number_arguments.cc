#include "number_arguments.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace hybrid_vo {
namespace render {

bool parse_int(const std::string& s, int lo, int hi, int* out) {
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (s.empty() || *end || errno || v < lo || v > hi) return false;
  *out = static_cast<int>(v);
  return true;
}

bool parse_double(const std::string& s, double lo, double hi, bool open_lo, double* out) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end || !std::isfinite(v) || v > hi || v < lo || (open_lo && v == lo))
    return false;
  *out = v;
  return true;
}

bool parse_u64(const std::string& s, uint64_t* out) {
  if (s.empty() || s[0] == '-') return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (*end || errno) return false;
  *out = v;
  return true;
}

}  // namespace render
}  // namespace hybrid_vo
