#pragma once
// The globe experiment's parts that sextant-globe-stereo shares with sextant-globe (run_globe.cpp).
#include <sextant/sim/globe_camera.hpp>
#include <string>
#include <vector>

#include "dataset_runs.hpp"
#include "runner_config.hpp"

namespace sextant::runner {

/// The simulator's options from the runner's [globe] settings; everything else at its default.
sim::GlobeCameraOptions globe_options(const GlobeSettings& s);

/// Every back-end in `kinds` over `data` through the landmark pool: the globe table, and with
/// options.out per-step CSV, TUM and .3Dscene files in <out>/<name>/. Rows are named `name`.
std::vector<TableRow> run_globe_dataset(const RunOptions& options, const std::string& name, const sim::GlobeCameraDataset& data,
                                        const std::vector<BackendKind>& kinds, const RunnerConfig& config);

/// Prints how far the prior's mean lies from the true first pose (once a run: the stereo run's
/// reference shares its start).
void print_start_draw(const sim::GlobeCameraDataset& data);

}  // namespace sextant::runner
