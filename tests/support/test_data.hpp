#pragma once
// Access to the real CFD meshes in ../shared/data, which a user's clone may not have.

#include <catch2/catch.hpp>

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

namespace meshmotion::test {

/// Path of a file in the shared data folder (MESHMOTION_DATA_DIR overrides the configured one),
/// or nullopt when the file is absent.
inline std::optional<std::filesystem::path> shared_data(const std::string& name) {
  std::filesystem::path dir = MESHMOTION_SHARED_DATA_DIR;
  if (const char* env = std::getenv("MESHMOTION_DATA_DIR")) dir = env;
  auto path = dir / name;
  if (!std::filesystem::exists(path)) return std::nullopt;
  return path;
}

/// A fresh path in the build tree's scratch folder for files a test writes.
inline std::filesystem::path scratch_path(const std::string& name) {
  return std::filesystem::path(MESHMOTION_TEST_TMP_DIR) / name;
}

}  // namespace meshmotion::test

/// Skips the rest of the test, with a message, when a shared data file is absent.
#define MESHMOTION_REQUIRE_DATA(var, name)                                           \
  const auto var##_opt = ::meshmotion::test::shared_data(name);                      \
  if (!var##_opt) {                                                                  \
    WARN("skipped: " << (name) << " not found (../shared/data is absent here)");     \
    return;                                                                          \
  }                                                                                  \
  const std::filesystem::path var = *var##_opt
