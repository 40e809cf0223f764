// libFuzzer target: the iSAM/GTSAM text reader (ODOMETRY / LANDMARK and EDGE2 / POINT2 lines),
// read with covariances and with square-root information matrices, and the noise-free ground truth derived from it.
// A malformed file must give a sextant::error; anything else escaping is a finding.
#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/io/isam_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sextant::fuzz::InputFile file(".txt");
  const std::string& path = file.write(data, size);
  for (auto form : {sextant::io::IsamNoise::covariance, sextant::io::IsamNoise::square_root_information}) {
    try {
      const auto dataset = sextant::io::read_isam_2d(path, form);
      (void)sextant::io::ground_truth_from_noise_free(dataset);
    } catch (const sextant::error&) {
    }
  }
  return 0;
}
