// libFuzzer target: the UTIAS MRCLAM reader. One input holds the five files of a robot's run, in
// the order below, separated by lines "%%"; a missing part is an empty file. A malformed data set
// must give a sextant::error; anything else escaping is a finding.
#include <unistd.h>

#include <array>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/io/mrclam_reader.hpp"

namespace {

constexpr std::array<const char*, 5> kFiles = {"Barcodes.dat", "Landmark_Groundtruth.dat", "Robot1_Odometry.dat",
                                               "Robot1_Measurement.dat", "Robot1_Groundtruth.dat"};


}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const sextant::fuzz::InputDirectory dir("mrclam");
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  for (const char* name : kFiles) {
    const auto separator = rest.find("%%\n");
    const std::string_view part = rest.substr(0, separator);
    rest = separator == std::string_view::npos ? std::string_view() : rest.substr(separator + 3);
    std::ofstream(dir.path() + "/" + name, std::ios::binary) << part;
  }
  try {
    (void)sextant::io::read_mrclam(dir.path(), 1);
  } catch (const sextant::error&) {
  }
  return 0;
}
