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

/// The whole content of `file`; throws IoError when it cannot be read. Only regular files are
/// read: a device (/dev/zero), a pipe or a folder is refused before any byte is, so that a
/// mistyped path neither hangs nor grows without bound.
[[nodiscard]] inline std::string read_whole_file(const std::filesystem::path& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) throw IoError(file.string() + ": no such file");
  if (!std::filesystem::is_regular_file(status))
    throw IoError(file.string() + ": cannot read: not a regular file (" +
                  (std::filesystem::is_directory(status) ? "a folder" : "a device, pipe or socket") + ")");
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
