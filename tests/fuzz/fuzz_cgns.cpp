// libFuzzer target for the CGNS reader. The CGNS library opens files by name, so each input
// is written to a scratch file and read from there: any input must read or raise
// meshmotion::Error. HDF5 is not instrumented; what the sanitizers watch is our reader.
#include "meshmotion/io/cgns_reader.hpp"

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("meshmotion_fuzz_" + std::to_string(getpid()) + ".cgns");
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  try {
    (void)meshmotion::read_cgns(file);
  } catch (const meshmotion::Error&) {
  }
  return 0;
}
