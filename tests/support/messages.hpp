#pragma once
// The message of an expected exception, for tests that check what an error says.

#include <string>

namespace meshmotion::test {

/// The message of the E that f throws ("(no exception)" when none; other types propagate).
template <class E, class F>
std::string message_of(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace meshmotion::test
