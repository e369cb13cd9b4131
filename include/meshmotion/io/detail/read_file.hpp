#pragma once
/// \file
/// Whole-file reading into memory: readers parse from a buffer, never token by token from a stream.

#include "meshmotion/core/error.hpp"

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace meshmotion::detail {

/// The whole content of `file`; throws IoError when it cannot be read.
[[nodiscard]] inline std::string read_whole_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw IoError(file.string() + ": cannot read (is a directory)");
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(file.string() + ": cannot open for reading (missing or unreadable)");
  const auto size = in.tellg();
  if (size < 0) throw IoError(file.string() + ": cannot determine the file size");
  std::string data(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  if (!in.read(data.data(), size)) throw IoError(file.string() + ": read failed");
  return data;
}

}  // namespace meshmotion::detail
