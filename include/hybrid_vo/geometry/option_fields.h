#pragma once

// Option structs declare their fields once, next to the struct, as
//
//   template <typename Visit> void visit_fields(HybridRansacOptions& o, Visit&& visit) {
//     HYBRID_VO_FIELDS(positive(), o.point_threshold_px, o.vp_threshold_deg);
//     ...  // = visit("point_threshold_px", o.point_threshold_px, positive()); ...
//   }
//
// (a nested component under a prefix: visit_fields(o.junctions, prefixed("junctions_", visit))).
// validate() below, the node's parameter checks and the Python bindings' keyword names all come
// from that one declaration, so a field is named and bounded in one place. It lives in the base
// layer because every layer's options use it.

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace hybrid_vo {

// In a visit_fields(o, visit) body: the fields o.a, o.b, ... under their own names ("a", "b"),
// all within `bounds`.
// The names are split once per declaration (a static at the call site), not on every visit.
#define HYBRID_VO_FIELDS(bounds, ...)                                  \
  do {                                                                 \
    static const std::vector<std::string> field_names =                \
        ::hybrid_vo::spelled_field_names(#__VA_ARGS__);                \
    ::hybrid_vo::visit_named(visit, bounds, field_names, __VA_ARGS__); \
  } while (false)

// The values a numeric option may take: [min, max], either end open.
struct Bounds {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false, max_open = false;

  bool contains(double value) const {
    return std::isfinite(value) && (min_open ? value > min : value >= min) &&
           (max_open ? value < max : value <= max);
  }
  // "must be > 0", "must be in (0, 1)", ...
  std::string requirement() const {
    std::ostringstream text;
    const bool upper = std::isfinite(max), lower = std::isfinite(min);
    if (lower && upper)
      text << "must be in " << (min_open ? "(" : "[") << min << ", " << max
           << (max_open ? ")" : "]");
    else if (lower)
      text << "must be " << (min_open ? "> " : ">= ") << min;
    else if (upper)
      text << "must be " << (max_open ? "< " : "<= ") << max;
    else
      text << "must be finite";
    return text.str();
  }
};
inline Bounds any_value() { return {}; }
inline Bounds positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
inline Bounds non_negative() { return {0.0, std::numeric_limits<double>::infinity()}; }
inline Bounds at_least(double min) { return {min, std::numeric_limits<double>::infinity()}; }
inline Bounds between(double min, double max) { return {min, max}; }
inline Bounds fraction() { return {0.0, 1.0}; }
inline Bounds open_fraction() { return {0.0, 1.0, true, true}; }
inline Bounds positive_fraction() { return {0.0, 1.0, true, false}; }

// The names of the preprocessor's spelling of HYBRID_VO_FIELDS' arguments: "o.a, o.b" -> a, b.
inline std::vector<std::string> spelled_field_names(const char* spelled) {
  std::vector<std::string> names;
  std::istringstream list(spelled);
  for (std::string name; std::getline(list, name, ',');)
    names.push_back(name.substr(name.find('.') + 1));
  return names;
}

// Visits each of `fields` under its name, within `bounds` (HYBRID_VO_FIELDS).
template <typename Visit, typename... Fields>
void visit_named(Visit& visit, const Bounds& bounds, const std::vector<std::string>& names,
                 Fields&... fields) {
  size_t k = 0;
  (visit(names[k++], fields, bounds), ...);
}

// A visitor that sees a nested component's fields under `prefix`, without those in `excluded`
// (fields the enclosing code sets itself, which would otherwise be silent no-ops).
template <typename Visit>
struct Prefixed {
  std::string prefix;
  Visit& visit;
  std::set<std::string> excluded;
  template <typename T>
  void operator()(const std::string& name, T& field, const Bounds& bounds = {}) const {
    if (!excluded.count(name)) visit(prefix + name, field, bounds);
  }
};
template <typename Visit>
Prefixed<Visit> prefixed(std::string prefix, Visit& visit, std::set<std::string> excluded = {}) {
  return {std::move(prefix), visit, std::move(excluded)};
}

template <typename T>
struct IsDoubleArray : std::false_type {};
template <size_t N>
struct IsDoubleArray<std::array<double, N>> : std::true_type {};

// The first field of `options` outside its bounds, as "name: must be > 0, got -1"; "" when every
// field is valid. Booleans and enums have no bounds; arrays are checked element by element.
template <typename Options>
std::string validate(const Options& options) {
  std::string message;
  auto check = [&message](const std::string& name, double value, const Bounds& bounds) {
    if (!message.empty() || bounds.contains(value)) return;
    std::ostringstream text;
    text << name << ": " << bounds.requirement() << ", got " << value;
    message = text.str();
  };
  auto visit = [&check](const std::string& name, auto& field, const Bounds& bounds = {}) {
    using T = std::decay_t<decltype(field)>;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      check(name, static_cast<double>(field), bounds);
    } else if constexpr (IsDoubleArray<T>::value) {
      for (size_t k = 0; k < field.size(); ++k)
        check(name + "[" + std::to_string(k) + "]", field[k], bounds);
    }
  };
  Options copy = options;  // visit_fields takes a mutable struct (the bindings write through it)
  visit_fields(copy, visit);
  return message;
}

}  // namespace hybrid_vo
