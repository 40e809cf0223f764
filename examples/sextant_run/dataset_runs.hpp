#pragma once
// What a data-set run is told besides the back-ends and the config: where to write its files.
#include <string>
#include <vector>

#include "table_row.hpp"

namespace sextant::runner {

struct RunnerConfig;  // runner_config.hpp

/// Where and what to write besides the table.
struct RunOptions {
  std::string out;     ///< directory for per-run files; empty: none
  bool plots = false;  ///< also PNG plots
};

}  // namespace sextant::runner
