#pragma once
/// \file The message of an MRPT exception, for sextant's own error texts.

#include <algorithm>
#include <optional>
#include <string>

namespace sextant::mrpt_io {

/// One line of an exception's text: MRPT's start with a "==== MRPT exception ====" banner, then
/// the message (after "Message:" in some versions, "Line 2: Expected closing ..." in others), then
/// a call stack; the first line that is neither banner nor stack is the one worth showing.
inline std::string exception_message(const std::string& text) {
  std::size_t start = 0;
  while (start < text.size()) {
    const auto end = std::min(text.find('\n', start), text.size());
    std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.rfind("Message:", 0) == 0) line.erase(0, 8);
    const auto first = line.find_first_not_of(" \t");
    line = first == std::string::npos ? std::string() : line.substr(first);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.rfind("Call stack", 0) == 0) break;
    if (line.empty() || line.rfind("====", 0) == 0) continue;
    return line;
  }
  return "unreadable data";
}

/// The class named by MRPT's error for an object of a class it does not know ("Stored object has
/// class 'X' which is not registered!"): a log of other sensors (a rotating scan, an image), not a
/// damaged one. nullopt for any other error.
inline std::optional<std::string> unreadable_class(const std::string& message) {
  const std::string before = "Stored object has class '", after = "' which is not registered";
  const auto open = message.find(before);
  if (open == std::string::npos) return std::nullopt;
  const auto first = open + before.size(), close = message.find(after, first);
  if (close == std::string::npos) return std::nullopt;
  return message.substr(first, close - first);
}

}  // namespace sextant::mrpt_io
