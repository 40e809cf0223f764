#pragma once
/// \file One rule for numbers in text files and settings: the whole token must be a finite number.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>

namespace sextant::io {

/// The token as a double if all of it is one finite number; nullopt for an empty token, trailing
/// characters, NaN, Inf or a value out of range.
inline std::optional<double> parse_finite_number(const std::string& token) {
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(token, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != token.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

/// Up to `length` characters of `text` with every byte that is not printable ASCII shown as \xHH,
/// so that no message echoes raw bytes of a binary or corrupt file.
inline std::string printable_excerpt(const std::string& text, std::size_t length = 40) {
  std::string out;
  for (std::size_t i = 0; i < text.size() && i < length; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  return text.size() > length ? out + "..." : out;
}

/// The largest magnitude a number in a data file may have: 1e12 (time stamps in seconds since 1970
/// are 1.7e9, coordinates in metres, noise values). A finite value beyond it (1e308) would overflow
/// in the first product an estimator forms, far from the file and line it came from; the readers
/// refuse it there (data_number_error).
inline constexpr double kMaxDataMagnitude = 1e12;

/// The message for a token that is not a number a data file may hold, or an empty string when it is one.
inline std::string data_number_error(const std::string& token, const std::optional<double>& value) {
  if (!value) return "'" + printable_excerpt(token) + "' is not a finite number";
  if (std::abs(*value) > kMaxDataMagnitude) return "'" + token + "' is beyond +-1e12, the largest magnitude sextant reads";
  return {};
}

/// A number read from text as an identifier: a non-negative integer that a double holds exactly
/// (below 2^53); nullopt otherwise (negative, fractional, 1e30: casting those would truncate or be
/// undefined behaviour).
inline std::optional<std::uint64_t> as_identifier(double value) {
  constexpr double kExactLimit = 9007199254740992.0;  // 2^53
  if (!(value >= 0.0) || !(value < kExactLimit) || value != std::floor(value)) return std::nullopt;
  return static_cast<std::uint64_t>(value);
}

}  // namespace sextant::io
