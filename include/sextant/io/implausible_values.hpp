#pragma once
/// \file Values that are legal numbers but implausible for what they measure (a small ground robot
/// at 50 m/s, a camera that sees a landmark a kilometre away): a reader uses them as given and lists
/// them, naming file and line, so that a program can print a warning instead of silently giving an
/// odd result. The limits are the readers' documented options, well above what real data holds.

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace sextant::io {

/// The implausible values a reader found: the first few in full and how many in all.
struct ImplausibleValues {
  static constexpr std::size_t kListed = 5;
  std::vector<std::string> listed;  ///< "file:line: what v beyond the plausible limit"
  std::size_t count = 0;

  /// Records `what` at `where` when |value| > limit.
  void check(double value, double limit, const std::string& where, const char* what, const char* unit) {
    if (!(std::abs(value) > limit)) return;
    char text[160];
    std::snprintf(text, sizeof text, ": %s %.6g %s is beyond the plausible %.6g %s (used as given)", what, value, unit,
                  limit, unit);
    record(where + text);
  }

  /// Records a line that says what was found and what the reader did with it.
  void record(std::string line) {
    ++count;
    if (listed.size() < kListed) listed.push_back(std::move(line));
  }

  /// The lines a program prints: each listed value, then how many more there are.
  std::vector<std::string> warnings() const {
    std::vector<std::string> out;
    for (const auto& line : listed) out.push_back("warning: " + line);
    if (count > listed.size())
      out.push_back("warning: and " + std::to_string(count - listed.size()) + " more implausible values");
    return out;
  }
};

}  // namespace sextant::io
