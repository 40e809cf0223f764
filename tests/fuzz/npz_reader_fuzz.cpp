// libFuzzer target: the .npz reader (libzip underneath, our .npy parser and the visual-inertial
// data set checks on top). A malformed file must give a sextant::error; anything else escaping is
// a finding. Seeds: small .npz files made at run time (cmake/fuzz.sh).
#include "../support/bounded_new.hpp"
#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/io/visual_inertial_npz.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sextant::fuzz::InputFile file(".npz");
  const std::string& path = file.write(data, size);
  try {
    (void)sextant::io::read_visual_inertial_npz(path);
  } catch (const sextant::error&) {
  }
  return 0;
}
