#pragma once
/// \file Whitespace-separated numeric text files (MRPT's ground-truth files, MRCLAM's .dat files):
/// every token a finite number, '%' and '#' lines are comments, errors name file:line.

#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/io/input_file.hpp"
#include "sextant/io/parse_number.hpp"

namespace sextant::io {

namespace detail {

/// The numeric rows of a whitespace-separated text file, each with its line number; throws
/// parse_error naming file:line for a token that is not a finite number.
inline std::vector<std::pair<int, std::vector<double>>> read_numeric_rows(const std::string& path) {
  std::ifstream in = open_input_file(path);
  std::vector<std::pair<int, std::vector<double>>> rows;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '%' || line[first] == '#') continue;
    std::istringstream fields(line);
    std::vector<double> values;
    std::string token;
    while (fields >> token) {
      const auto value = parse_finite_number(token);
      if (const auto error = data_number_error(token, value); !error.empty())
        throw parse_error(path + ":" + std::to_string(number) + ": " + error);
      values.push_back(*value);
    }
    rows.emplace_back(number, std::move(values));
  }
  return rows;
}

}  // namespace detail

}  // namespace sextant::io
