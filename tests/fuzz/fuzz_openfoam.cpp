// libFuzzer target for the OpenFOAM reader: an input is a whole polyMesh in one buffer, its
// files (points, faces, owner, neighbour, boundary, in that order) separated by lines
// "#next". They are written into a scratch folder and read back: any input must read or
// raise meshmotion::Error. An input that starts with a line "#gz" is written compressed
// (points.gz, ...), which takes the reader through its bounded decompression.
#include "meshmotion/io/openfoam_reader.hpp"

#include <unistd.h>

#ifdef MESHMOTION_HAVE_ZLIB
#include <zlib.h>
#endif

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("meshmotion_fuzz_openfoam_" + std::to_string(getpid()));
  static const bool made = std::filesystem::create_directories(dir);
  (void)made;
  static constexpr std::array<const char*, 5> files{"points", "faces", "owner", "neighbour", "boundary"};
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  const bool compressed = rest.starts_with("#gz\n");
  if (compressed) rest.remove_prefix(4);
  for (const char* name : files) {
    const std::size_t cut = rest.find("\n#next\n");
    const std::string_view text = rest.substr(0, cut);
    std::filesystem::remove(dir / name);
    std::filesystem::remove(dir / (std::string(name) + ".gz"));
#ifdef MESHMOTION_HAVE_ZLIB
    if (compressed) {
      gzFile out = gzopen((dir / (std::string(name) + ".gz")).c_str(), "wb1");
      if (out != nullptr) {
        if (!text.empty()) (void)gzwrite(out, text.data(), static_cast<unsigned>(text.size()));
        gzclose(out);
      }
    } else
#endif
    {
      std::ofstream(dir / name, std::ios::binary | std::ios::trunc) << text;
    }
    rest = cut == std::string_view::npos ? std::string_view{} : rest.substr(cut + 7);
  }
  try {
    (void)meshmotion::read_openfoam(dir);
  } catch (const meshmotion::Error&) {
  }
  return 0;
}
