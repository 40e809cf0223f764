// libFuzzer target: a Monte Carlo study's record file (eval/study_records.hpp), read, merged as a
// study of its own and averaged as the runner averages it. A malformed file must give a
// sextant::error; anything else escaping is a finding.
#include <sstream>
#include <string>

#include "sextant/core/error.hpp"
#include "sextant/eval/study_records.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
  try {
    auto file = sextant::eval::parse_records(in, "fuzz.tsv");
    const auto merged = sextant::eval::merge_records({file});
    std::vector<sextant::eval::RunScores> scores;
    for (const auto& r : merged) scores.push_back(r.scores);
    if (!merged.empty()) (void)sextant::eval::summarize(scores, merged.front().pose_dof);
  } catch (const sextant::error&) {
  }
  return 0;
}
