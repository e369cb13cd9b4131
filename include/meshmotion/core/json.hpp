#pragma once
/// \file
/// The one JSON writer of the library and its programs (reports, --json output, errors).
///
/// \code
/// JsonWriter w(std::cout);
/// w.begin_object().key("elements").value(n).key("min").value(0.3).end_object();
/// \endcode
/// Non-finite numbers are written as null (JSON has no NaN or infinity). Separators are
/// inserted automatically; the writer does not check that keys and values alternate.

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ostream>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace meshmotion {

class JsonWriter {
 public:
  explicit JsonWriter(std::ostream& out) : out_(out) {}

  JsonWriter& begin_object() { return open('{'); }
  JsonWriter& end_object() { return close('}'); }
  JsonWriter& begin_array() { return open('['); }
  JsonWriter& end_array() { return close(']'); }

  JsonWriter& key(std::string_view k) {
    separate();
    write_string(k);
    out_ << ':';
    after_key_ = true;
    return *this;
  }

  JsonWriter& value(std::string_view s) {
    separate();
    write_string(s);
    return *this;
  }
  JsonWriter& value(const char* s) { return value(std::string_view(s)); }
  JsonWriter& value(const std::string& s) { return value(std::string_view(s)); }
  JsonWriter& value(bool b) {
    separate();
    out_ << (b ? "true" : "false");
    return *this;
  }
  JsonWriter& value(double x) {
    separate();
    if (!std::isfinite(x)) {
      out_ << "null";
    } else {
      // The shortest text that reads back to the same double.
      char buf[32];
      const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;
      out_.write(buf, end - buf);
    }
    return *this;
  }
  template <class Int>
    requires std::is_integral_v<Int> && (!std::is_same_v<Int, bool>)
  JsonWriter& value(Int i) {
    separate();
    out_ << static_cast<std::int64_t>(i);
    return *this;
  }
  /// A whole array of numbers or strings.
  template <class T>
  JsonWriter& array(const std::vector<T>& items) {
    begin_array();
    for (const auto& x : items) value(x);
    return end_array();
  }

 private:
  JsonWriter& open(char c) {
    separate();
    out_ << c;
    first_.push_back(true);
    return *this;
  }
  JsonWriter& close(char c) {
    out_ << c;
    if (!first_.empty()) first_.pop_back();
    return *this;
  }
  void separate() {
    if (after_key_) {
      after_key_ = false;
      return;
    }
    if (first_.empty()) return;
    if (!first_.back()) out_ << ',';
    first_.back() = false;
  }
  // The length of the well-formed UTF-8 sequence starting at s[k] (1 to 4), or 0 when the
  // bytes there are not one (a stray continuation byte, an overlong form, a surrogate, a
  // truncated sequence).
  [[nodiscard]] static std::size_t utf8_length(std::string_view s, std::size_t k) {
    const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
    const unsigned char c = byte(k);
    if (c < 0x80) return 1;
    std::size_t n = 0;
    unsigned char lo = 0x80, hi = 0xBF;  // the range of the second byte
    if (c >= 0xC2 && c <= 0xDF) n = 2;
    else if (c >= 0xE0 && c <= 0xEF) n = 3, lo = c == 0xE0 ? 0xA0 : 0x80, hi = c == 0xED ? 0x9F : 0xBF;
    else if (c >= 0xF0 && c <= 0xF4) n = 4, lo = c == 0xF0 ? 0x90 : 0x80, hi = c == 0xF4 ? 0x8F : 0xBF;
    else return 0;
    if (k + n > s.size() || byte(k + 1) < lo || byte(k + 1) > hi) return 0;
    for (std::size_t i = 2; i < n; ++i)
      if ((byte(k + i) & 0xC0) != 0x80) return 0;
    return n;
  }

  void write_string(std::string_view s) {
    out_ << '"';
    for (std::size_t k = 0; k < s.size(); ++k) {
      const char ch = s[k];
      const auto c = static_cast<unsigned char>(ch);
      if (c >= 0x80) {
        // Well-formed UTF-8 passes; any other byte (a binary file's, a path's in another
        // encoding) is written as the code point of its value, so the output stays JSON.
        const std::size_t n = utf8_length(s, k);
        if (n == 0) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out_ << buf;
        } else {
          out_ << s.substr(k, n);
          k += n - 1;
        }
        continue;
      }
      switch (ch) {
        case '"': out_ << "\\\""; break;
        case '\\': out_ << "\\\\"; break;
        case '\n': out_ << "\\n"; break;
        case '\r': out_ << "\\r"; break;
        case '\t': out_ << "\\t"; break;
        default:
          if (c < 0x20) {
            char buf[8];
            std::snprintf(buf, sizeof buf, "\\u%04x", c);
            out_ << buf;
          } else {
            out_ << ch;
          }
      }
    }
    out_ << '"';
  }

  std::ostream& out_;
  std::vector<bool> first_;
  bool after_key_ = false;
};

}  // namespace meshmotion
