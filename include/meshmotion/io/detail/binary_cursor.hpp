#pragma once
/// \file
/// A cursor over binary data in a memory buffer: reads fixed-size values with optional byte
/// swapping and reports the byte offset of malformed or truncated data.

#include "meshmotion/core/error.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>
#include <type_traits>

namespace meshmotion::detail {

template <class T>
[[nodiscard]] T byte_swapped(T value) noexcept {
  static_assert(std::is_trivially_copyable_v<T>);
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  std::reverse(bytes, bytes + sizeof(T));
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

class BinaryCursor {
 public:
  BinaryCursor(std::string_view data, std::size_t offset, std::filesystem::path file, bool swap)
      : data_(data), pos_(offset), file_(std::move(file)), swap_(swap) {}

  [[nodiscard]] std::size_t offset() const noexcept { return pos_; }
  [[nodiscard]] bool swap() const noexcept { return swap_; }

  [[noreturn]] void fail(const std::string& what) const {
    throw ParseError(file_, pos_, what, ParseError::Position::byte_offset);
  }

  /// Fails unless `count` values of `size` bytes remain.
  void require(std::size_t count, std::size_t size, std::string_view what) const {
    const std::size_t left = data_.size() - pos_;
    if (size != 0 && count > left / size)
      fail("truncated binary data (expected " + std::to_string(count) + " " + std::string(what) + ", " +
           std::to_string(left) + " bytes left)");
  }

  template <class T>
  [[nodiscard]] T read(std::string_view what) {
    require(1, sizeof(T), what);
    T value;
    std::memcpy(&value, data_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return swap_ ? byte_swapped(value) : value;
  }

  /// Reads `count` values into `out`.
  template <class T>
  void read_array(T* out, std::size_t count, std::string_view what) {
    require(count, sizeof(T), what);
    if (count == 0) return;  // `out` may be null for an empty array
    std::memcpy(static_cast<void*>(out), data_.data() + pos_, count * sizeof(T));
    pos_ += count * sizeof(T);
    if (swap_)
      for (std::size_t i = 0; i < count; ++i) out[i] = byte_swapped(out[i]);
  }

  /// Reads an unsigned integer stored on `size` bytes (4 or 8).
  [[nodiscard]] std::uint64_t read_size(std::size_t size, std::string_view what) {
    return size == 4 ? read<std::uint32_t>(what) : read<std::uint64_t>(what);
  }

 private:
  std::string_view data_;
  std::size_t pos_;
  std::filesystem::path file_;
  bool swap_;
};

}  // namespace meshmotion::detail
