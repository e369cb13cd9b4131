#pragma once
/// \file
/// Tables kept per element type and built on first use.

#include "meshmotion/core/element.hpp"

#include <array>
#include <cstddef>
#include <mutex>

namespace meshmotion::detail {

/// One table per element type, each built on its first use (thread-safe): a process that
/// reads P1 meshes must not pay for the tables of a hex729 (its shape basis alone is a
/// 729 × 729 inverse, a third of a second).
template <class T>
class PerTypeCache {
 public:
  template <class Make>
  const T& get(ElementType t, Make&& make) {
    const auto i = static_cast<std::size_t>(t);
    std::call_once(built_[i], [&] { tables_[i] = make(t); });
    return tables_[i];
  }

 private:
  std::array<T, num_element_types> tables_{};
  std::array<std::once_flag, num_element_types> built_{};
};

}  // namespace meshmotion::detail
