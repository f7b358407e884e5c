#include "hybrid_vo/node/parameters_file.h"

#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

namespace hybrid_vo {
namespace {

using XmlRpc::XmlRpcValue;

std::string trim(const std::string& s) {
  size_t begin = 0, end = s.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(s[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(s[end - 1]))) --end;
  return s.substr(begin, end - begin);
}

// A YAML 1.1 plain or quoted scalar as rosparam types it.
bool scalar(const std::string& text, XmlRpcValue* value) {
  if (text.empty()) return false;
  const char quote = text.front();
  if (quote == '"' || quote == '\'') {
    if (text.size() < 2 || text.back() != quote) return false;
    *value = text.substr(1, text.size() - 2);
    return true;
  }
  // Flow collections, anchors, tags and block scalars: not a flat parameter.
  if (std::string("[{&*!|>").find(quote) != std::string::npos) return false;
  static const std::regex boolean_true("true|True|TRUE|yes|Yes|on|On"),
      boolean_false("false|False|FALSE|no|No|off|Off"), integer("[-+]?[0-9]+"),
      number(R"([-+]?(\.[0-9]+|[0-9]+(\.[0-9]*)?)([eE][-+]?[0-9]+)?)");
  if (std::regex_match(text, boolean_true)) {
    *value = true;
  } else if (std::regex_match(text, boolean_false)) {
    *value = false;
  } else if (std::regex_match(text, integer)) {
    errno = 0;
    const long long v = std::strtoll(text.c_str(), nullptr, 10);
    if (errno == ERANGE || v > INT32_MAX || v < INT32_MIN) return false;
    *value = static_cast<int>(v);
  } else if (std::regex_match(text, number)) {
    *value = std::strtod(text.c_str(), nullptr);
  } else {
    *value = text;
  }
  return true;
}

// The value part of a line: up to a comment (a `#` after a space, outside quotes).
std::string value_text(const std::string& rest) {
  char quote = 0;
  for (size_t i = 0; i < rest.size(); ++i) {
    const char c = rest[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#' && (i == 0 || std::isspace(static_cast<unsigned char>(rest[i - 1])))) {
      return trim(rest.substr(0, i));
    }
  }
  return trim(rest);
}

}  // namespace

bool parse_flat_yaml(const std::string& text, XmlRpcValue* params, std::string* error) {
  XmlRpcValue out;
  out.begin();  // an empty struct, not an invalid value
  std::istringstream lines(text);
  static const std::regex entry(R"(^([A-Za-z_][A-Za-z0-9_]*)\s*:(\s+(.*))?$)");
  int number = 0;
  for (std::string line; std::getline(lines, line);) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#' || content == "---") continue;
    std::smatch m;
    XmlRpcValue value;
    if (line[0] == ' ' || line[0] == '\t' || !std::regex_match(line, m, entry) ||
        !scalar(value_text(m[3]), &value)) {
      *error = "line " + std::to_string(number) + ": not a flat `name: value` entry: " + content;
      return false;
    }
    if (out.hasMember(m[1])) {
      *error = "line " + std::to_string(number) + ": " + m[1].str() + " given twice";
      return false;
    }
    out[m[1]] = value;
  }
  *params = out;
  return true;
}

bool read_node_parameters_file(const std::string& path,
                               const std::vector<std::pair<std::string, std::string>>& overrides,
                               NodeParameters* parameters, std::vector<std::string>* warnings,
                               std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = path + ": cannot be read";
    return false;
  }
  std::stringstream text;
  text << in.rdbuf();
  XmlRpcValue params;
  if (!parse_flat_yaml(text.str(), &params, error)) {
    *error = path + ": " + *error;
    return false;
  }
  for (const auto& [name, value_text] : overrides) {
    XmlRpcValue value;
    if (!scalar(trim(value_text), &value)) {
      *error = name + ": '" + value_text + "' is not a value";
      return false;
    }
    params[name] = value;
  }
  *parameters = read_node_parameters(params, warnings);
  return true;
}

}  // namespace hybrid_vo
