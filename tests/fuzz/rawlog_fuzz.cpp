// libFuzzer target: our code around MRPT's rawlog deserializer: reading the objects, telling a
// planar from a spatial log, converting actions and observations into steps (read_rawlog).
// MRPT's own deserializer is not instrumented; what it throws must come out as a sextant::error.
#include "../support/bounded_mrpt_alloc.hpp"
#include "fuzz_input_file.hpp"
#include "sextant/core/error.hpp"
#include "sextant/mrpt/rawlog.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static sextant::fuzz::InputFile file(".rawlog");
  const std::string& path = file.write(data, size);
  try {
    (void)sextant::mrpt_io::read_rawlog(path);
  } catch (const sextant::error&) {
  }
  return 0;
}
