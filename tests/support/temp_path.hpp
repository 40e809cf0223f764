#pragma once
// A temporary file name unique to this process, so that two test runs on one machine never share
// a file.
#include <filesystem>
#include <string>
#include <unistd.h>

namespace sextant::test {

inline std::filesystem::path unique_temp_path(const std::string& name) {
  return std::filesystem::temp_directory_path() / ("sextant_" + std::to_string(::getpid()) + "_" + name);
}

}  // namespace sextant::test
