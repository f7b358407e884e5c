#pragma once

// Helpers shared by the data set readers for their whitespace-separated text formats. Every error
// names the file and, where there is one, the 1-based line, compiler style: "file:line: message".

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace hybrid_vo {
namespace datasets {

// Writes `message` to *error (when error is not null) and returns false, so that readers can
// `return fail(error, ...)`.
bool fail(std::string* error, const std::string& message);

// "path:line: message", or "path: message" for line <= 0.
std::string located(const std::string& path, int line, const std::string& message);

// Reads every line of a regular file, without line terminators (a trailing '\r' is dropped too).
// False with "path: no such file" or "path: cannot read" otherwise.
bool read_lines(const std::string& path, std::vector<std::string>* lines, std::string* error);

// Splits a line at whitespace.
std::vector<std::string> split_fields(const std::string& line);

// Splits a comma-separated line (LaMAR's ", ") and trims whitespace around each field; an empty
// field stays an empty string.
std::vector<std::string> split_csv(const std::string& line);

// True for a line that is empty, whitespace only, or a '#' comment (after leading whitespace).
bool is_blank_or_comment(const std::string& line);

// The whole token must be a finite number ("nan", "inf", "1.5x" and "" are rejected).
bool parse_double(const std::string& token, double* value);
// The whole token must be a decimal integer that fits an int (int64_t).
bool parse_int(const std::string& token, int* value);
bool parse_int64(const std::string& token, int64_t* value);

// Parses fields[first, first + count) as finite numbers into out[0, count). On failure the error
// names the field (1-based, as a user counts the columns of the line) and its text.
bool parse_fields(const std::vector<std::string>& fields, size_t first, size_t count,
                  const std::string& path, int line, double* out, std::string* error);

// Fails unless the line has exactly `expected` fields; `layout` describes them for the message.
bool expect_field_count(const std::vector<std::string>& fields, size_t expected,
                        const std::string& layout, const std::string& path, int line,
                        std::string* error);

// Accepts a matrix that is a rotation up to the rounding of a text file (|RᵀR - I| and |det - 1|
// below 1e-3) and replaces it by the nearest rotation, so that relative poses are exact rotations.
bool to_rotation(const Eigen::Matrix3d& M, const std::string& path, int line, Eigen::Matrix3d* R,
                 std::string* error);

}  // namespace datasets
}  // namespace hybrid_vo
