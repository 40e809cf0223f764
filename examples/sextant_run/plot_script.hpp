#pragma once
// Runs one of the runner's Python plot scripts (installed next to the executable) on an output
// directory.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <sextant/core/error.hpp>

namespace sextant::runner {

/// Runs `script` (a file next to this executable) with the output directory and `arguments`;
/// throws naming the directory and the package to install when it fails.
inline void run_plot_script(const std::string& script, const std::filesystem::path& dir, const std::string& arguments = "") {
  const auto path = std::filesystem::canonical("/proc/self/exe").parent_path() / script;
  // Debian's interpreter (where python3-matplotlib installs) before whatever python3 is first on PATH.
  const std::string python = std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
  const std::string command = python + " '" + path.string() + "' '" + dir.string() + "' " + arguments;
  if (std::system(command.c_str()) != 0)
    throw error(dir.string() + ": plotting failed (needs python3 with matplotlib: Debian python3-matplotlib)");
  std::printf("wrote plots (PNG) to %s\n", dir.c_str());
}

}  // namespace sextant::runner
