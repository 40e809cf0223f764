#pragma once
// sextant-vislam's run (run_vislam.cpp), apart from sextant-run so that the main job neither
// compiles the SE(3) back-ends nor links libzip.
#include <string>
#include <vector>

#include "dataset_runs.hpp"

namespace sextant::runner {

/// Visual-inertial SLAM on "stereo-vi" (the simulator) or a KITTI-derived .npz file.
std::vector<TableRow> run_vislam(const RunOptions& options, const std::string& dataset,
                                 const std::vector<BackendKind>& kinds, const RunnerConfig& config);

}  // namespace sextant::runner
