#pragma once
/// \file
/// Fast text output of numbers into a string buffer with std::to_chars. Doubles are written in
/// their shortest form that reads back to the same bits, so ASCII round trips are exact.

#include <charconv>
#include <cstring>
#include <string>
#include <type_traits>

namespace meshmotion::detail {

template <class T>
void append_number(std::string& out, T value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  // (pointer, count): the (first, last) overload goes through replace(), a fifth of the time
  // of formatting a mesh's coordinates.
  out.append(buffer, static_cast<std::size_t>(result.ptr - buffer));
}

/// Appends the bytes of a trivially copyable value (native byte order) to a binary buffer.
template <class T>
void append_bytes(std::string& out, const T& value) {
  static_assert(std::is_trivially_copyable_v<T>);
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

}  // namespace meshmotion::detail
