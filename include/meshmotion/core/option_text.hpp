#pragma once
/// \file
/// Option values as text, both ways: the one parser behind command lines, config files and
/// the Python keywords. Numbers go through std::from_chars / std::to_chars (shortest form),
/// so a double written and read back is the same double; a malformed or non-finite number,
/// a stray character after it, or an unknown name is refused with the key it was meant for.
///
/// \code
/// double r = 0.0;
/// parse_option_value("support_radius", "4.9e-6", r);       // r == 4.9e-6 exactly
/// format_option_value(r);                                   // "4.9e-06"
/// const KeyValues kv = parse_key_values("kernel=wendland4 support_radius=0.5");
/// \endcode

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/types.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <concepts>
#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>
#include <vector>

namespace meshmotion {

/// key=value pairs in the order given.
using KeyValues = std::vector<std::pair<std::string, std::string>>;

/// The values a number option takes, part of its description in visit_options(): from lo to
/// hi (each end included unless open), and 0 as well where `or_zero` (the "off" or "from the
/// mesh" value below the range, as in "0: the mean"). set_option() and check_option_ranges()
/// refuse any other value, naming the key; listings show text().
struct OptionRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;
  bool or_zero = false;

  [[nodiscard]] bool holds(double v) const noexcept {
    if (!std::isfinite(v)) return false;
    if (or_zero && v == 0.0) return true;
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  /// "> 0", ">= 1 or 0", "in (-1, 0.5)", "1 to 8"; empty when unbounded.
  [[nodiscard]] std::string text() const;
};

/// The common ranges, by name.
namespace range {
inline constexpr OptionRange positive{0.0, std::numeric_limits<double>::infinity(), true};
inline constexpr OptionRange non_negative{0.0};
[[nodiscard]] constexpr OptionRange at_least(double lo) { return {lo}; }
[[nodiscard]] constexpr OptionRange at_most(double hi) { return {-std::numeric_limits<double>::infinity(), hi}; }
[[nodiscard]] constexpr OptionRange between(double lo, double hi) { return {lo, hi}; }
/// `r`, and 0 as well.
[[nodiscard]] constexpr OptionRange or_zero(OptionRange r) {
  r.or_zero = true;
  return r;
}
}  // namespace range

/// An option's description, the one doc of its field: what visit_options() hands each visitor
/// as its third argument (visitors that want the line alone take it as a std::string_view).
/// `text` is the line listings and flags show; `details`, where a line is not enough, the whole
/// description (defaults that depend on the case, costs, what the library measured), which the
/// API docs (docs/options.md) show in place of the line. Option structs carry no doc comment of their own
/// on a described field, so there is one text to keep true.
struct OptionHelp {
  std::string_view text;
  OptionRange range{};
  std::string_view details{};
  constexpr OptionHelp(const char* t, OptionRange r = {}, const char* d = "") : text(t), range(r), details(d) {}
  OptionHelp(const std::string& t, OptionRange r = {}) : text(t), range(r) {}
  constexpr operator std::string_view() const noexcept { return text; }
};

namespace detail {

[[nodiscard]] inline std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r\n");
  return s.substr(first, last - first + 1);
}

[[noreturn]] inline void bad_option_value(std::string_view key, std::string_view text, std::string_view expected) {
  throw InputError("option '" + std::string(key) + "': expected " + std::string(expected) + " (got '" +
                   std::string(text) + "')");
}

/// Levenshtein distance, for "did you mean" in unknown-key messages.
[[nodiscard]] inline std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

}  // namespace detail

/// The closest of `known` to `key` when it is a plausible misspelling, else empty.
[[nodiscard]] inline std::string closest_key(std::string_view key, const std::vector<std::string>& known) {
  std::string best;
  std::size_t best_distance = std::max<std::size_t>(2, key.size() / 3) + 1;
  for (const auto& k : known) {
    const std::size_t d = detail::edit_distance(key, k);
    if (d < best_distance) {
      best_distance = d;
      best = k;
    }
  }
  return best;
}

/// "unknown option 'suport_radius' for rbf (did you mean 'support_radius'?; known: a, b, c)".
[[nodiscard]] inline std::string unknown_key_message(std::string_view what, std::string_view key,
                                                     const std::vector<std::string>& known) {
  std::string list;
  for (const auto& k : known) {
    if (!list.empty()) list += ", ";
    list += k;
  }
  const std::string guess = closest_key(key, known);
  return "unknown option '" + std::string(key) + "' for " + std::string(what) +
         (guess.empty() ? std::string() : " (did you mean '" + guess + "'?)") + "; known: " + list;
}

/// Reads a finite double; the whole text must be the number.
inline void parse_option_value(std::string_view key, std::string_view text, double& out) {
  const std::string_view t = detail::trim(text);
  // from_chars takes no leading '+'; a user may well write one.
  const std::string_view digits = !t.empty() && t.front() == '+' ? t.substr(1) : t;
  double value = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || ec != std::errc{} || end != digits.data() + digits.size() || !std::isfinite(value))
    detail::bad_option_value(key, text, "a finite number");
  out = value;
}

/// Reads an integer (no fraction, no exponent) that fits in T.
template <std::integral T>
  requires(!std::same_as<T, bool>)
void parse_option_value(std::string_view key, std::string_view text, T& out) {
  const std::string_view t = detail::trim(text);
  const std::string_view digits = !t.empty() && t.front() == '+' ? t.substr(1) : t;
  T value{};
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || ec != std::errc{} || end != digits.data() + digits.size())
    detail::bad_option_value(key, text, std::is_signed_v<T> ? "an integer" : "a non-negative integer");
  out = value;
}

/// true/false, on/off, yes/no, 1/0.
inline void parse_option_value(std::string_view key, std::string_view text, bool& out) {
  const std::string_view t = detail::trim(text);
  if (t == "true" || t == "on" || t == "yes" || t == "1")
    out = true;
  else if (t == "false" || t == "off" || t == "no" || t == "0")
    out = false;
  else
    detail::bad_option_value(key, text, "true or false");
}

/// Comma-separated finite numbers (empty text: an empty list).
inline void parse_option_value(std::string_view key, std::string_view text, std::vector<double>& out) {
  std::vector<double> values;
  const std::string_view t = detail::trim(text);
  std::size_t at = 0;
  while (!t.empty() && at <= t.size()) {
    const std::size_t comma = std::min(t.find(',', at), t.size());
    double v = 0.0;
    parse_option_value(key, t.substr(at, comma - at), v);
    values.push_back(v);
    at = comma + 1;
  }
  out = std::move(values);
}

/// Text as it is, less surrounding white space.
inline void parse_option_value(std::string_view, std::string_view text, std::string& out) { out = std::string(detail::trim(text)); }

/// Comma-separated names (empty text: an empty list); an empty name is refused.
inline void parse_option_value(std::string_view key, std::string_view text, std::vector<std::string>& out) {
  std::vector<std::string> names;
  const std::string_view t = detail::trim(text);
  std::size_t at = 0;
  while (!t.empty() && at <= t.size()) {
    const std::size_t comma = std::min(t.find(',', at), t.size());
    const std::string_view item = detail::trim(t.substr(at, comma - at));
    if (item.empty()) detail::bad_option_value(key, text, "comma-separated names");
    names.emplace_back(item);
    at = comma + 1;
  }
  out = std::move(names);
}

/// Comma-separated integers (empty text: an empty list).
template <std::integral T>
  requires(!std::same_as<T, bool>)
void parse_option_value(std::string_view key, std::string_view text, std::vector<T>& out) {
  std::vector<T> values;
  std::vector<std::string> items;
  parse_option_value(key, text, items);
  for (const std::string& item : items) parse_option_value(key, item, values.emplace_back());
  out = std::move(values);
}

/// Exactly N comma-separated finite numbers.
template <int N>
void parse_option_value(std::string_view key, std::string_view text, Vec<N>& out) {
  std::vector<double> values;
  parse_option_value(key, text, values);
  if (static_cast<int>(values.size()) != N)
    detail::bad_option_value(key, text, std::to_string(N) + " comma-separated numbers");
  for (int d = 0; d < N; ++d) out[d] = values[static_cast<std::size_t>(d)];
}

/// A point, or "none" for no value.
template <int N>
void parse_option_value(std::string_view key, std::string_view text, std::optional<Vec<N>>& out) {
  if (detail::trim(text) == "none") {
    out.reset();
    return;
  }
  Vec<N> v;
  parse_option_value(key, text, v);
  out = v;
}

/// An enum with `name(E)` and a list `option_choices(E{})` of its values.
template <class E>
  requires std::is_enum_v<E> && requires(E e) { option_choices(e); }
void parse_option_value(std::string_view key, std::string_view text, E& out) {
  const std::string_view t = detail::trim(text);
  std::string known;
  for (const E e : option_choices(E{})) {
    if (name(e) == t) {
      out = e;
      return;
    }
    if (!known.empty()) known += ", ";
    known += name(e);
  }
  detail::bad_option_value(key, text, "one of " + known);
}

/// The shortest text that reads back to the same double.
[[nodiscard]] inline std::string format_option_value(double x) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x);
  return std::string(buffer, result.ptr);
}
template <std::integral T>
  requires(!std::same_as<T, bool>)
[[nodiscard]] std::string format_option_value(T x) {
  return std::to_string(x);
}
[[nodiscard]] inline std::string format_option_value(bool b) { return b ? "true" : "false"; }
[[nodiscard]] inline std::string format_option_value(const std::vector<double>& v) {
  std::string out;
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (k) out += ',';
    out += format_option_value(v[k]);
  }
  return out;
}
[[nodiscard]] inline std::string format_option_value(const std::string& s) { return s; }
[[nodiscard]] inline std::string format_option_value(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) {
    if (!out.empty()) out += ',';
    out += n;
  }
  return out;
}
template <std::integral T>
  requires(!std::same_as<T, bool>)
[[nodiscard]] std::string format_option_value(const std::vector<T>& v) {
  std::string out;
  for (const T x : v) {
    if (!out.empty()) out += ',';
    out += std::to_string(x);
  }
  return out;
}
template <int N>
[[nodiscard]] std::string format_option_value(const Vec<N>& v) {
  return format_option_value(std::vector<double>(v.data(), v.data() + N));
}
template <int N>
[[nodiscard]] std::string format_option_value(const std::optional<Vec<N>>& v) {
  return v ? format_option_value(*v) : std::string("none");
}
template <class E>
  requires std::is_enum_v<E> && requires(E e) { option_choices(e); }
[[nodiscard]] std::string format_option_value(E e) {
  return std::string(name(e));
}

/// What text a field takes, for listings and the docs' tables.
[[nodiscard]] inline std::string option_type_name(const double&) { return "number"; }
[[nodiscard]] inline std::string option_type_name(const bool&) { return "bool"; }
[[nodiscard]] inline std::string option_type_name(const std::string&) { return "text"; }
[[nodiscard]] inline std::string option_type_name(const std::vector<double>&) { return "numbers"; }
[[nodiscard]] inline std::string option_type_name(const std::vector<std::string>&) { return "names"; }
template <std::integral T>
  requires(!std::same_as<T, bool>)
[[nodiscard]] std::string option_type_name(const T&) {
  return std::is_signed_v<T> ? "integer" : "integer >= 0";
}
template <std::integral T>
  requires(!std::same_as<T, bool>)
[[nodiscard]] std::string option_type_name(const std::vector<T>&) {
  return "integers";
}
template <int N>
[[nodiscard]] std::string option_type_name(const Vec<N>&) {
  return std::to_string(N) + " numbers";
}
template <int N>
[[nodiscard]] std::string option_type_name(const std::optional<Vec<N>>&) {
  return std::to_string(N) + " numbers or none";
}
template <class E>
  requires std::is_enum_v<E> && requires(E e) { option_choices(e); }
[[nodiscard]] std::string option_type_name(const E&) {
  std::string out;
  for (const E e : option_choices(E{})) {
    if (!out.empty()) out += '|';
    out += name(e);
  }
  return out;
}

inline std::string OptionRange::text() const {
  const auto number = [](double x) { return format_option_value(x); };
  const bool has_lo = lo > -std::numeric_limits<double>::infinity(), has_hi = hi < std::numeric_limits<double>::infinity();
  std::string out;
  if (has_lo && has_hi) {
    out = lo_open || hi_open ? std::string("in ") + (lo_open ? "(" : "[") + number(lo) + ", " + number(hi) + (hi_open ? ")" : "]")
                             : number(lo) + " to " + number(hi);
  } else if (has_lo) {
    out = (lo_open ? "> " : ">= ") + number(lo);
  } else if (has_hi) {
    out = (hi_open ? "< " : "<= ") + number(hi);
  }
  if (or_zero && !out.empty()) out += " or 0";
  return out;
}

/// Refuses `value` of option `key` outside `range` (InputError naming both); lists are
/// checked entry by entry. Fields other than numbers have no range.
template <class T>
void check_option_range(std::string_view key, const T& value, const OptionRange& range) {
  if constexpr (std::is_arithmetic_v<T> && !std::same_as<T, bool>) {
    if (!range.holds(static_cast<double>(value)))
      throw InputError("option '" + std::string(key) + "': " + format_option_value(value) + " is out of range (expected " +
                       range.text() + ")");
  } else if constexpr (std::same_as<T, std::vector<double>>) {
    for (const double v : value) check_option_range(key, v, range);
  }
}

/// Refuses (InputError naming the key) any field of `o` outside the range its description
/// gives: for options set in code rather than through set_option().
template <class Options>
void check_option_ranges(Options o) {
  visit_options(o, [](const std::string& key, const auto& field, const OptionHelp& help) { check_option_range(key, field, help.range); });
}

/// One option as the listings and the docs show it.
struct OptionDoc {
  std::string key;
  std::string type;   ///< option_type_name()
  std::string value;  ///< its value (the default, for a default-made struct) as text
  std::string doc;    ///< one line
  std::string details;  ///< the whole description where one line is not enough (OptionHelp::details), else empty
};

/// Every key of an options struct with a visit_options description, in its order.
template <class Options>
[[nodiscard]] std::vector<OptionDoc> option_docs(Options o) {
  std::vector<OptionDoc> out;
  visit_options(o, [&](const std::string& key, auto& field, const OptionHelp& help) {
    std::string type = option_type_name(field);
    if (const std::string r = help.range.text(); !r.empty()) type += " " + r;
    out.push_back({key, std::move(type), format_option_value(field), std::string(help.text), std::string(help.details)});
  });
  return out;
}

/// Sets the field of `o` named `key` from `text`; false when `o` has no such key. Throws
/// InputError (naming the key) for a value the field cannot hold or outside its range.
template <class Options>
bool set_option(Options& o, std::string_view key, std::string_view text) {
  bool found = false;
  visit_options(o, [&](const std::string& k, auto& field, const OptionHelp& help) {
    if (found || k != key) return;
    auto value = field;
    parse_option_value(key, text, value);
    check_option_range(key, value, help.range);
    field = std::move(value);
    found = true;
  });
  return found;
}

/// Every key of `o`, in its order.
template <class Options>
[[nodiscard]] std::vector<std::string> option_keys(Options o) {
  std::vector<std::string> out;
  visit_options(o, [&](const std::string& key, auto&, std::string_view) { out.push_back(key); });
  return out;
}

/// Splits "key=value key2=value2" (whitespace- or newline-separated; '#' starts a comment to
/// the end of its line) into pairs. Throws InputError for a token without '=' or with an
/// empty key, or a key given twice.
[[nodiscard]] inline KeyValues parse_key_values(std::string_view text) {
  KeyValues out;
  std::size_t at = 0;
  while (at < text.size()) {
    if (text[at] == '#') {
      at = text.find('\n', at);
      if (at == std::string_view::npos) break;
      continue;
    }
    if (text[at] == ' ' || text[at] == '\t' || text[at] == '\r' || text[at] == '\n') {
      ++at;
      continue;
    }
    std::size_t end = text.find_first_of(" \t\r\n", at);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view token = text.substr(at, end - at);
    const std::size_t eq = token.find('=');
    if (eq == std::string_view::npos || eq == 0)
      throw InputError("options: expected key=value (got '" + std::string(token) + "')");
    std::string key(token.substr(0, eq));
    for (const auto& [k, v] : out)
      if (k == key) throw InputError("options: key '" + key + "' given twice");
    out.emplace_back(std::move(key), std::string(token.substr(eq + 1)));
    at = end;
  }
  return out;
}

}  // namespace meshmotion
