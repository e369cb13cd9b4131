#pragma once
/// \file
/// Whole-file reading into memory (readers parse from a buffer, never token by token from a
/// stream), and the extension that chooses a file's reader.

#include "meshmotion/core/error.hpp"

#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace meshmotion::detail {

/// Throws IoError naming the cause unless `file` is a regular file: missing, a symbolic link to
/// nothing, a path the system cannot follow (a loop of symbolic links), a folder, a device, a
/// pipe or a socket. Only regular files are read: a device (/dev/zero) or a pipe is refused
/// before any byte is, so that a mistyped path neither hangs nor grows without bound.
inline void check_regular_file(const std::filesystem::path& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) throw IoError(file.string() + ": cannot read: " + ec.message());
  if (!std::filesystem::exists(status)) {
    std::error_code ignored;
    if (std::filesystem::is_symlink(std::filesystem::symlink_status(file, ignored)))
      throw IoError(file.string() + ": a symbolic link to nothing (" + std::filesystem::read_symlink(file, ignored).string() + ")");
    throw IoError(file.string() + ": no such file");
  }
  if (!std::filesystem::is_regular_file(status))
    throw IoError(file.string() + ": cannot read: not a regular file (" +
                  (std::filesystem::is_directory(status) ? "a folder" : "a device, pipe or socket") + ")");
}

/// The whole content of `file`; throws IoError when it cannot be read (check_regular_file()).
[[nodiscard]] inline std::string read_whole_file(const std::filesystem::path& file) {
  check_regular_file(file);
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(file.string() + ": cannot open for reading (permission denied?)");
  const auto size = in.tellg();
  if (size < 0) throw IoError(file.string() + ": cannot determine the file size");
  std::string data(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(data.data(), size)) throw IoError(file.string() + ": read failed");
  return data;
}

/// The extension of `file` in lower case, with its dot (".msh"); empty when it has none.
[[nodiscard]] inline std::string lower_extension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace meshmotion::detail
