#pragma once
// The kf-slam demo rawlogs that Debian's mrpt-common installs; tests that need them skip without.
#include <filesystem>
#include <string>

#ifndef SEXTANT_MRPT_DATASETS_DIR
#define SEXTANT_MRPT_DATASETS_DIR "/usr/share/mrpt/datasets"
#endif

namespace sextant::testing {

inline std::string mrpt_demo(const std::string& name) { return std::string(SEXTANT_MRPT_DATASETS_DIR) + "/" + name; }

}  // namespace sextant::testing

/// Skips the test with a message when the demo rawlog is not installed.
#define SEXTANT_REQUIRE_MRPT_DEMO(name)                                                                  \
  do {                                                                                                \
    if (!std::filesystem::exists(::sextant::testing::mrpt_demo(name)))                                \
      GTEST_SKIP() << ::sextant::testing::mrpt_demo(name) << " not found (Debian package mrpt-common)"; \
  } while (false)
