#pragma once
/// \file Opening an input file with a message that says what is wrong with the path: a directory
/// where a file is expected, a missing file, one the process may not read (the operating system's
/// reason). Every text reader opens its files through it.

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

#include "sextant/core/error.hpp"

namespace sextant::io {

/// Throws parse_error "path: is a directory, not a file" or "path: cannot open file (reason)".
inline void require_input_file(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw parse_error(path + ": is a directory, not a file");
  if (!std::filesystem::exists(path, ec)) throw parse_error(path + ": cannot open file (no such file)");
}

inline std::ifstream open_input_file(const std::string& path, std::ios::openmode mode = std::ios::in) {
  require_input_file(path);
  std::ifstream in(path, mode);
  if (!in) throw parse_error(path + ": cannot open file (" + std::strerror(errno) + ")");
  return in;
}

}  // namespace sextant::io
