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

/// One option as the listings and the docs show it.
struct OptionDoc {
  std::string key;
  std::string type;   ///< option_type_name()
  std::string value;  ///< its value (the default, for a default-made struct) as text
  std::string doc;    ///< one line
};

/// Every key of an options struct with a visit_options description, in its order.
template <class Options>
[[nodiscard]] std::vector<OptionDoc> option_docs(Options o) {
  std::vector<OptionDoc> out;
  visit_options(o, [&](const std::string& key, auto& field, std::string_view doc) {
    out.push_back({key, option_type_name(field), format_option_value(field), std::string(doc)});
  });
  return out;
}

/// Sets the field of `o` named `key` from `text`; false when `o` has no such key. Throws
/// InputError (naming the key) for a value the field cannot hold.
template <class Options>
bool set_option(Options& o, std::string_view key, std::string_view text) {
  bool found = false;
  visit_options(o, [&](const std::string& k, auto& field, std::string_view) {
    if (found || k != key) return;
    parse_option_value(key, text, field);
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
