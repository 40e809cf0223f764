#pragma once
// The runner's rawlog runs; apart from dataset_runs.hpp so that the ship's translation unit does not
// parse MRPT's rawlog headers.
#include <sextant/mrpt/rawlog.hpp>
#include <string>
#include <vector>

#include "dataset_runs.hpp"

namespace sextant::runner {

/// A planar rawlog with its ground truth attached (run_planar_rawlog.cpp).
std::vector<TableRow> run_rawlog_dataset(const RunOptions& options, const std::string& name,
                                         const mrpt_io::RawlogDataset2D& data, const std::vector<BackendKind>& kinds,
                                         const RunnerConfig& config);
/// A spatial (6D) rawlog with its ground truth attached (run_spatial_rawlog.cpp).
std::vector<TableRow> run_rawlog_dataset(const RunOptions& options, const std::string& name,
                                         const mrpt_io::RawlogDataset3D& data, const std::vector<BackendKind>& kinds,
                                         const RunnerConfig& config);

}  // namespace sextant::runner
