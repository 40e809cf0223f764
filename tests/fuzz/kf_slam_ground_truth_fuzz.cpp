// libFuzzer target: the kf-slam ground-truth readers (landmark maps in 2D and 3D, robot paths).
#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/io/kf_slam_ground_truth.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sextant::fuzz::InputFile file(".txt");
  const std::string& path = file.write(data, size);
  try {
    (void)sextant::io::read_kf_slam_landmarks<2>(path);
  } catch (const sextant::error&) {
  }
  try {
    (void)sextant::io::read_kf_slam_landmarks<3>(path);
  } catch (const sextant::error&) {
  }
  try {
    (void)sextant::io::planar_path(sextant::io::read_kf_slam_path(path));
  } catch (const sextant::error&) {
  }
  return 0;
}
