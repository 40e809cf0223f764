#pragma once
/// \file One rule for numbers in text files and settings: the whole token must be a finite number.

#include <cmath>
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

}  // namespace sextant::io
