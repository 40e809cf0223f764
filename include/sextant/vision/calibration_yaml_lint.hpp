#pragma once
/// \file The stereo calibration file (calib.yaml) checked line by line before OpenCV's YAML parser
/// sees it: OpenCV 4.6's parser loops forever on some malformed files (a mapping indented before
/// any key, then a line indented less: found by stereo_sequence_fuzz), so the file must be the
/// plain layout that calib.yaml has (docs/runner.md) and that cv::FileStorage writes:
///   %YAML:1.0 (or %YAML 1.0), an optional ---, then
///   top-level keys at column 0:        name: value   or   name: !!opencv-matrix
///   a key's block, one indentation:      rows: 3 / cols: 3 / dt: d / data: [ ... ]
///   the rest of an open [ list:            numbers, commas and the closing ]
/// with blank lines and # comments anywhere, printable ASCII only. Anything else is a parse_error
/// naming file and line, with a printable excerpt.

#include <cctype>
#include <fstream>
#include <string>
#include <string_view>

#include "sextant/core/error.hpp"
#include "sextant/io/parse_number.hpp"

namespace sextant::vision::detail {

/// Tracks the block structure line by line (lint_calibration_yaml).
class CalibrationYamlLint {
 public:
  explicit CalibrationYamlLint(std::string file) : file_(std::move(file)) {}

  /// Checks line `number`; throws parse_error naming it.
  void check(const std::string& line, int number) {
    where_ = file_ + ":" + std::to_string(number);
    for (unsigned char ch : line)
      if (!(ch == '\t' || ch == '\r' || (ch >= 0x20 && ch < 0x7f))) fail(line, "not printable text");
    if (number == 1) return require_directive(line);
    const std::size_t indent = line.find_first_not_of(' ');
    if (indent == std::string::npos || line[indent] == '#' || line[indent] == '\r') return;  // blank or comment
    if (open_lists_ > 0) return continue_list(line, indent);
    if (indent == 0) return top_level(line);
    nested(line, indent);
  }
  /// At the end of the file: no list left open.
  void finish() const {
    if (open_lists_ > 0) throw parse_error(file_ + ": a [ list is not closed at the end of the file");
  }

 private:
  [[noreturn]] void fail(const std::string& line, const std::string& what) const {
    throw parse_error(where_ + ": " + what + " ('" + io::printable_excerpt(line) + "'); calib.yaml holds "
                      "'name: value' lines and matrix blocks as cv::FileStorage writes them");
  }
  void require_directive(const std::string& line) const {
    const std::string text = line.substr(0, line.find_last_not_of(" \r") + 1);
    if (text != "%YAML:1.0" && text != "%YAML 1.0") fail(line, "the first line must be %YAML:1.0");
  }
  /// "name:" then an optional value; returns what follows the colon.
  std::string key_value(const std::string& line, std::size_t indent) const {
    std::size_t end = indent;
    while (end < line.size() && (std::isalnum(static_cast<unsigned char>(line[end])) || line[end] == '_')) ++end;
    if (end == indent || end >= line.size() || line[end] != ':') fail(line, "expected 'name: value'");
    return line.substr(end + 1);
  }
  void count_brackets(const std::string& text) {
    for (char ch : text) open_lists_ += ch == '[' ? 1 : ch == ']' ? -1 : 0;
    if (open_lists_ < 0) throw parse_error(where_ + ": ']' without '['");
  }
  void top_level(const std::string& line) {
    if (line.rfind("---", 0) == 0 && !seen_key_) return;
    count_brackets(key_value(line, 0));
    seen_key_ = true;
    block_indent_ = 0;
  }
  void nested(const std::string& line, std::size_t indent) {
    if (!seen_key_) fail(line, "indented before any key");
    if (block_indent_ == 0) block_indent_ = indent;
    if (indent != block_indent_) fail(line, "indented unlike the lines before it in this block");
    count_brackets(key_value(line, indent));
  }
  void continue_list(const std::string& line, std::size_t indent) {
    for (std::size_t i = indent; i < line.size(); ++i)
      if (!(std::isdigit(static_cast<unsigned char>(line[i])) || std::string_view(" \t\r,.+-eE]").find(line[i]) != std::string_view::npos))
        fail(line, "a list may continue with numbers only");
    count_brackets(line);
  }

  std::string file_, where_;
  bool seen_key_ = false;
  std::size_t block_indent_ = 0;
  int open_lists_ = 0;
};

/// Throws parse_error naming file and line unless `file` has calib.yaml's plain layout (above).
inline void lint_calibration_yaml(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw parse_error(file + ": cannot open file (the stereo calibration)");
  CalibrationYamlLint lint(file);
  std::string line;
  int number = 0;
  while (std::getline(in, line)) lint.check(line, ++number);
  if (number == 0) throw parse_error(file + ": empty (the stereo calibration)");
  lint.finish();
}

}  // namespace sextant::vision::detail
