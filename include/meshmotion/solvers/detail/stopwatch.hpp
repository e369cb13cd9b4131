#pragma once
/// \file
/// Wall-clock stopwatch shared by the solvers and the movers for their reports.

#include <chrono>

namespace meshmotion::detail {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  /// Seconds since construction.
  [[nodiscard]] double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace meshmotion::detail
