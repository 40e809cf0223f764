#pragma once
// Where the external data sets live (../shared/data beside the project), and a skip when absent.
#include <filesystem>
#include <string>

namespace sextant::test {

inline std::string shared_data(const std::string& relative) {
  return (std::filesystem::path(SEXTANT_SHARED_DATA_DIR) / relative).string();
}

}  // namespace sextant::test

/// Skips the test with a message when the file is not there (a fresh clone has no ../shared/data).
#define SEXTANT_REQUIRE_DATA(path)                                                                 \
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "data set not found: " << (path)             \
                                                   << " (tests that need ../shared/data skip without it)"
