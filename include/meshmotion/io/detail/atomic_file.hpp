#pragma once
/// \file
/// Atomic writing: a temporary file in the same folder, then a rename, so a failed write never
/// leaves a partial output nor touches an existing file.

#include "meshmotion/core/error.hpp"

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <system_error>

namespace meshmotion::detail {

/// A name for the temporary file beside `file` (same folder, so rename is atomic).
[[nodiscard]] inline std::filesystem::path temporary_path_for(const std::filesystem::path& file) {
  static std::atomic<unsigned> counter{0};
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  std::filesystem::path tmp = file;
  tmp += ".tmp" + std::to_string(stamp % 1000000007) + "_" + std::to_string(counter++);
  return tmp;
}

/// Moves the complete temporary file `tmp` onto `file`; removes `tmp` and throws IoError when
/// the rename fails.
inline void rename_into_place(const std::filesystem::path& tmp, const std::filesystem::path& file) {
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw IoError(file.string() + ": cannot rename the temporary file into place (" + ec.message() + ")");
  }
}

/// Has `write(tmp)` write a whole file at a temporary path beside `file`, then renames it onto
/// `file`; when `write` throws, the temporary is removed and `file` is left as it was.
template <class Write>
void write_through_temporary(const std::filesystem::path& file, Write&& write) {
  const std::filesystem::path tmp = temporary_path_for(file);
  try {
    write(tmp);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  }
  rename_into_place(tmp, file);
}

/// Has `write(std::ofstream&)` write `file`'s content into a temporary file beside it, then
/// renames it into place. Throws IoError (leaving neither `file` changed nor the temporary
/// behind) when the file cannot be created or written.
template <class Write>
void write_file_through_stream(const std::filesystem::path& file, Write&& write) {
  write_through_temporary(file, [&](const std::filesystem::path& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw IoError(file.string() + ": cannot create the temporary file " + tmp.string());
    write(out);
    out.close();
    if (!out) throw IoError(file.string() + ": write failed (disk full?)");
  });
}

/// Writes `contents` to `file` through a temporary file in the same folder and a rename.
/// Throws IoError (leaving neither `file` changed nor the temporary behind) on failure.
inline void write_file_atomically(const std::filesystem::path& file, std::string_view contents) {
  write_file_through_stream(file, [&](std::ofstream& out) { out.write(contents.data(), static_cast<std::streamsize>(contents.size())); });
}

/// A file's text produced in pieces: kept whole in `text` (the format_*() functions), or written
/// to a file every `chunk` bytes (the write_*() functions, through write_streamed()). Built
/// whole, a 17 MB file cost 17 MB of fresh pages, each faulted in and zeroed by the kernel
/// before being copied to the page cache (on a virtual machine the larger part of writing it);
/// streamed, the same megabyte is reused.
class TextOutput {
 public:
  static constexpr std::size_t chunk = std::size_t{1} << 20;

  TextOutput() = default;
  explicit TextOutput(std::ofstream& file) : file_(&file) { text.reserve(chunk + chunk / 2); }

  std::string text;

  /// Writes out what is buffered once it reaches `chunk` bytes (nothing when kept in memory).
  /// Producers call it between pieces shorter than chunk / 2, so `text` never grows.
  void spill() {
    if (file_ != nullptr && text.size() >= chunk) flush();
  }
  void flush() {
    if (file_ == nullptr) return;
    file_->write(text.data(), static_cast<std::streamsize>(text.size()));
    text.clear();
  }

 private:
  std::ofstream* file_ = nullptr;
};

/// Writes `file` through a temporary and a rename, `produce(TextOutput&)` producing its text.
template <class Produce>
void write_streamed(const std::filesystem::path& file, Produce&& produce) {
  write_file_through_stream(file, [&](std::ofstream& out) {
    TextOutput text(out);
    produce(text);
    text.flush();
  });
}

}  // namespace meshmotion::detail
