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
#include <utility>
#include <vector>

#if defined(__linux__)
#include <fcntl.h>  // AT_FDCWD
#include <stdio.h>  // renameat2, RENAME_EXCHANGE (glibc 2.28, _GNU_SOURCE)
#endif

namespace meshmotion::detail {

/// ".tmp<stamp>_<counter>": what names a temporary file, new at each call.
[[nodiscard]] inline std::string temporary_suffix() {
  static std::atomic<unsigned> counter{0};
  const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
  return ".tmp" + std::to_string(stamp % 1000000007) + "_" + std::to_string(counter++);
}

/// A name for the temporary file beside `file` (same folder, so rename is atomic).
[[nodiscard]] inline std::filesystem::path temporary_path_for(const std::filesystem::path& file) {
  std::filesystem::path tmp = file;
  tmp += temporary_suffix();
  return tmp;
}

/// A temporary name beside `file` that keeps its extension ("out.tmp<stamp>_<counter>.msh"),
/// for writers that choose the format by it.
[[nodiscard]] inline std::filesystem::path temporary_path_keeping_extension(const std::filesystem::path& file) {
  return file.parent_path() / (file.stem().string() + temporary_suffix() + file.extension().string());
}

/// Moves the complete temporary file `tmp` onto `file`; removes `tmp` and throws IoError when
/// the rename fails.
///
/// An existing regular file is exchanged with `tmp` (renameat2's RENAME_EXCHANGE, atomic like a
/// rename) and then removed: ext4 writes a file renamed over another out to disk before the
/// rename returns (its auto_da_alloc heuristic for programs that never fsync), 15-25 ms for the
/// 30P30N's 17 MB .msh, which a loop writing one output again and again paid every time. The
/// output is as durable as a file written in place; neither way syncs it.
inline void rename_into_place(const std::filesystem::path& tmp, const std::filesystem::path& file) {
#if defined(__linux__) && defined(RENAME_EXCHANGE)
  std::error_code status_error;
  if (std::filesystem::symlink_status(file, status_error).type() == std::filesystem::file_type::regular &&
      ::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, file.c_str(), RENAME_EXCHANGE) == 0) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);  // the former file, now under the temporary name
    return;
  }
  // A file system without the exchange (EINVAL) or a file just removed takes the plain rename.
#endif
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw IoError(file.string() + ": cannot rename the temporary file into place (" + ec.message() + ")");
  }
}

/// Removes what a killed run left of its temporaries for `file` (the names of
/// temporary_path_for() and temporary_path_keeping_extension(), files or folders) once they are
/// an hour old: a run still writing one is younger.
inline void remove_stale_temporaries(const std::filesystem::path& file) {
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  const auto old = std::filesystem::file_time_type::clock::now() - std::chrono::hours(1);
  // "<prefix><stamp>_<counter><suffix>", digits only between: nothing else of this name is ours.
  const auto ours = [](std::string_view name, const std::string& prefix, const std::string& suffix) {
    if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) || !name.ends_with(suffix)) return false;
    const std::string_view tail = name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
    const std::size_t cut = tail.find('_');
    const auto digits = [](std::string_view t) { return !t.empty() && t.find_first_not_of("0123456789") == std::string_view::npos; };
    return cut != std::string_view::npos && digits(tail.substr(0, cut)) && digits(tail.substr(cut + 1));
  };
  const std::string whole = file.filename().string() + ".tmp", stem = file.stem().string() + ".tmp", extension = file.extension().string();
  std::error_code ec;
  for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (!ours(name, whole, "") && !(!extension.empty() && ours(name, stem, extension))) continue;
    std::error_code ignored;
    if (std::filesystem::last_write_time(it->path(), ignored) < old && !ignored) std::filesystem::remove_all(it->path(), ignored);
  }
}

/// Has `write(tmp)` write a whole file at a temporary path beside `file`, then renames it onto
/// `file`; when `write` throws, the temporary is removed and `file` is left as it was. Stale
/// temporaries of `file` from killed runs are removed first.
template <class Write>
void write_through_temporary(const std::filesystem::path& file, Write&& write) {
  remove_stale_temporaries(file);
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

/// The outputs of one run, written as a set: each is written whole at a temporary path beside
/// it that keeps its extension (the writers choose the format by it), and commit() renames
/// them all into place. Outputs not committed — a later one failed, the disk filled — are
/// removed, so a run that fails leaves none of its outputs and every old file as it was.
/// (The renames themselves, in one folder, do not fail short of the folder vanishing.)
class OutputSet {
 public:
  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet() { discard(); }

  /// Has `write(path)` write the file `file` at a temporary path beside it; errors name `file`.
  template <class Write>
  void stage(const std::filesystem::path& file, Write&& write) {
    remove_stale_temporaries(file);
    const std::filesystem::path tmp = temporary_path_keeping_extension(file);
    staged_.emplace_back(tmp, file);
    try {
      write(tmp);
    } catch (const IoError& e) {
      std::string what = e.message();
      for (std::size_t at = what.find(tmp.string()); at != std::string::npos; at = what.find(tmp.string(), at + file.string().size()))
        what.replace(at, tmp.string().size(), file.string());
      throw IoError(what);
    }
  }
  /// Renames every staged output into place (rename_into_place()).
  void commit() {
    for (auto& [tmp, file] : staged_) rename_into_place(tmp, file);
    staged_.clear();
  }

 private:
  void discard() noexcept {
    for (const auto& staged : staged_) {
      std::error_code ignored;
      std::filesystem::remove(staged.first, ignored);
    }
    staged_.clear();
  }

  std::vector<std::pair<std::filesystem::path, std::filesystem::path>> staged_;  ///< (temporary, output)
};

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
