// libFuzzer target: sextant-run's ini settings (MRPT CConfigFile underneath, our key table on top).
#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant_run/runner_config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sextant::fuzz::InputFile file(".ini");
  const std::string& path = file.write(data, size);
  try {
    (void)sextant::runner::load_config(path);
  } catch (const sextant::error&) {
  }
  return 0;
}
