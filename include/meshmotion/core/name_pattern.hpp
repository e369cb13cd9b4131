#pragma once
/// \file
/// Group names as OpenFOAM users write them: a regular expression naming several patches
/// (`"(inlet|outlet)"`, `"wall.*"`), matched against the whole name as OpenFOAM's wordRe
/// matches it. The syntax is the part of POSIX extended / ECMAScript expressions that
/// dictionaries use: literals, `.`, classes (`[a-z]`, `[^0-9]`, `\d`, `\w`, `\s`), groups with
/// alternatives (`(a|b)`), the quantifiers `*`, `+` and `?`, `\` escapes, and `^`/`$` at the
/// ends (the match is whole anyway). A matcher of its own: std::regex costs seconds of
/// compilation in every translation unit that would include it.

#include "meshmotion/core/error.hpp"

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace meshmotion {

/// A compiled name pattern. Throws InputError naming the pattern and the position for
/// malformed or unsupported syntax (an unclosed group or class, a quantifier with nothing to
/// repeat, counted repetition `{n,m}`).
class NamePattern {
 public:
  explicit NamePattern(std::string_view text) : text_(text) {
    std::size_t at = 0;
    if (at < text_.size() && text_[at] == '^') ++at;
    root_ = parse_alternatives(at);
    if (at < text_.size() && text_[at] == '$' && at + 1 == text_.size()) ++at;
    if (at != text_.size()) fail(at, text_[at] == ')' ? "a ')' closes no group" : "unexpected character");
  }

  /// True when the whole of `name` matches.
  [[nodiscard]] bool matches(std::string_view name) const {
    return match_alternatives(root_, name, 0, [&](std::size_t end) { return end == name.size(); });
  }

  /// Whether `text` uses any character with a meaning in a pattern (a plain name does not).
  [[nodiscard]] static bool is_pattern(std::string_view text) {
    return text.find_first_of("()|[].*+?\\^$") != std::string_view::npos;
  }

 private:
  struct Range {
    char low, high;
  };
  struct Piece {
    enum class Kind { literal, any, set, group } kind = Kind::literal;
    char literal = 0;
    std::vector<Range> ranges;  ///< set
    bool negated = false;       ///< set
    std::size_t group = 0;      ///< index into alternatives_
    int min = 1, max = 1;       ///< repetitions; max < 0: unbounded
  };
  using Sequence = std::vector<Piece>;
  using Continuation = std::function<bool(std::size_t)>;

  [[noreturn]] void fail(std::size_t at, const std::string& why) const {
    throw InputError("group name pattern '" + text_ + "': " + why + " at position " + std::to_string(at) +
                     " (supported: literals, '.', [classes], (a|b) groups, *, + and ?)");
  }

  std::size_t parse_alternatives(std::size_t& at) {
    std::vector<Sequence> options;
    for (;;) {
      options.push_back(parse_sequence(at));
      if (at < text_.size() && text_[at] == '|') {
        ++at;
        continue;
      }
      break;
    }
    alternatives_.push_back(std::move(options));
    return alternatives_.size() - 1;
  }

  Sequence parse_sequence(std::size_t& at) {
    Sequence out;
    while (at < text_.size() && text_[at] != '|' && text_[at] != ')') {
      if (text_[at] == '$' && at + 1 == text_.size()) break;
      Piece piece = parse_atom(at);
      if (at < text_.size() && (text_[at] == '*' || text_[at] == '+' || text_[at] == '?')) {
        piece.min = text_[at] == '+' ? 1 : 0;
        piece.max = text_[at] == '?' ? 1 : -1;
        ++at;
        if (at < text_.size() && (text_[at] == '*' || text_[at] == '+' || text_[at] == '?')) fail(at, "a quantifier repeats a quantifier");
      }
      out.push_back(std::move(piece));
    }
    return out;
  }

  Piece parse_atom(std::size_t& at) {
    Piece p;
    const char c = text_[at];
    switch (c) {
      case '(': {
        const std::size_t open = at++;
        p.kind = Piece::Kind::group;
        p.group = parse_alternatives(at);
        if (at >= text_.size() || text_[at] != ')') fail(open, "a '(' is not closed");
        ++at;
        return p;
      }
      case '[':
        return parse_class(at);
      case '.':
        p.kind = Piece::Kind::any;
        ++at;
        return p;
      case '*':
      case '+':
      case '?':
        fail(at, "a quantifier has nothing to repeat");
      case '{':
      case '}':
        fail(at, "counted repetition is not supported");
      case '\\':
        if (at + 1 >= text_.size()) fail(at, "a '\\' ends the pattern");
        at += 2;
        return escaped(text_[at - 1]);
      default:
        p.literal = c;
        ++at;
        return p;
    }
  }

  // \d, \w, \s as classes; any other escaped character stands for itself.
  static Piece escaped(char c) {
    Piece p;
    p.kind = Piece::Kind::set;
    switch (c) {
      case 'd': p.ranges = {{'0', '9'}}; return p;
      case 'w': p.ranges = {{'a', 'z'}, {'A', 'Z'}, {'0', '9'}, {'_', '_'}}; return p;
      case 's': p.ranges = {{' ', ' '}, {'\t', '\r'}}; return p;
      default:
        p.kind = Piece::Kind::literal;
        p.literal = c;
        return p;
    }
  }

  Piece parse_class(std::size_t& at) {
    const std::size_t open = at++;
    Piece p;
    p.kind = Piece::Kind::set;
    if (at < text_.size() && text_[at] == '^') {
      p.negated = true;
      ++at;
    }
    bool first = true;
    while (at < text_.size() && (text_[at] != ']' || first)) {
      char low = text_[at];
      if (low == '\\' && at + 1 < text_.size()) {
        const Piece e = escaped(text_[++at]);
        ++at;
        if (e.kind == Piece::Kind::set) {
          p.ranges.insert(p.ranges.end(), e.ranges.begin(), e.ranges.end());
          first = false;
          continue;
        }
        low = e.literal;
      } else {
        ++at;
      }
      char high = low;
      if (at + 1 < text_.size() && text_[at] == '-' && text_[at + 1] != ']') {
        high = text_[at + 1];
        at += 2;
        if (high < low) fail(at - 1, "a class range runs backwards");
      }
      p.ranges.push_back({low, high});
      first = false;
    }
    if (at >= text_.size()) fail(open, "a '[' is not closed");
    ++at;
    return p;
  }

  [[nodiscard]] static bool single(const Piece& p, char c) {
    if (p.kind == Piece::Kind::any) return true;
    if (p.kind == Piece::Kind::literal) return p.literal == c;
    bool in = false;
    for (const Range& r : p.ranges) in = in || (c >= r.low && c <= r.high);
    return in != p.negated;
  }

  // Backtracking with continuations: `rest` is asked whether the remainder matches from an end.
  [[nodiscard]] bool match_alternatives(std::size_t alternatives, std::string_view name, std::size_t at,
                                        const Continuation& rest) const {
    for (const Sequence& s : alternatives_[alternatives])
      if (match_sequence(s, 0, name, at, rest)) return true;
    return false;
  }

  [[nodiscard]] bool match_sequence(const Sequence& s, std::size_t i, std::string_view name, std::size_t at,
                                    const Continuation& rest) const {
    if (i == s.size()) return rest(at);
    return match_piece(s[i], 0, name, at, [&](std::size_t end) { return match_sequence(s, i + 1, name, end, rest); });
  }

  [[nodiscard]] bool match_piece(const Piece& p, int count, std::string_view name, std::size_t at, const Continuation& rest) const {
    // Greedy: one more repetition first (each must consume a character, or the loop would not end).
    if (p.max < 0 || count < p.max) {
      const Continuation again = [&](std::size_t end) {
        return (end > at || count < p.min) && match_piece(p, count + 1, name, end, rest);
      };
      if (p.kind == Piece::Kind::group) {
        if (match_alternatives(p.group, name, at, again)) return true;
      } else if (at < name.size() && single(p, name[at]) && again(at + 1)) {
        return true;
      }
    }
    return count >= p.min && rest(at);
  }

  std::string text_;
  std::vector<std::vector<Sequence>> alternatives_;
  std::size_t root_ = 0;
};

}  // namespace meshmotion
