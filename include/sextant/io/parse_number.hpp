#pragma once
/// \file One rule for numbers in text files and settings: the whole token must be a finite number.

#include <cmath>
#include <cstdint>
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

/// A number read from text as an identifier: a non-negative integer that a double holds exactly
/// (below 2^53); nullopt otherwise (negative, fractional, 1e30: casting those would truncate or be
/// undefined behaviour).
inline std::optional<std::uint64_t> as_identifier(double value) {
  constexpr double kExactLimit = 9007199254740992.0;  // 2^53
  if (!(value >= 0.0) || !(value < kExactLimit) || value != std::floor(value)) return std::nullopt;
  return static_cast<std::uint64_t>(value);
}

}  // namespace sextant::io
