#pragma once
/// \file
/// A cursor over an in-memory text buffer that parses tokens with std::from_chars and keeps
/// the line number, so readers report "file:line: expected ... (got ...)" without iostreams.

#include "meshmotion/core/error.hpp"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <type_traits>

namespace meshmotion::detail {

/// A token cut to a readable length for messages (non-printable bytes as '?').
[[nodiscard]] inline std::string shorten_token(std::string_view token) {
  std::string s(token.substr(0, 40));
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126) c = '?';
  return token.size() > 40 ? s + "..." : s;
}

/// A token as an integer of type T in [lo, hi]; otherwise calls fail(message), which throws.
/// Shared by the readers' cursors, so every format words these errors alike.
template <class T, class Fail>
  requires std::is_signed_v<T>
[[nodiscard]] T integer_token(std::string_view token, std::string_view what, T lo, T hi, Fail&& fail) {
  std::int64_t value = 0;
  const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size())
    fail("expected " + std::string(what) + " as an integer (got '" + shorten_token(token) + "')");
  if (value < static_cast<std::int64_t>(lo) || value > static_cast<std::int64_t>(hi))
    fail(std::string(what) + " out of range (got " + std::to_string(value) + ", expected " + std::to_string(lo) + " to " +
         std::to_string(hi) + ")");
  return static_cast<T>(value);
}

/// A token as a finite double; otherwise calls fail(message), which throws.
template <class Fail>
[[nodiscard]] double real_token(std::string_view token, std::string_view what, Fail&& fail) {
  double value = 0;
  const char* first = token.data() + (token.size() > 1 && token[0] == '+' ? 1 : 0);
  const auto [ptr, ec] = std::from_chars(first, token.data() + token.size(), value);
  if (ec != std::errc() || ptr != token.data() + token.size())
    fail("expected " + std::string(what) + " as a number (got '" + shorten_token(token) + "')");
  if (!std::isfinite(value)) fail(std::string(what) + " is not finite (got '" + shorten_token(token) + "')");
  return value;
}

class TextCursor {
 public:
  /// `text` must outlive the cursor; `file` is the name used in error messages.
  /// A UTF-8 byte-order mark at the start (editors on Windows write one) is skipped.
  TextCursor(std::string_view text, std::filesystem::path file)
      : begin_(text.data()),
        pos_(text.data() + (text.starts_with("\xEF\xBB\xBF") ? 3 : 0)),
        end_(text.data() + text.size()),
        file_(std::move(file)) {}

  [[nodiscard]] const std::filesystem::path& file() const noexcept { return file_; }
  [[nodiscard]] std::uint64_t line() const noexcept { return line_; }
  [[nodiscard]] std::size_t offset() const noexcept { return static_cast<std::size_t>(pos_ - begin_); }
  [[nodiscard]] std::string_view remaining() const noexcept { return {pos_, static_cast<std::size_t>(end_ - pos_)}; }

  /// Moves to byte `offset` (after a binary section); `newlines` lines were passed on the way.
  void seek(std::size_t offset, std::uint64_t newlines = 0) {
    pos_ = begin_ + offset;
    line_ += newlines;
  }

  /// Report positions as byte offsets from now on (binary files).
  void use_byte_offsets() noexcept { byte_offsets_ = true; }

  [[noreturn]] void fail(const std::string& what) const {
    if (byte_offsets_) throw ParseError(file_, offset(), what, ParseError::Position::byte_offset);
    throw ParseError(file_, line_, what);
  }

  /// Skips blanks and line ends (counting lines).
  void skip_space() noexcept {
    while (pos_ < end_) {
      const char c = *pos_;
      if (c == '\n') ++line_;
      else if (c != ' ' && c != '\t' && c != '\r' && c != '\f' && c != '\v') return;
      ++pos_;
    }
  }
  /// Skips blanks on the current line only.
  void skip_blanks() noexcept {
    while (pos_ < end_ && (*pos_ == ' ' || *pos_ == '\t' || *pos_ == '\r')) ++pos_;
  }
  [[nodiscard]] bool at_end() noexcept {
    skip_space();
    return pos_ == end_;
  }
  /// True when only blanks remain on the current line.
  [[nodiscard]] bool at_line_end() noexcept {
    skip_blanks();
    return pos_ == end_ || *pos_ == '\n';
  }
  /// Moves past the next line end.
  void next_line() noexcept {
    while (pos_ < end_ && *pos_ != '\n') ++pos_;
    if (pos_ < end_) {
      ++pos_;
      ++line_;
    }
  }

  /// The next whitespace-separated token; fails at the end of the text.
  [[nodiscard]] std::string_view word(std::string_view what) {
    skip_space();
    if (pos_ == end_) fail("unexpected end of file (expected " + std::string(what) + ")");
    const char* start = pos_;
    while (pos_ < end_ && !is_space(*pos_)) ++pos_;
    return {start, static_cast<std::size_t>(pos_ - start)};
  }

  /// The rest of the current line without surrounding blanks; moves to the next line.
  [[nodiscard]] std::string_view rest_of_line() {
    skip_blanks();
    const char* start = pos_;
    while (pos_ < end_ && *pos_ != '\n') ++pos_;
    const char* stop = pos_;
    while (stop > start && is_space(stop[-1])) --stop;
    next_line();
    return {start, static_cast<std::size_t>(stop - start)};
  }

  /// Next token as an integer of type T, in [lo, hi].
  template <class T>
    requires std::is_signed_v<T>
  [[nodiscard]] T integer(std::string_view what, T lo = std::numeric_limits<T>::min(),
                          T hi = std::numeric_limits<T>::max()) {
    return integer_token(word(what), what, lo, hi, [this](const std::string& m) { fail(m); });
  }

  /// Next token as a finite double.
  [[nodiscard]] double real(std::string_view what) {
    return real_token(word(what), what, [this](const std::string& m) { fail(m); });
  }

  /// Requires the next token to be exactly `expected`.
  void expect(std::string_view expected) {
    const std::string_view token = word(expected);
    if (token != expected) fail("expected '" + std::string(expected) + "' (got '" + shorten(token) + "')");
  }

  /// Skips text up to and past the line that starts with `marker`; fails if there is none.
  void skip_past(std::string_view marker) {
    for (;;) {
      skip_space();
      if (pos_ == end_) fail("unexpected end of file (expected " + std::string(marker) + ")");
      if (remaining().starts_with(marker)) {
        pos_ += marker.size();
        return;
      }
      next_line();
    }
  }

  /// A token cut to a readable length for messages.
  [[nodiscard]] static std::string shorten(std::string_view token) { return shorten_token(token); }

 private:
  static bool is_space(char c) noexcept {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
  }

  const char* begin_;
  const char* pos_;
  const char* end_;
  std::filesystem::path file_;
  std::uint64_t line_ = 1;
  bool byte_offsets_ = false;
};

}  // namespace meshmotion::detail
