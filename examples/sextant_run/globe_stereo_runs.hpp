#pragma once
// sextant-globe-stereo's data sets (run_globe_stereo.cpp): they need OpenCV (sextant::vision).
#include <string>
#include <vector>

#include "dataset_runs.hpp"

namespace sextant::runner {

/// The globe rendered as stereo images, the front-end, then every back-end on its observations and,
/// for comparison, the EKF on the point simulator's observations of the same trajectory.
/// save_images: also write the rendered sequence there (stereo:<dir> layout); empty: not.
std::vector<TableRow> run_globe_stereo(const RunOptions& options, const std::string& save_images,
                                       const std::vector<BackendKind>& kinds, const RunnerConfig& config);

/// A user's rectified sequence (left/*.png, right/*.png, calib.yaml): the front-end with EKF tracking.
std::vector<TableRow> run_stereo_directory(const RunOptions& options, const std::string& dir, const RunnerConfig& config);

}  // namespace sextant::runner
