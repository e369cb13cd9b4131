// libFuzzer target for the VTK XML reader: any input must parse or raise meshmotion::Error.
#include "meshmotion/io/vtu_reader.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)meshmotion::parse_vtu(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.vtu");
  } catch (const meshmotion::Error&) {
  }
  return 0;
}
