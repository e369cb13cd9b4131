#pragma once
/// \file
/// OpenFOAM polyMesh (`constant/polyMesh/`: points, faces, owner, neighbour, boundary) in, and
/// moved points back out, in place.
///
/// Reading: ASCII and binary files (FoamFile header; `arch` label and scalar sizes),
/// `faceList` and `faceCompactList` faces, gzip-compressed files (`points.gz`, ...) when
/// built with zlib. read_polymesh() gives the face-based mesh as the files hold it;
/// to_mesh() turns it into a Mesh<3>:
/// - when every cell is a tetrahedron, pyramid, prism or hexahedron (4, 5, 6 or 8 vertices
///   with the faces of that shape), the cells are those elements, numbered as OpenFOAM's cells
///   (ids = cell + 1), and nothing is added;
/// - otherwise every cell is cut into tetrahedra around its centre, each face of more than
///   three vertices around its centre too (as OpenFOAM's own tet decomposition does); those
///   centres are appended after the points as auxiliary nodes (Mesh::num_auxiliary_nodes).
/// Patches become facet groups (tag = patch index + 1) of the boundary faces, oriented out of
/// the domain as OpenFOAM lists them. Malformed files give the file, the line (ASCII) or byte
/// offset (binary) and the entry; inconsistent lists (an owner list shorter than the faces, a
/// face index out of range, patches that do not cover the boundary faces) name the list.
///
/// Writing: write_polymesh_points() replaces the `points` of a case, atomically, keeping the
/// case's own header, format (ASCII or binary) and compression; the faces and the rest of the
/// case are not touched. It writes the nodes before the auxiliary ones and refuses a mesh whose
/// node count differs from the case's. Targets: a case folder (its constant/polyMesh), a
/// polyMesh folder, or a time folder of a case (`case/0.001`: its polyMesh/points, created,
/// which is where OpenFOAM looks for moved points).

#include "meshmotion/core/element.hpp"
#include "meshmotion/core/error.hpp"
#include "meshmotion/core/mesh.hpp"
#include "meshmotion/core/topology.hpp"
#include "meshmotion/io/detail/atomic_file.hpp"
#include "meshmotion/io/detail/number_format.hpp"
#include "meshmotion/io/detail/read_file.hpp"
#include "meshmotion/io/detail/text_cursor.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <vector>

#ifdef MESHMOTION_HAVE_ZLIB
#include <zlib.h>
#endif

namespace meshmotion {

/// An OpenFOAM polyMesh as its files hold it: faces as vertex lists (outward from their owner
/// cell), owner and neighbour cells per face (internal faces first), patches as face ranges.
struct PolyMesh {
  struct Patch {
    std::string name;
    std::string type;  ///< patch, wall, empty, symmetryPlane, ...
    Index start = 0;   ///< first face
    Index size = 0;    ///< number of faces
  };
  Points<3> points;
  std::vector<Index> face_offsets{0};  ///< face f: face_nodes[face_offsets[f] .. face_offsets[f+1])
  std::vector<Index> face_nodes;
  std::vector<Index> owner;      ///< one per face
  std::vector<Index> neighbour;  ///< one per internal face
  std::vector<Patch> patches;
  Index num_cells = 0;

  [[nodiscard]] Index num_faces() const noexcept { return static_cast<Index>(face_offsets.size()) - 1; }
  [[nodiscard]] Index num_internal_faces() const noexcept { return static_cast<Index>(neighbour.size()); }
  [[nodiscard]] std::span<const Index> face(Index f) const {
    return {face_nodes.data() + face_offsets[static_cast<std::size_t>(f)],
            static_cast<std::size_t>(face_offsets[static_cast<std::size_t>(f) + 1] - face_offsets[static_cast<std::size_t>(f)])};
  }
};

namespace detail {

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
        if (end == std::string_view::npos) fail("unterminated comment");
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
    if (pos_ >= text_.size()) fail("unexpected end of file (expected " + std::string(what) + ")");
    const std::size_t start = pos_;
    const char c = text_[pos_];
    if (c == '(' || c == ')' || c == '{' || c == '}' || c == ';') {
      ++pos_;
      return text_.substr(start, 1);
    }
    if (c == '"') {
      const std::size_t end = text_.find('"', pos_ + 1);
      if (end == std::string_view::npos) fail("unterminated string");
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

  /// `count` raw bytes right after the current position (a binary list body).
  [[nodiscard]] std::string_view raw(std::size_t count, std::string_view what) {
    if (pos_ + count > text_.size())
      fail("binary " + std::string(what) + " ends after " + std::to_string(text_.size() - pos_) + " of " + std::to_string(count) +
           " bytes");
    const std::string_view bytes = text_.substr(pos_, count);
    pos_ += count;
    return bytes;
  }
  /// Positions from now on are byte offsets (binary content follows).
  void use_byte_offsets() noexcept { binary_ = true; }
  [[nodiscard]] std::size_t offset() const noexcept { return pos_; }


 private:
  std::string_view text_;
  std::filesystem::path file_;
  std::size_t pos_ = 0;
  std::uint64_t line_ = 1;
  bool binary_ = false;
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

/// A list of labels: "N ( a b c ... )", its binary form, or "N{value}".
[[nodiscard]] inline std::vector<Index> read_label_list(FoamCursor& in, const FoamHeader& h, std::string_view what) {
  const auto n = in.integer<std::int64_t>(std::string(what) + " count", 0, std::int64_t{1} << 40);
  std::vector<Index> out;
  if (in.peek() == '{') {
    in.expect("{");
    const auto v = in.integer<std::int64_t>(what, std::numeric_limits<std::int64_t>::min(), std::numeric_limits<std::int64_t>::max());
    in.expect("}");
    out.assign(static_cast<std::size_t>(n), static_cast<Index>(v));
    return out;
  }
  in.expect("(");
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

/// The whole content of `file`, or of `file`.gz decompressed (zlib) when only that exists.
[[nodiscard]] inline std::string read_foam_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::exists(file, ec)) return read_whole_file(file);
  std::filesystem::path gz = file;
  gz += ".gz";
  if (!std::filesystem::exists(gz, ec)) throw IoError(file.string() + ": no such file (nor " + gz.filename().string() + ")");
#ifdef MESHMOTION_HAVE_ZLIB
  gzFile in = gzopen(gz.c_str(), "rb");
  if (in == nullptr) throw IoError(gz.string() + ": cannot open for reading");
  std::string data;
  std::array<char, 1 << 16> buffer{};
  for (;;) {
    const int got = gzread(in, buffer.data(), static_cast<unsigned>(buffer.size()));
    if (got < 0) {
      int code = 0;
      const std::string message = gzerror(in, &code);
      gzclose(in);
      throw IoError(gz.string() + ": decompression failed (" + message + ")");
    }
    if (got == 0) break;
    data.append(buffer.data(), static_cast<std::size_t>(got));
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

/// Appends a points list ("N ( (x y z) ... )" or its binary form) to `out`.
inline void append_foam_points(std::string& out, const Eigen::Ref<const Points<3>>& points, const FoamHeader& h) {
  const Index n = points.cols();
  out += "\n\n\n";
  append_number(out, n);
  out += "\n(";
  if (h.binary) {
    const std::size_t at = out.size();
    out.resize(at + static_cast<std::size_t>(3 * n) * static_cast<std::size_t>(h.scalar_bytes));
    for (Index i = 0; i < n; ++i)
      for (int d = 0; d < 3; ++d) {
        const double v = points(d, i);
        char* dst = out.data() + at + static_cast<std::size_t>(3 * i + d) * static_cast<std::size_t>(h.scalar_bytes);
        if (h.scalar_bytes == 8) {
          std::memcpy(dst, &v, 8);
        } else {
          const auto f = static_cast<float>(v);
          std::memcpy(dst, &f, 4);
        }
      }
    out += ")\n";
    return;
  }
  out += '\n';
  for (Index i = 0; i < n; ++i) {
    out += '(';
    for (int d = 0; d < 3; ++d) {
      if (d > 0) out += ' ';
      append_number(out, points(d, i));
    }
    out += ")\n";
  }
  out += ")\n";
}

/// Writes `text` to `file` (or `file`.gz, compressed) through a temporary file and a rename.
inline void write_foam_file(const std::filesystem::path& file, const std::string& text, bool compressed) {
  if (!compressed) {
    write_file_atomically(file, text);
    return;
  }
#ifdef MESHMOTION_HAVE_ZLIB
  std::filesystem::path gz = file;
  gz += ".gz";
  write_through_temporary(gz, [&](const std::filesystem::path& tmp) {
    gzFile out = gzopen(tmp.c_str(), "wb");
    if (out == nullptr) throw IoError(gz.string() + ": cannot create the temporary file " + tmp.string());
    std::size_t done = 0;
    bool ok = true;
    while (ok && done < text.size()) {
      const auto chunk = static_cast<unsigned>(std::min<std::size_t>(text.size() - done, std::size_t{1} << 30));
      ok = gzwrite(out, text.data() + done, chunk) == static_cast<int>(chunk);
      done += chunk;
    }
    if (gzclose(out) != Z_OK || !ok) throw IoError(gz.string() + ": compressed write failed");
  });
#else
  throw InputError(file.string() + ".gz: compressed OpenFOAM files need zlib (meshmotion was built without it)");
#endif
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

/// Reads the points file: "N ( (x y z) ... )" or its binary form.
[[nodiscard]] inline Points<3> read_foam_points(const std::filesystem::path& file) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  const FoamHeader h = read_foam_header(in);
  const auto n = in.integer<Index>("point count", 0, Index{1} << 40);
  Points<3> points(3, n);
  in.expect("(");
  if (h.binary && n > 0) {
    in.use_byte_offsets();
    const std::string_view bytes = in.raw(static_cast<std::size_t>(3 * n) * static_cast<std::size_t>(h.scalar_bytes), "points");
    for (Index k = 0; k < 3 * n; ++k) {
      double v = 0;
      if (h.scalar_bytes == 8) {
        std::memcpy(&v, bytes.data() + 8 * k, 8);
      } else {
        float f = 0;
        std::memcpy(&f, bytes.data() + 4 * k, 4);
        v = f;
      }
      if (!std::isfinite(v)) in.fail("point " + std::to_string(k / 3) + " has a non-finite coordinate");
      points.data()[k] = v;
    }
  } else {
    for (Index i = 0; i < n; ++i) {
      in.expect("(");
      for (int d = 0; d < 3; ++d) points(d, i) = in.real("a point coordinate");
      in.expect(")");
    }
  }
  in.expect(")");
  return points;
}

/// Reads the faces: faceList "N ( k(a b ...) ... )" or faceCompactList (offsets, then labels).
inline void read_foam_faces(const std::filesystem::path& file, PolyMesh& mesh) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  const FoamHeader h = read_foam_header(in);
  const auto cls = h.entries.find("class");
  if (h.binary || (cls != h.entries.end() && cls->second == "faceCompactList")) {
    std::vector<Index> offsets = read_label_list(in, h, "face offsets");
    std::vector<Index> nodes = read_label_list(in, h, "face vertices");
    if (offsets.empty() || offsets.front() != 0 || offsets.back() != static_cast<Index>(nodes.size()))
      in.fail("faceCompactList offsets do not span the vertex list (first " + std::to_string(offsets.empty() ? -1 : offsets.front()) +
              ", last " + std::to_string(offsets.empty() ? -1 : offsets.back()) + ", vertices " + std::to_string(nodes.size()) + ")");
    for (std::size_t k = 1; k < offsets.size(); ++k)
      if (offsets[k] < offsets[k - 1] + 3) in.fail("face " + std::to_string(k - 1) + " has fewer than 3 vertices");
    mesh.face_offsets = std::move(offsets);
    mesh.face_nodes = std::move(nodes);
    return;
  }
  const auto n = in.integer<Index>("face count", 0, Index{1} << 40);
  in.expect("(");
  mesh.face_offsets.assign(1, 0);
  mesh.face_offsets.reserve(static_cast<std::size_t>(n) + 1);
  mesh.face_nodes.reserve(static_cast<std::size_t>(4 * n));
  for (Index f = 0; f < n; ++f) {
    const auto k = in.integer<Index>("a face's vertex count", 3, 1 << 20);
    in.expect("(");
    for (Index j = 0; j < k; ++j) mesh.face_nodes.push_back(in.integer<Index>("a face vertex", 0, std::numeric_limits<Index>::max()));
    in.expect(")");
    mesh.face_offsets.push_back(static_cast<Index>(mesh.face_nodes.size()));
  }
  in.expect(")");
}

/// Reads the boundary dictionary list: "N ( name { type T; nFaces N; startFace S; ... } ... )".
[[nodiscard]] inline std::vector<PolyMesh::Patch> read_foam_boundary(const std::filesystem::path& file) {
  const std::string text = read_foam_file(file);
  FoamCursor in(text, file);
  (void)read_foam_header(in);
  const auto n = in.integer<Index>("patch count", 0, 1 << 20);
  in.expect("(");
  std::vector<PolyMesh::Patch> patches;
  for (Index p = 0; p < n; ++p) {
    PolyMesh::Patch patch;
    patch.name = std::string(in.token("a patch name"));
    in.expect("{");
    bool have_faces = false, have_start = false;
    for (;;) {
      const std::string key(in.token("a patch entry or '}'"));
      if (key == "}") break;
      if (key == "nFaces") {
        patch.size = in.integer<Index>("nFaces", 0, std::numeric_limits<Index>::max());
        have_faces = true;
        in.expect(";");
      } else if (key == "startFace") {
        patch.start = in.integer<Index>("startFace", 0, std::numeric_limits<Index>::max());
        have_start = true;
        in.expect(";");
      } else {
        int depth = 0;
        std::string value;
        for (std::string_view t = in.token("';'"); depth > 0 || t != ";"; t = in.token("';'")) {
          if (t == "(" || t == "{") ++depth;
          if (t == ")" || t == "}") --depth;
          if (key == "type") value += std::string(t);
        }
        if (key == "type") patch.type = value;
      }
    }
    if (!have_faces || !have_start) in.fail("patch '" + patch.name + "' lacks " + (have_faces ? "startFace" : "nFaces"));
    patches.push_back(std::move(patch));
  }
  in.expect(")");
  return patches;
}

/// The faces of a cell that may be a standard element: at most six, of three or four
/// vertices, each turned outward. Fixed storage: to_mesh() fills one per cell.
struct SmallCell {
  std::array<std::array<Index, 4>, 6> faces{};
  std::array<int, 6> sizes{};
  int count = 0;

  /// Adds face `v` (reversed when `flip`); false when the cell can no longer be standard.
  bool add(std::span<const Index> v, bool flip) {
    if (count == 6 || v.size() < 3 || v.size() > 4) return false;
    auto& f = faces[static_cast<std::size_t>(count)];
    for (std::size_t k = 0; k < v.size(); ++k) f[k] = flip ? v[v.size() - 1 - k] : v[k];
    sizes[static_cast<std::size_t>(count++)] = static_cast<int>(v.size());
    return true;
  }
};

/// A cell as one of the catalogue's linear types, from its faces turned outward; false when
/// the cell is not a tetrahedron, pyramid, prism or hexahedron.
[[nodiscard]] inline bool match_cell(const SmallCell& cell, ElementType& type, std::array<Index, 8>& nodes) {
  int tris = 0, quads = 0;
  std::array<Index, 24> all{};
  std::size_t n_all = 0;
  for (int i = 0; i < cell.count; ++i) {
    (cell.sizes[static_cast<std::size_t>(i)] == 3 ? tris : quads) += 1;
    for (int k = 0; k < cell.sizes[static_cast<std::size_t>(i)]; ++k) all[n_all++] = cell.faces[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)];
  }
  std::sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n_all));
  const auto num_vertices_of_cell = static_cast<std::size_t>(std::unique(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(n_all)) - all.begin());
  const auto face = [&](int i) { return std::span<const Index>(cell.faces[static_cast<std::size_t>(i)].data(), static_cast<std::size_t>(cell.sizes[static_cast<std::size_t>(i)])); };
  const auto first_with = [&](int size) {
    for (int i = 0; i < cell.count; ++i)
      if (cell.sizes[static_cast<std::size_t>(i)] == size) return face(i);
    return face(0);
  };
  // For each vertex of `base`, the vertex joined to it by an edge of the cell and not on
  // `base`, in one pass over the edges; -1 where there is none or more than one.
  const auto up = [&](std::span<const Index> base, std::array<Index, 4>& tops) {
    tops.fill(-2);
    const auto on_base = [&](Index v) {
      for (std::size_t k = 0; k < base.size(); ++k)
        if (base[k] == v) return static_cast<int>(k);
      return -1;
    };
    const auto link = [&](int k, Index other) {
      Index& t = tops[static_cast<std::size_t>(k)];
      t = t == -2 || t == other ? other : -1;
    };
    for (int i = 0; i < cell.count; ++i) {
      const auto f = face(i);
      for (std::size_t k = 0; k < f.size(); ++k) {
        const Index a = f[k], b = f[(k + 1) % f.size()];
        const int ka = on_base(a), kb = on_base(b);
        if (ka >= 0 && kb < 0) link(ka, b);
        if (kb >= 0 && ka < 0) link(kb, a);
      }
    }
  };
  std::array<Index, 4> tops{};
  if (tris == 4 && quads == 0 && num_vertices_of_cell == 4) {
    const auto b = face(0);  // outward (a, b, c) is our facet (0, 2, 1)
    up(b, tops);
    nodes = {b[0], b[2], b[1], tops[0], 0, 0, 0, 0};
    type = ElementType::tet4;
  } else if (tris == 0 && quads == 6 && num_vertices_of_cell == 8) {
    const auto b = face(0);  // outward (a, b, c, d) is our facet (0, 3, 2, 1)
    up(b, tops);
    nodes = {b[0], b[3], b[2], b[1], tops[0], tops[3], tops[2], tops[1]};
    type = ElementType::hex8;
  } else if (tris == 2 && quads == 3 && num_vertices_of_cell == 6) {
    const auto b = first_with(3);  // outward (a, b, c) is our facet (0, 2, 1)
    up(b, tops);
    nodes = {b[0], b[2], b[1], tops[0], tops[2], tops[1], 0, 0};
    type = ElementType::prism6;
  } else if (tris == 4 && quads == 1 && num_vertices_of_cell == 5) {
    const auto b = first_with(4);  // outward (a, b, c, d) is our facet (0, 3, 2, 1)
    Index apex = -1;
    for (std::size_t k = 0; k < num_vertices_of_cell; ++k)
      if (std::find(b.begin(), b.end(), all[k]) == b.end()) apex = all[k];
    nodes = {b[0], b[3], b[2], b[1], apex, 0, 0, 0};
    type = ElementType::pyramid5;
  } else {
    return false;
  }
  for (int k = 0; k < num_vertices(type); ++k)
    if (nodes[static_cast<std::size_t>(k)] < 0) return false;
  return true;
}

}  // namespace detail

/// Reads an OpenFOAM polyMesh from a case folder (its constant/polyMesh) or a polyMesh folder.
/// Throws IoError for a missing file, ParseError for malformed content (file and line or byte
/// offset), InputError for lists that do not fit together (naming the list and the entry).
[[nodiscard]] inline PolyMesh read_polymesh(const std::filesystem::path& path) {
  const std::filesystem::path dir = detail::polymesh_folder(path);
  if (dir.empty())
    throw IoError(path.string() + ": not an OpenFOAM case or polyMesh folder (no constant/polyMesh/faces nor faces in it)");
  PolyMesh mesh;
  mesh.points = detail::read_foam_points(dir / "points");
  detail::read_foam_faces(dir / "faces", mesh);
  {
    const std::string text = detail::read_foam_file(dir / "owner");
    detail::FoamCursor in(text, dir / "owner");
    const auto h = detail::read_foam_header(in);
    mesh.owner = detail::read_label_list(in, h, "owner");
  }
  {
    const std::string text = detail::read_foam_file(dir / "neighbour");
    detail::FoamCursor in(text, dir / "neighbour");
    const auto h = detail::read_foam_header(in);
    mesh.neighbour = detail::read_label_list(in, h, "neighbour");
  }
  mesh.patches = detail::read_foam_boundary(dir / "boundary");

  const Index nf = mesh.num_faces(), np = mesh.points.cols();
  const auto fail = [&](const std::string& file, const std::string& what) { throw InputError((dir / file).string() + ": " + what); };
  for (Index f = 0; f < nf; ++f)
    for (const Index v : mesh.face(f))
      if (v < 0 || v >= np)
        fail("faces", "face " + std::to_string(f) + " has vertex " + std::to_string(v) + " (the mesh has " + std::to_string(np) +
                          " points, numbered from 0)");
  if (static_cast<Index>(mesh.owner.size()) != nf)
    fail("owner", "the owner list has " + std::to_string(mesh.owner.size()) + " entries for " + std::to_string(nf) + " faces");
  if (static_cast<Index>(mesh.neighbour.size()) > nf)
    fail("neighbour", "the neighbour list has " + std::to_string(mesh.neighbour.size()) + " entries for " + std::to_string(nf) + " faces");
  Index cells = 0;
  for (const Index c : mesh.owner) cells = std::max(cells, c + 1);
  for (const Index c : mesh.neighbour) cells = std::max(cells, c + 1);
  for (std::size_t f = 0; f < mesh.owner.size(); ++f)
    if (mesh.owner[f] < 0) fail("owner", "face " + std::to_string(f) + " has owner " + std::to_string(mesh.owner[f]));
  for (std::size_t f = 0; f < mesh.neighbour.size(); ++f)
    if (mesh.neighbour[f] < 0 || mesh.neighbour[f] == mesh.owner[f])
      fail("neighbour", "internal face " + std::to_string(f) + " has neighbour " + std::to_string(mesh.neighbour[f]) + " (owner " +
                            std::to_string(mesh.owner[f]) + ")");
  mesh.num_cells = cells;
  Index next = mesh.num_internal_faces();
  for (const auto& p : mesh.patches) {
    if (p.start != next || p.start + p.size > nf)
      fail("boundary", "patch '" + p.name + "' covers faces " + std::to_string(p.start) + ".." + std::to_string(p.start + p.size - 1) +
                           " (expected to start at face " + std::to_string(next) + " of " + std::to_string(nf) + ")");
    next = p.start + p.size;
  }
  if (next != nf)
    fail("boundary", "the patches end at face " + std::to_string(next) + " (the boundary faces run to " + std::to_string(nf) + ")");
  return mesh;
}

/// The Mesh<3> of a polyMesh: its cells as tetrahedra, pyramids, prisms and hexahedra when
/// they all are, else every cell cut into tetrahedra around auxiliary centre nodes; patches as
/// facet groups. See the file comment.
[[nodiscard]] inline Mesh<3> to_mesh(const PolyMesh& poly) {
  const Index nc = poly.num_cells, nf = poly.num_faces(), np = poly.points.cols();
  // Cell -> faces (CSR), each face oriented out of the cell.
  std::vector<Index> start(static_cast<std::size_t>(nc) + 1, 0);
  for (Index f = 0; f < nf; ++f) {
    ++start[static_cast<std::size_t>(poly.owner[static_cast<std::size_t>(f)]) + 1];
    if (f < poly.num_internal_faces()) ++start[static_cast<std::size_t>(poly.neighbour[static_cast<std::size_t>(f)]) + 1];
  }
  for (std::size_t c = 0; c < static_cast<std::size_t>(nc); ++c) start[c + 1] += start[c];
  std::vector<Index> cell_faces(static_cast<std::size_t>(start.back()));  // face index, negative-1 when reversed
  {
    std::vector<Index> fill(start.begin(), start.end() - 1);
    for (Index f = 0; f < nf; ++f) {
      cell_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(poly.owner[static_cast<std::size_t>(f)])]++)] = f;
      if (f < poly.num_internal_faces())
        cell_faces[static_cast<std::size_t>(fill[static_cast<std::size_t>(poly.neighbour[static_cast<std::size_t>(f)])]++)] = -f - 1;
    }
  }
  const auto outward = [&](Index entry) {
    const Index f = entry >= 0 ? entry : -entry - 1;
    const auto v = poly.face(f);
    std::vector<Index> out(v.begin(), v.end());
    if (entry < 0) std::reverse(out.begin(), out.end());
    return out;
  };

  Mesh<3> mesh;
  mesh.points = poly.points;
  std::vector<ElementType> types(static_cast<std::size_t>(nc));
  std::vector<std::array<Index, 8>> matched(static_cast<std::size_t>(nc));
  bool all_matched = true;
  for (Index c = 0; c < nc && all_matched; ++c) {
    detail::SmallCell cell;
    for (Index k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1] && all_matched; ++k) {
      const Index entry = cell_faces[static_cast<std::size_t>(k)];
      all_matched = cell.add(poly.face(entry >= 0 ? entry : -entry - 1), entry < 0);
    }
    all_matched = all_matched && cell.count > 0 &&
                  detail::match_cell(cell, types[static_cast<std::size_t>(c)], matched[static_cast<std::size_t>(c)]);
  }
  for (std::size_t p = 0; p < poly.patches.size(); ++p) mesh.groups.push_back({2, static_cast<int>(p) + 1, poly.patches[p].name});
  const auto patch_tag = [&](Index f) {
    for (std::size_t p = 0; p < poly.patches.size(); ++p)
      if (f >= poly.patches[p].start && f < poly.patches[p].start + poly.patches[p].size) return static_cast<int>(p) + 1;
    return 0;
  };

  if (all_matched) {
    for (Index c = 0; c < nc; ++c) {
      ElementBlock& b = mesh.block(types[static_cast<std::size_t>(c)]);
      b.add(std::span<const Index>(matched[static_cast<std::size_t>(c)].data(), static_cast<std::size_t>(num_nodes(b.type))));
      b.ids.push_back(c + 1);
    }
    for (Index f = poly.num_internal_faces(); f < nf; ++f) {
      const auto v = poly.face(f);
      ElementBlock& b = mesh.block(v.size() == 3 ? ElementType::tri3 : ElementType::quad4);
      b.add(v, patch_tag(f));
      b.ids.push_back(nc + f + 1);
    }
    return mesh;
  }

  // Tetrahedra around each cell's centre; faces of more than three vertices around theirs.
  std::vector<Index> face_centre(static_cast<std::size_t>(nf), -1);
  std::vector<Vec<3>> extra;
  for (Index f = 0; f < nf; ++f) {
    const auto v = poly.face(f);
    if (v.size() == 3) continue;
    Vec<3> sum = Vec<3>::Zero();
    for (const Index i : v) sum += poly.points.col(i);
    face_centre[static_cast<std::size_t>(f)] = np + static_cast<Index>(extra.size());
    extra.push_back(sum / static_cast<double>(v.size()));
  }
  ElementBlock& tets = mesh.block(ElementType::tet4);
  for (Index c = 0; c < nc; ++c) {
    std::vector<Index> vertices;
    for (Index k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1]; ++k) {
      const Index entry = cell_faces[static_cast<std::size_t>(k)];
      const auto v = poly.face(entry >= 0 ? entry : -entry - 1);
      vertices.insert(vertices.end(), v.begin(), v.end());
    }
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());
    Vec<3> sum = Vec<3>::Zero();
    for (const Index i : vertices) sum += poly.points.col(i);
    const Index centre = np + static_cast<Index>(extra.size());
    extra.push_back(sum / static_cast<double>(vertices.size()));
    for (Index k = start[static_cast<std::size_t>(c)]; k < start[static_cast<std::size_t>(c) + 1]; ++k) {
      const Index entry = cell_faces[static_cast<std::size_t>(k)];
      const std::vector<Index> f = outward(entry);
      if (f.size() == 3) {
        tets.add({f[0], f[2], f[1], centre});  // outward (a, b, c) is our facet (0, 2, 1)
        continue;
      }
      const Index fc = face_centre[static_cast<std::size_t>(entry >= 0 ? entry : -entry - 1)];
      for (std::size_t i = 0; i < f.size(); ++i) tets.add({fc, f[(i + 1) % f.size()], f[i], centre});
    }
  }
  for (Index f = poly.num_internal_faces(); f < nf; ++f) {
    const auto v = poly.face(f);
    ElementBlock& tris = mesh.block(ElementType::tri3);
    if (v.size() == 3) {
      tris.add(v, patch_tag(f));
      continue;
    }
    for (std::size_t i = 0; i < v.size(); ++i) tris.add({face_centre[static_cast<std::size_t>(f)], v[i], v[(i + 1) % v.size()]}, patch_tag(f));
  }
  mesh.points.conservativeResize(3, np + static_cast<Index>(extra.size()));
  for (std::size_t k = 0; k < extra.size(); ++k) mesh.points.col(np + static_cast<Index>(k)) = extra[k];
  mesh.num_auxiliary_nodes = static_cast<Index>(extra.size());
  return mesh;
}

/// The polyMesh of a linear 3D mesh: its nodes as points, its cells as cells (same order), each
/// face once, oriented out of its owner (the lower-numbered cell), internal faces in upper
/// triangular order, then one patch per facet group holding the boundary faces its facets
/// cover (named after the group, type `patch`), and `defaultFaces` for boundary faces no
/// facet covers. Throws InputError for quadratic elements or a face shared by three cells.
[[nodiscard]] inline PolyMesh to_polymesh(const Mesh<3>& mesh) {
  validate(mesh);
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (order(b.type) > 1) throw InputError("to_polymesh: OpenFOAM meshes are linear (the mesh has " + std::string(name(b.type)) + ")");
  const FacetTopology topo = unique_facets(mesh);
  PolyMesh poly;
  poly.points = mesh.points;
  poly.num_cells = mesh.num_cells();
  // Boundary faces by facet group: the tag of the facet element on each face.
  const auto key_of = [](std::span<const Index> v) {
    std::array<Index, 4> k{-1, -1, -1, -1};
    const std::size_t n = std::min<std::size_t>(v.size(), 4);
    for (std::size_t i = 0; i < n; ++i) {  // insertion sort of at most 4 vertices
      std::size_t j = i;
      for (; j > 0 && k[j - 1] > v[i]; --j) k[j] = k[j - 1];
      k[j] = v[i];
    }
    return k;
  };
  struct KeyHash {
    std::size_t operator()(const std::array<Index, 4>& k) const noexcept {
      std::size_t h = 0;
      for (const Index v : k) h = h * 0x9E3779B97F4A7C15ull + static_cast<std::size_t>(v);
      return h;
    }
  };
  std::unordered_map<std::array<Index, 4>, int, KeyHash> tag_of_face;
  for (const auto& b : mesh.facets)
    for (Index e = 0; e < b.size(); ++e) tag_of_face.emplace(key_of(b.element(e).first(static_cast<std::size_t>(num_vertices(b.type)))), b.tags[static_cast<std::size_t>(e)]);
  std::vector<int> tags;  // patch order: the named facet groups, then other tags, then 0
  for (const auto& g : mesh.groups)
    if (g.dim == 2 && std::find(tags.begin(), tags.end(), g.tag) == tags.end()) tags.push_back(g.tag);

  struct Face {
    Index owner, neighbour;  // neighbour -1 on the boundary
    int patch;
    Index facet;
    bool flip;
  };
  std::vector<Face> faces;
  faces.reserve(topo.vertices.size());
  for (Index f = 0; f < topo.size(); ++f) {
    const auto& e = topo.elements[static_cast<std::size_t>(f)];
    if (topo.count[static_cast<std::size_t>(f)] == 2) {
      faces.push_back({std::min(e[0], e[1]), std::max(e[0], e[1]), -1, f, e[0] > e[1]});
      continue;
    }
    const auto v = std::span<const Index>(topo.vertices[static_cast<std::size_t>(f)].data(), static_cast<std::size_t>(topo.num_vertices[static_cast<std::size_t>(f)]));
    const auto it = tag_of_face.find(key_of(v));
    const int tag = it == tag_of_face.end() ? 0 : it->second;
    auto at = std::find(tags.begin(), tags.end(), tag);
    if (at == tags.end()) at = tags.insert(tags.end(), tag);
    faces.push_back({e[0], -1, static_cast<int>(at - tags.begin()), f, false});
  }
  // Tag 0 (no group) last, as defaultFaces.
  if (const auto zero = std::find(tags.begin(), tags.end(), 0); zero != tags.end()) {
    const int old = static_cast<int>(zero - tags.begin());
    tags.erase(zero);
    tags.push_back(0);
    for (Face& f : faces)
      if (f.patch >= 0) f.patch = f.patch == old ? static_cast<int>(tags.size()) - 1 : f.patch > old ? f.patch - 1 : f.patch;
  }
  std::sort(faces.begin(), faces.end(), [](const Face& a, const Face& b) {
    if ((a.patch < 0) != (b.patch < 0)) return a.patch < 0;
    if (a.patch != b.patch) return a.patch < b.patch;
    return a.owner != b.owner ? a.owner < b.owner : a.neighbour < b.neighbour;
  });
  poly.face_nodes.reserve(4 * faces.size());
  for (const Face& f : faces) {
    const auto& v = topo.vertices[static_cast<std::size_t>(f.facet)];
    const int n = topo.num_vertices[static_cast<std::size_t>(f.facet)];
    for (int k = 0; k < n; ++k) poly.face_nodes.push_back(v[static_cast<std::size_t>(f.flip ? n - 1 - k : k)]);
    poly.face_offsets.push_back(static_cast<Index>(poly.face_nodes.size()));
    poly.owner.push_back(f.owner);
    if (f.patch < 0) poly.neighbour.push_back(f.neighbour);
  }
  Index start = poly.num_internal_faces();
  for (std::size_t p = 0; p < tags.size(); ++p) {
    const Index size = static_cast<Index>(std::count_if(faces.begin(), faces.end(), [&](const Face& f) { return f.patch == static_cast<int>(p); }));
    std::string patch_name = tags[p] == 0 ? "defaultFaces" : "tag_" + std::to_string(tags[p]);
    for (const auto& g : mesh.groups)
      if (g.dim == 2 && g.tag == tags[p]) patch_name = g.name;
    poly.patches.push_back({patch_name, "patch", start, size});
    start += size;
  }
  return poly;
}

/// Reads an OpenFOAM case or polyMesh folder as a Mesh<3> (read_polymesh, then to_mesh).
[[nodiscard]] inline Mesh<3> read_openfoam(const std::filesystem::path& path) {
  Mesh<3> mesh = to_mesh(read_polymesh(path));
  validate(mesh);
  return mesh;
}

namespace detail {

/// Where write_polymesh_points() writes for `target` (see the file comment), and the points
/// file whose header and node count it follows; empty when `target` is no OpenFOAM folder.
struct FoamPointsTarget {
  std::filesystem::path points;     ///< the file to write (without .gz)
  std::filesystem::path reference;  ///< the case's existing points file (without .gz)
};

[[nodiscard]] inline FoamPointsTarget foam_points_target(const std::filesystem::path& target) {
  std::filesystem::path dir = polymesh_folder(target);
  if (!dir.empty()) return {dir / "points", dir / "points"};
  // A time folder of a case: "<case>/<number>".
  const std::filesystem::path case_dir = target.has_filename() ? target.parent_path() : target.parent_path().parent_path();
  const std::string time = (target.has_filename() ? target : target.parent_path()).filename().string();
  double t = 0;
  const auto [ptr, ec] = std::from_chars(time.data(), time.data() + time.size(), t);
  const std::filesystem::path constant = polymesh_folder(case_dir.empty() ? std::filesystem::path(".") : case_dir);
  if (ec == std::errc() && ptr == time.data() + time.size() && !constant.empty())
    return {(case_dir.empty() ? std::filesystem::path(".") : case_dir) / time / "polyMesh" / "points", constant / "points"};
  return {};
}

}  // namespace detail

/// Whether write_mesh() treats `path` as an OpenFOAM output whose points it replaces (a case,
/// polyMesh or time folder).
[[nodiscard]] inline bool is_openfoam_target(const std::filesystem::path& path) {
  return !detail::foam_points_target(path).points.empty();
}

/// Whether write_mesh() writes a whole new OpenFOAM case at `path`: a path without extension
/// that does not exist or is an empty folder.
[[nodiscard]] inline bool is_new_openfoam_case(const std::filesystem::path& path) {
  std::error_code ec;
  if (path.empty() || !path.extension().empty() || is_openfoam_target(path)) return false;
  if (!std::filesystem::exists(path, ec)) return true;
  return std::filesystem::is_directory(path, ec) && std::filesystem::is_empty(path, ec);
}

/// Replaces the points of the OpenFOAM case at `target` by the mesh's nodes (those before the
/// auxiliary ones), atomically, with the case's header, format and compression. Throws
/// InputError when `target` is not an OpenFOAM folder, when the mesh has high-order elements or
/// a node count other than the case's, IoError when writing fails.
inline void write_polymesh_points(const std::filesystem::path& target, const Mesh<3>& mesh) {
  validate(mesh);
  const detail::FoamPointsTarget where = detail::foam_points_target(target);
  if (where.points.empty())
    throw InputError(target.string() + ": not an OpenFOAM case, polyMesh folder or time folder of a case (nowhere to write points)");
  for (const auto* list : {&mesh.cells, &mesh.facets})
    for (const auto& b : *list)
      if (order(b.type) > 1) throw InputError(target.string() + ": OpenFOAM meshes are linear (the mesh has " + std::string(name(b.type)) + ")");
  const Index n = mesh.num_nodes() - mesh.num_auxiliary_nodes;
  const bool compressed = detail::foam_file_is_compressed(where.reference);
  const std::string reference_text = detail::read_foam_file(where.reference);
  detail::FoamCursor in(reference_text, where.reference);
  const detail::FoamHeader h = detail::read_foam_header(in);
  const auto expected = in.integer<Index>("point count", 0, Index{1} << 40);
  if (n != expected)
    throw InputError(target.string() + ": the mesh has " + std::to_string(n) + " points, the case " + std::to_string(expected) +
                     " (" + where.reference.string() + "): not this case's mesh");
  std::string header(reference_text.substr(0, h.data_offset));
  if (where.points != where.reference) {
    // A time folder: the header's location names it.
    const std::size_t at = header.find("location");
    if (at != std::string::npos) {
      const std::size_t end = header.find(';', at);
      const std::string time = where.points.parent_path().parent_path().filename().string();
      header.replace(at, end - at, "location    \"" + time + "/polyMesh\"");
    }
  }
  std::string out = header;
  detail::append_foam_points(out, mesh.points.leftCols(n), h);
  out += "\n\n// ************************************************************************* //\n";
  std::error_code ec;
  std::filesystem::create_directories(where.points.parent_path(), ec);
  if (ec) throw IoError(where.points.parent_path().string() + ": cannot create the folder (" + ec.message() + ")");
  detail::write_foam_file(where.points, out, compressed);
}

/// Options of write_polymesh().
struct PolyMeshWriteOptions {
  bool binary = false;      ///< binary lists (faces as faceCompactList), else ASCII
  bool compressed = false;  ///< gzip every file (needs zlib)
};

/// Writes a whole polyMesh (points, faces, owner, neighbour, boundary) into `case_dir`'s
/// constant/polyMesh, each file through a temporary file and a rename. The faces must be
/// ordered as OpenFOAM requires (internal faces first, then each patch's); InputError otherwise.
inline void write_polymesh(const std::filesystem::path& case_dir, const PolyMesh& mesh, const PolyMeshWriteOptions& options = {}) {
  const Index nf = mesh.num_faces();
  if (static_cast<Index>(mesh.owner.size()) != nf || mesh.num_internal_faces() > nf)
    throw InputError("write_polymesh: " + std::to_string(mesh.owner.size()) + " owners and " + std::to_string(mesh.neighbour.size()) +
                     " neighbours for " + std::to_string(nf) + " faces");
  Index next = mesh.num_internal_faces();
  for (const auto& p : mesh.patches) {
    if (p.start != next) throw InputError("write_polymesh: patch '" + p.name + "' starts at face " + std::to_string(p.start) +
                                          " (expected " + std::to_string(next) + ")");
    next += p.size;
  }
  if (next != nf) throw InputError("write_polymesh: the patches end at face " + std::to_string(next) + " of " + std::to_string(nf));
  for (const auto& p : mesh.patches)
    if (p.name.empty() || p.name.find_first_of(" \t\n\"';{}()/\\") != std::string::npos)
      throw InputError("write_polymesh: patch name '" + p.name + "' is not an OpenFOAM word (no blanks, quotes, ;, braces, parentheses or slashes)");
#ifndef MESHMOTION_HAVE_ZLIB
  if (options.compressed) throw InputError("write_polymesh: compressed files need zlib (meshmotion was built without it)");
#endif
  const std::filesystem::path dir = case_dir / "constant" / "polyMesh";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError(dir.string() + ": cannot create the folder (" + ec.message() + ")");
  detail::FoamHeader h;
  h.binary = options.binary;
  h.label_bytes = 4;
  if (mesh.points.cols() > std::numeric_limits<std::int32_t>::max() || static_cast<Index>(mesh.face_nodes.size()) > std::numeric_limits<std::int32_t>::max())
    h.label_bytes = 8;
  const auto header = [&](const char* cls, const char* object, bool binary) {
    return std::string("FoamFile\n{\n    version     2.0;\n    format      ") + (binary ? "binary" : "ascii") +
           ";\n    arch        \"LSB;label=" + std::to_string(8 * h.label_bytes) + ";scalar=64\";\n    class       " + cls +
           ";\n    location    \"constant/polyMesh\";\n    object      " + object + ";\n}\n";
  };
  const auto end = std::string("\n\n// ************************************************************************* //\n");
  const auto labels = [&](std::string& out, std::span<const Index> v) {
    out += "\n";
    detail::append_number(out, static_cast<Index>(v.size()));
    out += "\n(";
    if (h.binary) {
      for (const Index x : v) {
        if (h.label_bytes == 4) {
          const auto i = static_cast<std::int32_t>(x);
          out.append(reinterpret_cast<const char*>(&i), 4);
        } else {
          const auto i = static_cast<std::int64_t>(x);
          out.append(reinterpret_cast<const char*>(&i), 8);
        }
      }
      out += ")\n";
    } else {
      out += '\n';
      for (const Index x : v) {
        detail::append_number(out, x);
        out += '\n';
      }
      out += ")\n";
    }
  };
  std::string points = header("vectorField", "points", h.binary);
  detail::append_foam_points(points, mesh.points, h);
  detail::write_foam_file(dir / "points", points + end, options.compressed);

  std::string faces = header(h.binary ? "faceCompactList" : "faceList", "faces", h.binary);
  if (h.binary) {
    labels(faces, mesh.face_offsets);
    labels(faces, mesh.face_nodes);
  } else {
    faces += "\n";
    detail::append_number(faces, nf);
    faces += "\n(\n";
    for (Index f = 0; f < nf; ++f) {
      const auto v = mesh.face(f);
      detail::append_number(faces, static_cast<Index>(v.size()));
      faces += '(';
      for (std::size_t k = 0; k < v.size(); ++k) {
        if (k > 0) faces += ' ';
        detail::append_number(faces, v[k]);
      }
      faces += ")\n";
    }
    faces += ")\n";
  }
  detail::write_foam_file(dir / "faces", faces + end, options.compressed);
  std::string owner = header("labelList", "owner", h.binary);
  labels(owner, mesh.owner);
  detail::write_foam_file(dir / "owner", owner + end, options.compressed);
  std::string neighbour = header("labelList", "neighbour", h.binary);
  labels(neighbour, mesh.neighbour);
  detail::write_foam_file(dir / "neighbour", neighbour + end, options.compressed);
  std::string boundary = header("polyBoundaryMesh", "boundary", false) + "\n" + std::to_string(mesh.patches.size()) + "\n(\n";
  for (const auto& p : mesh.patches)
    boundary += "    " + p.name + "\n    {\n        type            " + (p.type.empty() ? std::string("patch") : p.type) +
                ";\n        nFaces          " + std::to_string(p.size) + ";\n        startFace       " + std::to_string(p.start) +
                ";\n    }\n";
  detail::write_foam_file(dir / "boundary", boundary + ")\n" + end, options.compressed);
}

}  // namespace meshmotion
