#pragma once

// The node's parameters from a file of the form of config/*.yaml, without a parameter server: the
// tools that run the node's VisualOdometry offline (hybrid_vo_bench_frontend --config) then run
// exactly what `roslaunch ... config:=FILE` runs.

#include <xmlrpcpp/XmlRpcValue.h>

#include <string>
#include <vector>

#include "hybrid_vo/node/node_parameters.h"

namespace hybrid_vo {

// A flat YAML mapping, one `name: value` per line with `#` comments, into a struct as the
// parameter server answers for the node's namespace: true/false as booleans, integers, numbers
// (also 1e-3, .5, -2.), the rest as strings (quotes removed). Nested or multi-line values, a line
// without a name, or a name given twice: false and `error` (with the line number).
bool parse_flat_yaml(const std::string& text, XmlRpc::XmlRpcValue* params, std::string* error);

// The file at `path` read as the node reads its namespace (read_node_parameters), after
// `overrides` (name, value as YAML text) replace or add entries. False when the file cannot be
// read, does not parse, or an override does not parse; warnings as read_node_parameters gives them.
bool read_node_parameters_file(const std::string& path,
                               const std::vector<std::pair<std::string, std::string>>& overrides,
                               NodeParameters* parameters, std::vector<std::string>* warnings,
                               std::string* error);

}  // namespace hybrid_vo
