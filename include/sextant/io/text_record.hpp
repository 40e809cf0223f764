#pragma once
/// \file One line of a record-per-line text format (iSAM, g2o, TORO): a tag and finite numbers,
/// with where it is (file:line) for every message about it. '#' starts a comment line.

#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/io/parse_number.hpp"

namespace sextant::io::detail {

struct TextRecord {
  std::string where, tag;
  std::vector<double> values;

  /// A value as an identifier; parse_error otherwise.
  std::uint64_t identifier(std::size_t index, const char* what) const {
    const auto id = as_identifier(values[index]);
    if (!id)
      throw parse_error(where + ": " + what + " must be a non-negative integer below 2^53, got " +
                        std::to_string(values[index]));
    return *id;
  }
  void require_fields(std::size_t count) const {
    if (values.size() != count)
      throw parse_error(where + ": " + tag + " needs " + std::to_string(count) + " values, found " +
                        std::to_string(values.size()));
  }
};

/// The record on `line`; nullopt for a blank line or a comment. Throws parse_error naming `where`
/// for a value that is not a finite number within the data-file range (parse_number.hpp).
inline std::optional<TextRecord> parse_text_record(const std::string& line, std::string where) {
  std::istringstream fields(line);
  TextRecord record{std::move(where), {}, {}};
  if (!(fields >> record.tag) || record.tag[0] == '#') return std::nullopt;
  for (std::string word; fields >> word;) {
    const auto value = parse_finite_number(word);
    if (const auto error = data_number_error(word, value); !error.empty()) throw parse_error(record.where + ": " + error);
    record.values.push_back(*value);
  }
  return record;
}

}  // namespace sextant::io::detail
