#pragma once
/// \file NumPy's .npy format (versions 1.0-3.0): the magic, a little-endian header length, a Python
/// dict literal {'descr': '<f8', 'fortran_order': False, 'shape': (3, 1010), } and the raw data.
/// Arrays of little-endian float64, float32, int64 and int32 are read into doubles in C
/// (row-major) order, Fortran-ordered ones reordered. Anything else, a header that does not parse,
/// or data shorter than the shape says is a parse_error naming the array.

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant::io {

/// An n-dimensional array of doubles in C order.
struct NpyArray {
  std::vector<std::size_t> shape;  ///< empty for a scalar
  std::vector<double> values;

  std::size_t dimensions() const { return shape.size(); }
  /// The value at a C-order multi-index (no bounds check beyond the debug assertion of vector).
  double at(std::initializer_list<std::size_t> index) const {
    std::size_t flat = 0, k = 0;
    for (const std::size_t i : index) flat = flat * shape[k++] + i;
    return values[flat];
  }
};

/// Reads `n` bytes into `dst`, returns how many it read (fewer at the end of the data).
using NpyByteReader = std::function<std::size_t(void* dst, std::size_t n)>;

namespace detail {

struct NpyHeader {
  char kind = 0;            ///< 'f' or 'i'
  std::size_t item_size = 0;
  bool fortran_order = false;
  std::vector<std::size_t> shape;
};

/// The text after `'key':` in the header dict, leading spaces skipped; npos when the key is absent.
inline std::size_t npy_value_of(const std::string& header, const std::string& key) {
  const auto at = header.find("'" + key + "'");
  if (at == std::string::npos) return std::string::npos;
  auto colon = header.find(':', at);
  if (colon == std::string::npos) return std::string::npos;
  ++colon;
  while (colon < header.size() && header[colon] == ' ') ++colon;
  return colon;
}

inline NpyHeader parse_npy_header(const std::string& header, const std::string& what) {
  const auto bad = [&](const std::string& problem) { return parse_error(what + ": " + problem + " in the .npy header '" + header + "'"); };
  NpyHeader out;
  // descr: '<f8', '|f8' (byte order irrelevant or little), '<i4', ...
  auto at = npy_value_of(header, "descr");
  if (at == std::string::npos || at >= header.size() || header[at] != '\'') throw bad("no 'descr'");
  const auto end = header.find('\'', at + 1);
  if (end == std::string::npos) throw bad("unterminated 'descr'");
  const std::string descr = header.substr(at + 1, end - at - 1);
  if (descr.size() < 3 || (descr[0] != '<' && descr[0] != '|') || (descr[1] != 'f' && descr[1] != 'i') ||
      (descr.substr(2) != "8" && descr.substr(2) != "4"))
    throw parse_error(what + ": dtype '" + descr +
                      "' is not supported (little-endian float64, float32, int64 or int32 are)");
  out.kind = descr[1];
  out.item_size = descr[2] == '8' ? 8 : 4;
  // fortran_order: True or False
  at = npy_value_of(header, "fortran_order");
  if (at == std::string::npos) throw bad("no 'fortran_order'");
  if (header.compare(at, 4, "True") == 0)
    out.fortran_order = true;
  else if (header.compare(at, 5, "False") != 0)
    throw bad("'fortran_order' is neither True nor False");
  // shape: (), (5,), (4, 5105, 1010)
  at = npy_value_of(header, "shape");
  if (at == std::string::npos || at >= header.size() || header[at] != '(') throw bad("no 'shape' tuple");
  const auto close = header.find(')', at);
  if (close == std::string::npos) throw bad("unterminated 'shape'");
  std::size_t i = at + 1;
  while (i < close) {
    while (i < close && (header[i] == ' ' || header[i] == ',')) ++i;
    if (i == close) break;
    std::size_t value = 0;
    const std::size_t digits_start = i;
    while (i < close && header[i] >= '0' && header[i] <= '9') {
      const std::size_t digit = static_cast<std::size_t>(header[i] - '0');
      if (value > (std::numeric_limits<std::size_t>::max() - digit) / 10) throw bad("a dimension too large");
      value = value * 10 + digit;
      ++i;
    }
    if (i == digits_start) throw bad("a dimension that is not a non-negative integer");
    out.shape.push_back(value);
  }
  if (out.shape.size() > 8) throw bad("more than 8 dimensions");
  return out;
}

/// Element count of a shape, or a parse_error when it overflows `limit` elements.
inline std::size_t npy_element_count(const std::vector<std::size_t>& shape, std::size_t limit, const std::string& what) {
  std::size_t count = 1;
  for (const std::size_t d : shape) {
    if (d != 0 && count > limit / d) throw parse_error(what + ": the array's shape holds more than " + std::to_string(limit) + " values");
    count *= d;
  }
  return count;
}

/// C-order values from data stored with the first index fastest.
inline std::vector<double> from_fortran_order(const std::vector<double>& f, const std::vector<std::size_t>& shape) {
  std::vector<double> c(f.size());
  const std::size_t n = shape.size();
  std::vector<std::size_t> index(n, 0);
  for (std::size_t flat = 0; flat < c.size(); ++flat) {
    std::size_t offset = 0, stride = 1;
    for (std::size_t k = 0; k < n; ++k) {
      offset += index[k] * stride;
      stride *= shape[k];
    }
    c[flat] = f[offset];
    for (std::size_t k = n; k-- > 0;) {  // C order: the last index runs fastest
      if (++index[k] < shape[k]) break;
      index[k] = 0;
    }
  }
  return c;
}

template <class T>
void convert_items(const std::vector<char>& raw, std::vector<double>& out) {
  for (std::size_t i = 0; i < out.size(); ++i) {
    T item;
    std::memcpy(&item, raw.data() + i * sizeof(T), sizeof(T));
    out[i] = static_cast<double>(item);
  }
}

}  // namespace detail

/// Reads one .npy array through `read`. `what` names it in errors ("FILE: key 'K'"). `stream_size`,
/// the bytes the source holds when known, lets a shape larger than the data fail before anything is
/// allocated for it; `max_values` bounds the array in any case (a corrupt shape must not ask for
/// terabytes).
inline NpyArray read_npy(const NpyByteReader& read, const std::string& what,
                         std::size_t stream_size = std::numeric_limits<std::size_t>::max(),
                         std::size_t max_values = std::size_t{1} << 31) {
  std::array<char, 8> preamble{};
  if (read(preamble.data(), 8) != 8 || std::memcmp(preamble.data(), "\x93NUMPY", 6) != 0)
    throw parse_error(what + ": not a .npy array (no \\x93NUMPY magic)");
  const int major = static_cast<unsigned char>(preamble[6]);
  if (major < 1 || major > 3) throw parse_error(what + ": .npy version " + std::to_string(major) + " is not supported");
  std::size_t header_length = 0;
  std::array<unsigned char, 4> length_bytes{};
  const std::size_t length_size = major == 1 ? 2 : 4;
  if (read(length_bytes.data(), length_size) != length_size) throw parse_error(what + ": truncated .npy header");
  for (std::size_t i = length_size; i-- > 0;) header_length = header_length * 256 + length_bytes[i];
  if (header_length > 65536) throw parse_error(what + ": .npy header of " + std::to_string(header_length) + " bytes");
  std::string header(header_length, '\0');
  if (read(header.data(), header_length) != header_length) throw parse_error(what + ": truncated .npy header");
  while (!header.empty() && (header.back() == '\n' || header.back() == ' ')) header.pop_back();
  const auto h = detail::parse_npy_header(header, what);

  NpyArray out;
  out.shape = h.shape;
  const std::size_t count = detail::npy_element_count(h.shape, max_values, what);
  const std::size_t bytes = count * h.item_size;
  const std::size_t consumed = 8 + length_size + header_length;
  if (stream_size != std::numeric_limits<std::size_t>::max() && (stream_size < consumed || bytes > stream_size - consumed))
    throw parse_error(what + ": truncated .npy data (the shape says " + std::to_string(count) + " values, " +
                      std::to_string(bytes) + " bytes; " + std::to_string(stream_size - std::min(stream_size, consumed)) +
                      " follow the header)");
  out.values.resize(count);
  if (h.kind == 'f' && h.item_size == 8) {  // the common case: straight into place
    if (read(out.values.data(), bytes) != bytes)
      throw parse_error(what + ": truncated .npy data (the shape says " + std::to_string(count) + " values)");
  } else {
    std::vector<char> raw(bytes);
    if (read(raw.data(), bytes) != bytes)
      throw parse_error(what + ": truncated .npy data (the shape says " + std::to_string(count) + " values)");
    if (h.kind == 'f')
      detail::convert_items<float>(raw, out.values);
    else if (h.item_size == 8)
      detail::convert_items<std::int64_t>(raw, out.values);
    else
      detail::convert_items<std::int32_t>(raw, out.values);
  }
  if (h.fortran_order && h.shape.size() > 1) out.values = detail::from_fortran_order(out.values, h.shape);
  return out;
}

/// Reads a .npy array held in memory.
inline NpyArray read_npy(const std::string& bytes, const std::string& what) {
  std::size_t position = 0;
  return read_npy(
      [&](void* dst, std::size_t n) {
        const std::size_t take = std::min(n, bytes.size() - position);
        std::memcpy(dst, bytes.data() + position, take);
        position += take;
        return take;
      },
      what, bytes.size());
}

}  // namespace sextant::io
