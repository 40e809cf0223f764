#pragma once
/// \file NumPy .npz files: a zip archive of .npy arrays, one per key (numpy.savez). Read with
/// libzip (Debian libzip-dev; the target sextant::npz); each array through io/npy.hpp. A file
/// that is not a readable zip, a missing key or a corrupt entry is a parse_error naming the file
/// and the key.

#include <zip.h>

#include <memory>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/io/input_file.hpp"
#include "sextant/io/npy.hpp"

namespace sextant::io {

class NpzFile {
 public:
  /// The largest entry array() inflates, in bytes once uncompressed (1 GiB). An entry compresses
  /// far better than that can be checked from the archive's size (a sparse feature array of the
  /// KITTI-derived files is 165 MB deflated to 1.5 MB, 100:1), so the archive's own statement of the
  /// uncompressed size is checked against this limit before a byte is inflated.
  static constexpr std::size_t kDefaultMaxEntryBytes = std::size_t{1} << 30;

  /// Opens `path`; libzip checks the archive's central directory against the file (ZIP_CHECKCONS),
  /// so a truncated file fails here.
  explicit NpzFile(std::string path, std::size_t max_entry_bytes = kDefaultMaxEntryBytes)
      : path_(std::move(path)), max_entry_bytes_(max_entry_bytes) {
    require_input_file(path_);
    int error_code = 0;
    zip_t* archive = zip_open(path_.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &error_code);
    if (!archive) {
      zip_error_t error;
      zip_error_init_with_code(&error, error_code);
      const std::string message = zip_error_strerror(&error);
      zip_error_fini(&error);
      throw parse_error(path_ + ": not a readable .npz (zip) file: " + message);
    }
    archive_.reset(archive);
  }

  const std::string& path() const { return path_; }

  /// The keys of the arrays: entry names without ".npy".
  std::vector<std::string> keys() const {
    std::vector<std::string> out;
    const zip_int64_t n = zip_get_num_entries(archive_.get(), 0);
    for (zip_int64_t i = 0; i < n; ++i) {
      const char* name = zip_get_name(archive_.get(), static_cast<zip_uint64_t>(i), 0);
      if (!name) continue;
      std::string key = name;
      if (key.size() > 4 && key.compare(key.size() - 4, 4, ".npy") == 0) out.push_back(key.substr(0, key.size() - 4));
    }
    return out;
  }

  bool contains(const std::string& key) const { return zip_name_locate(archive_.get(), (key + ".npy").c_str(), 0) >= 0; }

  /// The array stored under `key`.
  NpyArray array(const std::string& key) const {
    const std::string what = path_ + ": key '" + key + "'";
    const zip_int64_t index = zip_name_locate(archive_.get(), (key + ".npy").c_str(), 0);
    if (index < 0) throw parse_error(what + " is missing");
    zip_stat_t stat;
    zip_stat_init(&stat);
    if (zip_stat_index(archive_.get(), static_cast<zip_uint64_t>(index), 0, &stat) != 0 || !(stat.valid & ZIP_STAT_SIZE))
      throw parse_error(what + ": the entry's size is unknown: " + zip_strerror(archive_.get()));
    if (stat.size > max_entry_bytes_)
      throw parse_error(what + ": " + std::to_string(stat.size) + " bytes once uncompressed (" +
                        std::to_string(stat.comp_size) + " compressed), more than the reader's limit of " +
                        std::to_string(max_entry_bytes_) + " bytes (NpzFile::kDefaultMaxEntryBytes)");
    std::unique_ptr<zip_file_t, ZipFileCloser> file(zip_fopen_index(archive_.get(), static_cast<zip_uint64_t>(index), 0));
    if (!file) throw parse_error(what + ": cannot open the entry: " + zip_strerror(archive_.get()));
    bool failed = false;
    auto read = [&](void* dst, std::size_t n) -> std::size_t {
      std::size_t total = 0;
      while (total < n) {
        const zip_int64_t got = zip_fread(file.get(), static_cast<char*>(dst) + total, n - total);
        if (got < 0) {
          failed = true;
          break;
        }
        if (got == 0) break;
        total += static_cast<std::size_t>(got);
      }
      return total;
    };
    const auto corrupt = [&] { return parse_error(what + ": corrupt entry: " + zip_file_strerror(file.get())); };
    NpyArray out;
    try {
      out = read_npy(read, what, static_cast<std::size_t>(stat.size));
    } catch (const parse_error&) {
      if (failed) throw corrupt();
      throw;
    }
    // Reading past the end makes libzip compare the entry's CRC.
    char extra = 0;
    const zip_int64_t got = zip_fread(file.get(), &extra, 1);
    if (got < 0) throw corrupt();
    if (got > 0) throw parse_error(what + ": data after the end of the array");
    return out;
  }

 private:
  struct ZipCloser {
    void operator()(zip_t* archive) const { zip_discard(archive); }
  };
  struct ZipFileCloser {
    void operator()(zip_file_t* file) const { zip_fclose(file); }
  };
  std::string path_;
  std::unique_ptr<zip_t, ZipCloser> archive_;
  std::size_t max_entry_bytes_;
};

}  // namespace sextant::io
