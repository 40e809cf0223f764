#pragma once
// Runs a program through the shell and captures its exit code, stdout and stderr (the runner tests).
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

namespace sextant::test {

struct ProgramResult {
  int exit_code;
  std::string out, err;
};

/// `command_line` with stdout and stderr sent to files in `dir`, read back.
inline ProgramResult run_program(const std::string& command_line, const std::filesystem::path& dir) {
  const auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  const std::string command = command_line + " >" + out.string() + " 2>" + err.string();
  const int status = std::system(command.c_str());
  auto slurp = [](const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

}  // namespace sextant::test
