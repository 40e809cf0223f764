// sextant-run's planar rawlog part: every chosen back-end on one planar MRPT rawlog.
#include "dataset_runner.hpp"
#include "rawlog_runs.hpp"

namespace sextant::runner {

std::vector<TableRow> run_rawlog_dataset(const RunOptions& options, const std::string& name,
                                         const mrpt_io::RawlogDataset2D& data, const std::vector<BackendKind>& kinds,
                                         const RunnerConfig& config) {
  return run_dataset(options, name, data, kinds, config, Scoring{2, 3, 2}, "m");
}

}  // namespace sextant::runner
