#pragma once
// Runs the chosen back-ends on one data set and scores them: the same code for the simulated
// ship (Monte Carlo over seeds) and for rawlogs (one run), whatever the models.
#include <Eigen/Core>
#include <optional>
#include <sextant/eval/experiment.hpp>
#include <sextant/eval/monte_carlo.hpp>
#include <string>
#include <vector>

#include "progress_bar.hpp"
#include "runner_config.hpp"
#include "table.hpp"

namespace sextant::runner {

/// One back-end's run: its scores and what the output files and scene need.
template <class Dataset>
struct BackendRun {
  using State = typename decltype(Dataset::motion)::State;
  static constexpr int M = decltype(Dataset::sensor)::Landmark::RowsAtCompileTime;
  eval::RunSummary<State> run;
  std::vector<LandmarkEstimate<M>> map;
  std::vector<State> particles;  ///< FastSLAM's particle poses after the last step
};

/// Runs one back-end over the data set; on_step(k) after every step.
template <class Dataset, class OnStep>
BackendRun<Dataset> run_backend(BackendKind kind, const Dataset& data, const RunnerConfig& c, const Scoring& scoring,
                                OnStep on_step) {
  using Motion = decltype(Dataset::motion);
  using Sensor = decltype(Dataset::sensor);
  BackendRun<Dataset> out;
  const auto finish = [&](auto& backend, auto run) {
    out.run = std::move(run);
    out.map = backend.map();
    if constexpr (requires { backend.particles(); })
      for (const auto& particle : backend.particles()) out.particles.push_back(particle.x);
  };
  switch (kind) {
    case BackendKind::ekf: {
      EkfSlam<Motion, Sensor> b(data.motion, data.sensor, data.prior, c.ekf);
      finish(b, eval::evaluate_run(b, data, scoring.position_dim, on_step));
      break;
    }
    case BackendKind::seif: {
      SeifSlam<Motion, Sensor> b(data.motion, data.sensor, data.prior, c.seif);
      finish(b, eval::evaluate_run(b, data, scoring.position_dim, on_step));
      break;
    }
    case BackendKind::graph: {
      GraphSlam<Motion, Sensor> b(data.motion, data.sensor, data.prior, c.graph);
      finish(b, eval::evaluate_smoothed_run(b, data, scoring.position_dim, on_step));
      break;
    }
    case BackendKind::fastslam1:
    case BackendKind::fastslam2: {
      FastSlamOptions o = c.fastslam;
      o.version = kind == BackendKind::fastslam1 ? FastSlamVersion::v1 : FastSlamVersion::v2;
      FastSlam<Motion, Sensor> b(data.motion, data.sensor, data.prior, o);
      finish(b, eval::evaluate_run(b, data, scoring.position_dim, on_step));
      break;
    }
  }
  return out;
}

/// Every chosen back-end on one rawlog: one run each; `first_runs` receives them for the outputs.
template <class Dataset>
std::vector<TableRow> run_on_rawlog(const std::string& name, const Dataset& data, const std::vector<BackendKind>& kinds,
                                    const RunnerConfig& c, const Scoring& scoring,
                                    std::vector<std::pair<BackendKind, BackendRun<Dataset>>>& first_runs) {
  std::vector<TableRow> rows;
  for (BackendKind kind : kinds) {
    ProgressBar progress(name + ": " + backend_key(kind), data.steps.size());
    auto result = run_backend(kind, data, c, scoring, [&](std::size_t) { progress.advance(); });
    rows.push_back({name, backend_key(kind), backend_label(kind, c),
                    eval::summarize(std::vector{result.run}, scoring.pose_dof, scoring.landmark_dof), 1});
    first_runs.emplace_back(kind, std::move(result));
  }
  return rows;
}

/// Every chosen back-end on `runs` simulated ships (seeds in parallel); the first seed's run of
/// each back-end goes to `first_runs`.
template <class Dataset>
std::vector<TableRow> run_on_ship(const std::vector<BackendKind>& kinds, const RunnerConfig& c, const Scoring& scoring,
                                  std::vector<std::pair<BackendKind, BackendRun<Dataset>>>& first_runs) {
  std::vector<TableRow> rows;
  for (BackendKind kind : kinds) {
    ProgressBar progress("ship: " + backend_key(kind), static_cast<std::size_t>(c.ship_runs));
    std::optional<BackendRun<Dataset>> first;
    std::mutex first_mutex;
    const auto runs = eval::monte_carlo(c.ship_runs, c.ship.seed, [&](std::uint64_t seed) {
      sim::Ship2DOptions o = c.ship;
      o.seed = seed;
      auto result = run_backend(kind, sim::simulate_ship_2d(o), c, scoring, [](std::size_t) {});
      progress.advance();
      if (seed == c.ship.seed) {
        std::lock_guard lock(first_mutex);
        first = result;
      }
      return result.run;
    });
    rows.push_back({"ship", backend_key(kind), backend_label(kind, c),
                    eval::summarize(runs, scoring.pose_dof, scoring.landmark_dof), c.ship_runs});
    first_runs.emplace_back(kind, std::move(*first));
  }
  return rows;
}

}  // namespace sextant::runner
