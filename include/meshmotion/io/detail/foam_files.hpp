#pragma once
/// \file
/// Reading OpenFOAM's files: the token cursor, the FoamFile header, label lists, gzip, and
/// the polyMesh folder a path names. Shared by io/openfoam_reader.hpp and io/openfoam_writer.hpp.

#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/io/detail/text_cursor.hpp"

#include <array>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#ifdef MESHMOTION_HAVE_ZLIB
#include <zlib.h>
#endif

namespace meshmotion::detail {

/// Tokens of an OpenFOAM file: words, numbers, punctuation ( ) { } ; and quoted strings;
/// comments skipped; lines counted for messages. Binary list bodies are read as raw bytes.
class FoamCursor {
 public:
  FoamCursor(std::string_view text, std::filesystem::path file) : text_(text), file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& what) const {
    if (binary_) throw ParseError(file_, pos_, what, ParseError::Position::byte_offset);
    throw ParseError(file_, line_, what);
  }
  [[nodiscard]] const std::filesystem::path& file() const noexcept { return file_; }

  void skip_space() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == '\n') {
        ++line_;
        ++pos_;
      } else if (c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v') {
        ++pos_;
      } else if (text_.compare(pos_, 2, "//") == 0) {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else if (text_.compare(pos_, 2, "/*") == 0) {
        const std::size_t end = text_.find("*/", pos_ + 2);
        if (end == std::string_view::npos) run_out("unterminated comment");
        for (std::size_t k = pos_; k < end; ++k)
          if (text_[k] == '\n') ++line_;
        pos_ = end + 2;
      } else {
        return;
      }
    }
  }

  [[nodiscard]] bool at_end() {
    skip_space();
    return pos_ >= text_.size();
  }
  [[nodiscard]] char peek() {
    skip_space();
    return pos_ < text_.size() ? text_[pos_] : '\0';
  }

  /// The next token; `what` names it in the message at the end of the file.
  [[nodiscard]] std::string_view token(std::string_view what) {
    skip_space();
    if (pos_ >= text_.size()) run_out("unexpected end of file (expected " + std::string(what) + ")");
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (c == '(' || c == ')' || c == '{' || c == '}' || c == ';') {
      ++pos_;
      return text_.substr(start, 1);
    }
    if (c == '"') {
      const std::size_t end = text_.find('"', pos_ + 1);
      if (end == std::string_view::npos) run_out("unterminated string");
      pos_ = end + 1;
      return text_.substr(start, pos_ - start);
    }
    while (pos_ < text_.size()) {
      const char d = text_[pos_];
      if (d == ' ' || d == '\t' || d == '\n' || d == '\r' || d == '(' || d == ')' || d == '{' || d == '}' || d == ';' || d == '"')
        break;
      ++pos_;
    }
    return text_.substr(start, pos_ - start);
  }

  void expect(std::string_view expected) {
    const std::string_view t = token(expected);
    if (t != expected) fail("expected '" + std::string(expected) + "' (got '" + shorten_token(t) + "')");
  }

  template <class T>
  [[nodiscard]] T integer(std::string_view what, T lo, T hi) {
    return integer_token(token(what), what, lo, hi, [this](const std::string& m) { fail(m); });
  }
  [[nodiscard]] double real(std::string_view what) {
    return real_token(token(what), what, [this](const std::string& m) { fail(m); });
  }

  /// Refuses a list count `n` when the rest of the file cannot hold that many entries of at
  /// least `entry_bytes` bytes each: a corrupt count must not allocate gigabytes.
  void check_count(Index n, std::string_view what, std::size_t entry_bytes) {
    const std::size_t left = text_.size() - std::min(pos_, text_.size());
    if (static_cast<std::size_t>(n) > left / entry_bytes + 1)
      fail(std::string(what) + " count " + std::to_string(n) + " is more than the " + std::to_string(left) +
           " bytes left in the file can hold");
  }

  /// `count` raw bytes right after the current position (a binary list body).
  [[nodiscard]] std::string_view raw(std::size_t count, std::string_view what) {
    if (pos_ + count > text_.size())
      run_out("binary " + std::string(what) + " ends after " + std::to_string(text_.size() - pos_) + " of " + std::to_string(count) +
           " bytes");
    const std::string_view bytes = text_.substr(pos_, count);
    pos_ += count;
    return bytes;
  }
  /// Positions from now on are byte offsets (binary content follows).
  void use_byte_offsets() noexcept { binary_ = true; }
  [[nodiscard]] std::size_t offset() const noexcept { return pos_; }
  /// The last failure was the text ending early (a prefix of a longer file may go on).
  [[nodiscard]] bool ran_out() const noexcept { return ran_out_; }

  /// Refuses anything but spaces and comments after the content `what`: bytes appended to a
  /// file (a damaged copy, NUL padding) are not part of any mesh.
  void expect_end(std::string_view what) {
    skip_space();
    if (pos_ >= text_.size()) return;
    const std::string got = text_[pos_] == '\0' ? std::string("a NUL byte") : "'" + shorten_token(token("the end")) + "'";
    fail("unexpected content after the " + std::string(what) + " (" + got + ")");
  }

 private:
  [[noreturn]] void run_out(const std::string& what) {
    ran_out_ = true;
    fail(what);
  }


  std::string_view text_;
  std::filesystem::path file_;
  std::size_t pos_ = 0;
  std::uint64_t line_ = 1;
  bool binary_ = false;
  bool ran_out_ = false;
};

/// The FoamFile header entries, and where the data after it starts.
struct FoamHeader {
  std::map<std::string, std::string> entries;
  bool binary = false;
  int label_bytes = 4;
  int scalar_bytes = 8;
  std::size_t data_offset = 0;  ///< byte offset just past the header's closing brace
};

[[nodiscard]] inline FoamHeader read_foam_header(FoamCursor& in) {
  FoamHeader h;
  in.expect("FoamFile");
  in.expect("{");
  for (;;) {
    const std::string key(in.token("a header entry or '}'"));
    if (key == "}") break;
    std::string value;
    for (std::string_view t = in.token("';'"); t != ";"; t = in.token("';'")) {
      if (!value.empty()) value += ' ';
      value.append(t);
    }
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') value = value.substr(1, value.size() - 2);
    h.entries[key] = value;
  }
  h.data_offset = in.offset();
  const auto format = h.entries.find("format");
  if (format != h.entries.end()) {
    if (format->second == "binary") h.binary = true;
    else if (format->second != "ascii") in.fail("FoamFile format '" + format->second + "' (expected ascii or binary)");
  }
  if (const auto arch = h.entries.find("arch"); arch != h.entries.end()) {
    const auto size_of = [&](std::string_view key, int fallback) {
      const std::size_t at = arch->second.find(key);
      if (at == std::string::npos) return fallback;
      int bits = 0;
      const char* first = arch->second.data() + at + key.size();
      std::from_chars(first, arch->second.data() + arch->second.size(), bits);
      if (bits != 32 && bits != 64) in.fail("FoamFile arch '" + arch->second + "': " + std::string(key) + " must be 32 or 64");
      return bits / 8;
    };
    h.label_bytes = size_of("label=", 4);
    h.scalar_bytes = size_of("scalar=", 8);
    if (arch->second.find("MSB") != std::string::npos) in.fail("FoamFile arch '" + arch->second + "': big-endian data is not supported");
  }
  return h;
}

/// Refuses a header whose `class` is none of `expected` (OpenFOAM itself refuses such a file,
/// and write_polymesh_points() would copy the class into what it writes). A header without
/// `class` is taken as it is.
inline void check_foam_class(FoamCursor& in, const FoamHeader& h, std::initializer_list<std::string_view> expected) {
  const auto cls = h.entries.find("class");
  if (cls == h.entries.end()) return;
  std::string list;
  for (const std::string_view e : expected) {
    if (cls->second == e) return;
    if (!list.empty()) list += " or ";
    list += e;
  }
  in.fail("FoamFile class '" + cls->second + "' (expected " + list + ")");
}

/// A list of labels: "N ( a b c ... )", its binary form, or "N{value}". A uniform list
/// "N{value}" holds no entries in the file: its count is refused beyond `max_uniform`.
[[nodiscard]] inline std::vector<Index> read_label_list(FoamCursor& in, const FoamHeader& h, std::string_view what,
                                                        Index max_uniform) {
  const auto n = in.integer<Index>(std::string(what) + " count", 0, std::numeric_limits<Index>::max());
  std::vector<Index> out;
  if (in.peek() == '{') {
    if (n > max_uniform) in.fail("uniform " + std::string(what) + " list of " + std::to_string(n) + " entries (at most " +
                                 std::to_string(max_uniform) + " here)");
    in.expect("{");
    const auto v = in.integer<std::int64_t>(what, std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max());
    in.expect("}");
    out.assign(static_cast<std::size_t>(n), static_cast<Index>(v));
    return out;
  }
  in.expect("(");
  // An ASCII label takes a digit and a separator at least.
  in.check_count(n, what, h.binary ? static_cast<std::size_t>(h.label_bytes) : 2);
  out.resize(static_cast<std::size_t>(n));
  if (h.binary && n > 0) {
    in.use_byte_offsets();
    const std::string_view bytes = in.raw(static_cast<std::size_t>(n) * static_cast<std::size_t>(h.label_bytes), what);
    for (std::size_t k = 0; k < out.size(); ++k) {
      if (h.label_bytes == 4) {
        std::int32_t v = 0;
        std::memcpy(&v, bytes.data() + 4 * k, 4);
        out[k] = v;
      } else {
        std::int64_t v = 0;
        std::memcpy(&v, bytes.data() + 8 * k, 8);
        out[k] = static_cast<Index>(v);
      }
    }
  } else {
    for (auto& v : out) v = in.integer<Index>(what, std::numeric_limits<Index>::min(), std::numeric_limits<Index>::max());
  }
  in.expect(")");
  return out;
}

/// The bytes a polyMesh list file needs from its start: its header and its list (both lists
/// of a faceCompactList); nullopt while `prefix` ends before they do, or for a file of
/// another class (dictionaries and zones, whose nested binary lists only their readers
/// know). Throws ParseError where `prefix` is no such file.
[[nodiscard]] inline std::optional<std::size_t> foam_list_extent(std::string_view prefix, const std::filesystem::path& file) {
  FoamCursor in(prefix, file);
  try {
    const FoamHeader h = read_foam_header(in);
    const auto cls = h.entries.find("class");
    if (cls == h.entries.end()) return std::nullopt;
    const bool compact = cls->second == "faceCompactList" || (h.binary && cls->second == "faceList");
    const bool vectors = cls->second == "vectorField";
    if (!compact && !vectors && cls->second != "labelList" && cls->second != "faceList") return std::nullopt;
    const std::size_t width = static_cast<std::size_t>(vectors ? 3 * h.scalar_bytes : h.label_bytes);
    for (int list = 0; list < (compact ? 2 : 1); ++list) {
      const auto n = static_cast<std::size_t>(in.integer<std::int64_t>("a list count", 0, std::numeric_limits<std::int64_t>::max() / 16));
      if (in.peek() == '{') {
        in.expect("{");
        (void)in.token("a uniform value");
        in.expect("}");
        continue;
      }
      in.expect("(");
      if (h.binary) {
        in.use_byte_offsets();
        (void)in.raw(n * width, "list");
        in.expect(")");
        continue;
      }
      for (int depth = 1; depth > 0;) {
        const std::string_view t = in.token("')'");
        if (t == "(") ++depth;
        if (t == ")") --depth;
      }
    }
    return in.offset();
  } catch (const ParseError&) {
    if (in.ran_out()) return std::nullopt;
    throw;
  }
}

/// The whole content of `file`, or of `file`.gz decompressed (zlib) when only that exists.
/// A compressed list file is decompressed no further than its list needs and a short tail
/// (comments): a few compressed bytes must not become gigabytes. Throws ParseError for more.
[[nodiscard]] inline std::string read_foam_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::exists(file, ec)) return read_whole_file(file);
  std::filesystem::path gz = file;
  gz += ".gz";
  if (!std::filesystem::exists(gz, ec)) throw IoError(file.string() + ": no such file (nor " + gz.filename().string() + ")");
#ifdef MESHMOTION_HAVE_ZLIB
  const std::uintmax_t packed = std::filesystem::file_size(gz, ec);
  gzFile in = gzopen(gz.c_str(), "rb");
  if (in == nullptr) throw IoError(gz.string() + ": cannot open for reading");
  constexpr std::size_t tail = 64 * 1024;
  // Files of other classes: a ratio no real OpenFOAM file reaches (ASCII compresses ~10:1).
  std::size_t limit = std::max<std::size_t>(64u << 20, 256 * static_cast<std::size_t>(ec ? 0 : packed));
  std::size_t next_look = 1 << 16;
  bool sized = false;
  std::string data;
  std::array<char, 1 << 16> buffer{};
  const auto refuse = [&](auto&& error) {
    gzclose(in);
    throw error;
  };
  for (;;) {
    const int got = gzread(in, buffer.data(), static_cast<unsigned>(buffer.size()));
    if (got < 0) {
      int code = 0;
      refuse(IoError(gz.string() + ": decompression failed (" + gzerror(in, &code) + ")"));
    }
    if (got == 0) break;
    data.append(buffer.data(), static_cast<std::size_t>(got));
    if (!sized && data.size() >= next_look) {
      // Looked at each time the text doubles: linear in all.
      next_look = 2 * data.size();
      try {
        if (const auto extent = foam_list_extent(data, gz)) {
          limit = *extent + tail;
          sized = true;
        }
      } catch (const ParseError&) {
        break;  // not a list file: its reader finds the same fault in what is here, and says it
      }
    }
    if (data.size() > limit)
      refuse(ParseError(gz, limit,
                        sized ? "decompresses to more than its list needs (" + std::to_string(limit - tail) + " bytes) and a " +
                                    std::to_string(tail) + "-byte tail: bytes after the list"
                              : "decompresses to more than " + std::to_string(limit) + " bytes (the larger of 64 MiB and 256 times its compressed size)",
                        ParseError::Position::byte_offset));
  }
  gzclose(in);
  return data;
#else
  throw InputError(gz.string() + ": compressed OpenFOAM files need zlib (meshmotion was built without it: install zlib1g-dev and "
                   "reconfigure)");
#endif
}

/// Which of a polyMesh folder's files is compressed.
[[nodiscard]] inline bool foam_file_is_compressed(const std::filesystem::path& file) {
  std::error_code ec;
  std::filesystem::path gz = file;
  gz += ".gz";
  return !std::filesystem::exists(file, ec) && std::filesystem::exists(gz, ec);
}

/// The polyMesh folder a path names: a case (its constant/polyMesh) or the folder itself.
[[nodiscard]] inline std::filesystem::path polymesh_folder(const std::filesystem::path& path) {
  std::error_code ec;
  const auto has_faces = [&](const std::filesystem::path& dir) {
    return std::filesystem::exists(dir / "faces", ec) || std::filesystem::exists(dir / "faces.gz", ec);
  };
  if (has_faces(path / "constant" / "polyMesh")) return path / "constant" / "polyMesh";
  if (has_faces(path)) return path;
  return {};
}

/// Whether a folder name is a time, as OpenFOAM names them ("0", "0.25", "1e-05").
[[nodiscard]] inline bool is_foam_time_name(const std::string& name, double* value = nullptr) {
  double t = 0;
  const auto [end, ec] = std::from_chars(name.data(), name.data() + name.size(), t);
  if (ec != std::errc() || end != name.data() + name.size() || name.empty()) return false;
  if (value != nullptr) *value = t;
  return true;
}

/// A time folder of a case ("<case>/<time>", the case holding a constant/polyMesh, or
/// "<case>/<time>/<region>", the case holding a constant/<region>/polyMesh): where a moved
/// mesh's points go (<case>/<time>[/<region>]/polyMesh/points) and OpenFOAM's tools read them
/// from.
struct FoamTimeFolder {
  std::filesystem::path case_dir, constant;  ///< the case, and its (region's) polyMesh folder
  std::string time;
  std::string region{};  ///< empty: the case's default region
  [[nodiscard]] std::filesystem::path mesh_folder(const std::string& at) const {
    return (region.empty() ? case_dir / at : case_dir / at / region) / "polyMesh";
  }
  [[nodiscard]] std::filesystem::path points() const { return mesh_folder(time) / "points"; }
  /// The points OpenFOAM's tools read at this time: those of the latest time up to it that
  /// holds them (the mesh moved then and not since), else the constant ones.
  [[nodiscard]] std::filesystem::path current_points() const {
    double now = 0, best = 0;
    (void)is_foam_time_name(time, &now);
    std::filesystem::path found = constant / "points";
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(case_dir, ec)) {
      const std::string name = entry.path().filename().string();
      double t = 0;
      if (!is_foam_time_name(name, &t) || t > now || (found != constant / "points" && t <= best)) continue;
      const std::filesystem::path file = mesh_folder(name) / "points";
      if (std::filesystem::exists(file, ec) || std::filesystem::exists(file.string() + ".gz", ec)) {
        found = file;
        best = t;
      }
    }
    return found;
  }
};
[[nodiscard]] inline std::optional<FoamTimeFolder> foam_time_folder(const std::filesystem::path& path) {
  const std::filesystem::path folder = path.has_filename() ? path : path.parent_path();
  const auto case_of = [](const std::filesystem::path& p) { return p.empty() ? std::filesystem::path(".") : p; };
  if (const std::string time = folder.filename().string(); is_foam_time_name(time)) {
    const std::filesystem::path case_dir = case_of(folder.parent_path());
    std::filesystem::path constant = polymesh_folder(case_dir);
    if (constant.empty()) return std::nullopt;
    return FoamTimeFolder{case_dir, std::move(constant), time};
  }
  const std::string time = folder.parent_path().filename().string(), region = folder.filename().string();
  if (!is_foam_time_name(time) || region.empty()) return std::nullopt;
  const std::filesystem::path case_dir = case_of(folder.parent_path().parent_path());
  std::filesystem::path constant = polymesh_folder(case_dir / "constant" / region / "polyMesh");
  if (constant.empty()) return std::nullopt;
  return FoamTimeFolder{case_dir, std::move(constant), time, region};
}

}  // namespace meshmotion::detail
