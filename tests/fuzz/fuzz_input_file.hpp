#pragma once
// libFuzzer hands bytes; sextant's readers take paths. One temporary file (or directory) per
// fuzzing process, rewritten for every input (unique name, removed at exit).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace sextant::fuzz {

class InputFile {
 public:
  explicit InputFile(const char* suffix) {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir && *dir ? dir : "/tmp") + "/sextant_fuzz_XXXXXX" + suffix;
    const int fd = mkstemps(path_.data(), static_cast<int>(std::string(suffix).size()));
    if (fd < 0) std::abort();
    close(fd);
  }
  ~InputFile() { std::remove(path_.c_str()); }
  /// Writes the input and returns the path to read it from.
  const std::string& write(const std::uint8_t* data, std::size_t size) {
    std::FILE* f = std::fopen(path_.c_str(), "wb");
    if (!f || std::fwrite(data, 1, size, f) != size || std::fclose(f) != 0) std::abort();
    return path_;
  }

 private:
  std::string path_;
};

/// A directory of its own for the fuzzing process, removed at exit (readers of several files).
class InputDirectory {
 public:
  explicit InputDirectory(const char* name) {
    const char* dir = std::getenv("TMPDIR");
    path_ = std::string(dir && *dir ? dir : "/tmp") + "/sextant_fuzz_" + name + "_XXXXXX";
    if (!mkdtemp(path_.data())) std::abort();
  }
  ~InputDirectory() { std::filesystem::remove_all(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace sextant::fuzz
