#pragma once
// Every chosen back-end on a landmark data set of the models MRPT's rawlogs use, compiled once in
// sextant-run (run_planar_rawlog.cpp, run_spatial_rawlog.cpp): a family whose data are planar
// (SE(2) odometry, range and bearing) or spatial (SE(3) odometry, 3D range and bearing) builds an
// io::LandmarkDataset and hands it here (sextant-run/run_square.cpp, docs/runner.md).
#include <sextant/io/landmark_dataset.hpp>
#include <sextant/models/range_bearing_2d.hpp>
#include <sextant/models/range_bearing_3d.hpp>
#include <sextant/models/se2_odometry.hpp>
#include <sextant/models/se3_odometry.hpp>
#include <string>
#include <vector>

#include "runner_cli.hpp"

namespace sextant::runner {

/// A rawlog with its ground truth beside it, planar or spatial as the log is (run_planar_rawlog.cpp).
std::vector<TableRow> run_rawlog(const CliOptions& cli, const std::string& path, const std::vector<BackendKind>& kinds,
                                 const RunnerConfig& config);

/// A planar data set: its part of the table and, with options.out, its files (run_planar_rawlog.cpp).
std::vector<TableRow> run_landmark_dataset(const RunOptions& options, const std::string& name,
                                           const io::LandmarkDataset<Se2Odometry, RangeBearing2D>& data,
                                           const std::vector<BackendKind>& kinds, const RunnerConfig& config);
/// A spatial (6D) data set (run_spatial_rawlog.cpp).
std::vector<TableRow> run_landmark_dataset(const RunOptions& options, const std::string& name,
                                           const io::LandmarkDataset<Se3Odometry, RangeBearing3D>& data,
                                           const std::vector<BackendKind>& kinds, const RunnerConfig& config);

}  // namespace sextant::runner
