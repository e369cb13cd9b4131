#pragma once
/// \file
/// The library's version (CMakeLists.txt checks that its project version agrees).

#define MESHMOTION_VERSION_MAJOR 0
#define MESHMOTION_VERSION_MINOR 2
#define MESHMOTION_VERSION_PATCH 0
#define MESHMOTION_VERSION_STRING "0.2.0"

namespace meshmotion {
/// "0.2.0": the headers' version, for a program to print beside the compiled library's.
inline constexpr const char* version_string = MESHMOTION_VERSION_STRING;
}  // namespace meshmotion
