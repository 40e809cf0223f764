#pragma once
/// \file A minimal CSV writer: a header, then rows of numbers, with full double precision.

#include <fstream>
#include <initializer_list>
#include <iomanip>
#include <limits>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"

namespace sextant::io {

class CsvWriter {
 public:
  /// Opens `path` for writing and writes the header; throws sextant::error if it cannot.
  CsvWriter(const std::string& path, const std::vector<std::string>& columns) : out_(path), columns_(columns.size()) {
    if (!out_) throw error("cannot open " + path + " for writing");
    out_ << std::setprecision(std::numeric_limits<double>::max_digits10);
    write_line(columns);
  }

  /// Writes one row; it must have as many values as there are columns.
  void row(std::initializer_list<double> values) { row(std::vector<double>(values)); }
  void row(const std::vector<double>& values) {
    if (values.size() != columns_) throw invalid_input_error("CSV row has " + std::to_string(values.size()) +
                                                             " values, expected " + std::to_string(columns_));
    write_line(values);
  }

 private:
  template <class T>
  void write_line(const std::vector<T>& values) {
    for (std::size_t i = 0; i < values.size(); ++i) out_ << (i ? "," : "") << values[i];
    out_ << '\n';
  }

  std::ofstream out_;
  std::size_t columns_;
};

}  // namespace sextant::io
