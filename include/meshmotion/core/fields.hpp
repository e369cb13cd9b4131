#pragma once
/// \file
/// One description per field, and the outlets written from it.
///
/// Every options struct and every report of the library describes its fields once, next to
/// the struct:
/// - options: `visit_options(o, f)` calls `f(key, field, doc)` for each field text may set
///   (movers/registry.hpp, curving/curve_mesh.hpp);
/// - results: `visit_fields(r, f)` calls `f(key, value, doc)` for each field of a report
///   (MoverStats, QualityReport, UntangleReport, CurveResult, ...).
/// The key is the field's name in every outlet: the command-line flag (`--key-with-dashes`),
/// the Python keyword and dict key, the options file, the JSON key and the docs' tables.
/// Adding a field is one line in its description; the outlets below and those of the
/// programs and the Python module pick it up.
///
/// A result field is a number, a bool, a string, an enum with `name()`, a fixed or growing
/// list of these, a struct with its own `visit_fields` (an object), a list of such structs, or
/// a list of (name, value) pairs (an object keyed by the names: counts per element type).
///
/// \code
/// JsonWriter w(std::cout);
/// write_json(w, result.quality);          // {"metric": ..., "elements": ..., ...}
/// write_text(std::cout, result.untangle); // "cells_below: 3" lines
/// field_keys<UntangleReport>();           // {"cells_below", "invalid_before", ...}
/// \endcode

#include "meshmotion/core/json.hpp"
#include "meshmotion/core/option_text.hpp"

#include <array>
#include <cstddef>
#include <cstdio>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshmotion {

/// A report type with a description of its fields.
template <class T>
concept DescribedFields = requires(const T& t) { visit_fields(t, [](std::string_view, const auto&, std::string_view) {}); };

namespace detail {

template <class T>
struct is_field_list : std::false_type {};
template <class T, class A>
struct is_field_list<std::vector<T, A>> : std::true_type {};
template <class T, std::size_t N>
struct is_field_list<std::array<T, N>> : std::true_type {};

// (name, value) pairs: an object keyed by the names.
template <class T>
struct is_keyed_list : std::false_type {};
template <class V, class A>
struct is_keyed_list<std::vector<std::pair<std::string, V>, A>> : std::true_type {};

// A list of reports (an array of objects): one line per item in text.
template <class T>
struct is_report_list : std::false_type {};
template <class T, class A>
struct is_report_list<std::vector<T, A>> : std::bool_constant<DescribedFields<T>> {};

// A scalar as text: numbers in their shortest exact form, enums by name.
template <class V>
[[nodiscard]] std::string scalar_text(const V& v) {
  if constexpr (std::is_enum_v<V>) return std::string(name(v));
  else if constexpr (std::is_convertible_v<const V&, std::string_view>) return std::string(std::string_view(v));
  else return format_option_value(v);
}

template <class V>
void write_json_value(JsonWriter& w, const V& v);

}  // namespace detail

/// The keys of T's description, in its order.
template <DescribedFields T>
[[nodiscard]] std::vector<std::string> field_keys(const T& t = T{}) {
  std::vector<std::string> keys;
  visit_fields(t, [&](std::string_view key, const auto&, std::string_view) { keys.emplace_back(key); });
  return keys;
}

/// Every field of `r` as one JSON object (nested reports as nested objects).
template <DescribedFields T>
void write_json(JsonWriter& w, const T& r) {
  w.begin_object();
  write_json_fields(w, r);
  w.end_object();
}

/// The fields of `r` as key/value pairs into an object the caller has opened (to put a
/// program's own keys beside them).
template <DescribedFields T>
void write_json_fields(JsonWriter& w, const T& r) {
  visit_fields(r, [&](std::string_view key, const auto& value, std::string_view) {
    w.key(key);
    detail::write_json_value(w, value);
  });
}

/// The fields of `r` as readable lines "key: value", nested reports indented below their key
/// and lists of reports one line per item.
template <DescribedFields T>
void write_text(std::ostream& out, const T& r, int indent = 0);

namespace detail {

template <class V>
void write_json_value(JsonWriter& w, const V& v) {
  if constexpr (DescribedFields<V>) {
    write_json(w, v);
  } else if constexpr (is_keyed_list<V>::value) {
    w.begin_object();
    for (const auto& [key, x] : v) {
      w.key(key);
      write_json_value(w, x);
    }
    w.end_object();
  } else if constexpr (is_field_list<V>::value) {
    w.begin_array();
    for (const auto& x : v) write_json_value(w, x);
    w.end_array();
  } else if constexpr (std::is_enum_v<V>) {
    w.value(name(v));
  } else {
    w.value(v);
  }
}

// A value on one line: lists comma-separated, reports as key=value pairs.
template <class V>
[[nodiscard]] std::string inline_text(const V& v) {
  if constexpr (DescribedFields<V>) {
    std::string out;
    visit_fields(v, [&](std::string_view key, const auto& x, std::string_view) {
      if (!out.empty()) out += ' ';
      out += std::string(key) + '=' + inline_text(x);
    });
    return out;
  } else if constexpr (is_keyed_list<V>::value) {
    std::string out;
    for (const auto& [key, x] : v) {
      if (!out.empty()) out += ", ";
      out += key + ' ' + inline_text(x);
    }
    return out.empty() ? std::string("none") : out;
  } else if constexpr (is_field_list<V>::value) {
    std::string out;
    for (const auto& x : v) {
      if (!out.empty()) out += ", ";
      out += inline_text(x);
    }
    return '[' + out + ']';
  } else if constexpr (std::is_floating_point_v<V>) {
    // Six digits read well; JSON keeps every digit.
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", v);
    return buffer;
  } else {
    return scalar_text(v);
  }
}

}  // namespace detail

template <DescribedFields T>
void write_text(std::ostream& out, const T& r, int indent) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  visit_fields(r, [&]<class V>(std::string_view key, const V& value, std::string_view) {
    if constexpr (DescribedFields<V>) {
      out << pad << key << ":\n";
      write_text(out, value, indent + 2);
    } else if constexpr (detail::is_report_list<V>::value) {
      out << pad << key << ":" << (value.empty() ? " none" : "") << "\n";
      for (const auto& item : value) out << pad << "  - " << detail::inline_text(item) << "\n";
    } else {
      out << pad << key << ": " << detail::inline_text(value) << "\n";
    }
  });
}

}  // namespace meshmotion
