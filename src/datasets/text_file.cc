#include "hybrid_vo/datasets/text_file.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <Eigen/LU>

#include "hybrid_vo/geometry/rotation.h"

namespace hybrid_vo {
namespace datasets {

bool fail(std::string* error, const std::string& message) {
  if (error) *error = message;
  return false;
}

std::string located(const std::string& path, int line, const std::string& message) {
  if (line <= 0) return path + ": " + message;
  return path + ":" + std::to_string(line) + ": " + message;
}

bool read_lines(const std::string& path, std::vector<std::string>* lines, std::string* error) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return fail(error, located(path, 0, "no such file"));
  if (!fs::is_regular_file(path, ec)) return fail(error, located(path, 0, "not a regular file"));
  std::ifstream in(path);
  if (!in) return fail(error, located(path, 0, "cannot read"));
  lines->clear();
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();  // files written on Windows
    lines->push_back(line);
  }
  if (in.bad()) return fail(error, located(path, 0, "read error"));
  return true;
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::istringstream in(line);
  std::string field;
  while (in >> field) fields.push_back(field);
  return fields;
}

std::vector<std::string> split_csv(const std::string& line) {
  static const char kSpace[] = " \t\r\n\f\v";
  std::vector<std::string> fields;
  size_t begin = 0;
  while (true) {
    const size_t end = line.find(',', begin);
    const std::string field = line.substr(begin, end == std::string::npos ? end : end - begin);
    const size_t first = field.find_first_not_of(kSpace);
    const size_t last = field.find_last_not_of(kSpace);
    fields.push_back(first == std::string::npos ? "" : field.substr(first, last - first + 1));
    if (end == std::string::npos) return fields;
    begin = end + 1;
  }
}

bool is_blank_or_comment(const std::string& line) {
  const size_t first = line.find_first_not_of(" \t\r\n\f\v");
  return first == std::string::npos || line[first] == '#';
}

bool parse_double(const std::string& token, double* value) {
  if (token.empty()) return false;
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  // ERANGE on underflow still gives a usable (tiny) value; overflow gives inf, caught below.
  if (end != begin + token.size() || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

bool parse_int(const std::string& token, int* value) {
  if (token.empty()) return false;
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(begin, &end, 10);
  if (end != begin + token.size() || errno == ERANGE || v < std::numeric_limits<int>::min() ||
      v > std::numeric_limits<int>::max())
    return false;
  *value = static_cast<int>(v);
  return true;
}

bool parse_int64(const std::string& token, int64_t* value) {
  if (token.empty()) return false;
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(begin, &end, 10);
  if (end != begin + token.size() || errno == ERANGE) return false;
  *value = static_cast<int64_t>(v);
  return true;
}

bool parse_fields(const std::vector<std::string>& fields, size_t first, size_t count,
                  const std::string& path, int line, double* out, std::string* error) {
  for (size_t k = 0; k < count; ++k) {
    const size_t index = first + k;
    if (index >= fields.size())
      return fail(error, located(path, line, "missing field " + std::to_string(index + 1)));
    if (!parse_double(fields[index], &out[k]))
      return fail(error, located(path, line,
                                 "field " + std::to_string(index + 1) + " '" + fields[index] +
                                     "' is not a finite number"));
  }
  return true;
}

bool expect_field_count(const std::vector<std::string>& fields, size_t expected,
                        const std::string& layout, const std::string& path, int line,
                        std::string* error) {
  if (fields.size() == expected) return true;
  return fail(error, located(path, line,
                             "expected " + std::to_string(expected) + " fields (" + layout +
                                 "), found " + std::to_string(fields.size())));
}

bool to_rotation(const Eigen::Matrix3d& M, const std::string& path, int line, Eigen::Matrix3d* R,
                 std::string* error) {
  // Text files round to 4-6 digits, so a real rotation is off by ~1e-5 at most.
  constexpr double kTolerance = 1e-3;
  const double orthogonality = (M.transpose() * M - Eigen::Matrix3d::Identity()).norm();
  const double det = M.determinant();
  if (!(orthogonality < kTolerance) || !(std::abs(det - 1.0) < kTolerance)) {
    std::ostringstream message;
    message << "not a rotation matrix (|R^T R - I| = " << orthogonality << ", det = " << det
            << ")";
    return fail(error, located(path, line, message.str()));
  }
  *R = nearest_rotation(M);
  return true;
}

}  // namespace datasets
}  // namespace hybrid_vo
