// libFuzzer target for the SU2 reader: any input must parse or raise meshmotion::Error.
#include "meshmotion/io/su2_reader.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)meshmotion::parse_su2(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.su2");
  } catch (const meshmotion::Error&) {
  }
  return 0;
}
