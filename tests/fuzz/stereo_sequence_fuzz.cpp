// libFuzzer target: the stereo sequence reader (vision/stereo_sequence.hpp). One input holds
// calib.yaml, then after a line "%%" the names of the left images and after another "%%" those of the
// right images, one per line (each becomes a small valid PNG of the calibration's size, 32x24, or an
// empty directory when the name ends in "/"). A malformed sequence must give a sextant::error;
// anything else escaping, a crash or a hang is a finding.
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>

#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/vision/stereo_sequence.hpp"

namespace {


std::string_view next_part(std::string_view& rest) {
  const auto separator = rest.find("%%\n");
  const std::string_view part = rest.substr(0, separator);
  rest = separator == std::string_view::npos ? std::string_view() : rest.substr(separator + 3);
  return part;
}

/// The side's entries, at most 4, names of printable characters without '/' except a trailing one (a
/// directory); the harness writes only what a file system and OpenCV's writer take.
void write_side(const std::filesystem::path& side, std::string_view names) {
  std::filesystem::create_directories(side);  // the input directory is ours: this cannot fail but for the disk
  static const cv::Mat image(24, 32, CV_8UC1, cv::Scalar(128));
  std::istringstream lines{std::string(names)};
  int count = 0;
  for (std::string name; std::getline(lines, name) && count < 4; ++count) {
    const bool folder = !name.empty() && name.back() == '/';
    if (folder) name.pop_back();
    const bool printable = std::all_of(name.begin(), name.end(), [](char c) { return c > 0x20 && c < 0x7f; });
    if (!printable || name.empty() || name.size() > 64 || name.find('/') != std::string::npos || name == "." ||
        name == "..")
      continue;
    const auto file = side / name;
    std::error_code ignored;  // a name given twice, as a file and as a directory: the first stays
    if (folder)
      std::filesystem::create_directories(file, ignored);
    else if (file.extension() == ".png" && !std::filesystem::exists(file, ignored))
      cv::imwrite(file.string(), image);
    else if (!std::filesystem::exists(file, ignored))
      std::ofstream(file) << name;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const sextant::fuzz::InputDirectory dir("stereo");
  const std::filesystem::path root(dir.path());
  for (const char* side : {"left", "right"}) std::filesystem::remove_all(root / side);
  std::filesystem::remove_all(root / "calib.yaml");
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  std::ofstream(root / "calib.yaml", std::ios::binary) << next_part(rest);
  write_side(root / "left", next_part(rest));
  write_side(root / "right", next_part(rest));
  try {
    const sextant::vision::StereoSequence sequence(root);
    for (std::size_t k = 0; k < sequence.size(); ++k) (void)sequence.load(k);
  } catch (const sextant::error&) {
  }
  return 0;
}
