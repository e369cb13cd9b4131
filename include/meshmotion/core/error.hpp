#pragma once
/// \file
/// The exception hierarchy: every error the library raises derives from meshmotion::Error.
/// Messages read "where: what is wrong (got ..., expected ...)".

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace meshmotion {

/// Root of all exceptions thrown by meshmotion.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error("meshmotion: " + what) {}
  /// what() without its "meshmotion: " prefix: for an error that passes the message on.
  [[nodiscard]] std::string message() const { return std::string(what()).substr(12); }
};

/// Invalid argument or invalid mesh data given by the caller: out-of-range index, NaN
/// coordinate, duplicate boundary node, inconsistent sizes.
class InputError : public Error {
 public:
  using Error::Error;
};

/// Failure to open, read or write a file (not a format error: see ParseError).
class IoError : public Error {
 public:
  using Error::Error;
};

/// Malformed file content. Carries the file and the line (ASCII) or byte offset (binary).
class ParseError : public InputError {
 public:
  enum class Position { line, byte_offset };

  ParseError(std::filesystem::path file, std::uint64_t position, const std::string& what,
             Position kind = Position::line)
      : InputError(file.string() + (kind == Position::line ? ":" : ": byte ") +
                   std::to_string(position) + ": " + what),
        file_(std::move(file)),
        position_(position),
        kind_(kind) {}

  [[nodiscard]] const std::filesystem::path& file() const noexcept { return file_; }
  /// Line number (1-based) or byte offset, as position_kind() says.
  [[nodiscard]] std::uint64_t position() const noexcept { return position_; }
  [[nodiscard]] Position position_kind() const noexcept { return kind_; }

 private:
  std::filesystem::path file_;
  std::uint64_t position_;
  Position kind_;
};

/// A linear or nonlinear solver failed or did not converge.
class SolverError : public Error {
 public:
  using Error::Error;
};

/// The mesh is geometrically invalid where validity is required (inverted elements in
/// strict mode, a Delaunay graph that folded over).
class InvalidMeshError : public Error {
 public:
  using Error::Error;
};

}  // namespace meshmotion
