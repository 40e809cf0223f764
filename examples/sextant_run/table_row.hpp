#pragma once
// A row of the comparison table: which back-end and its scores. Apart from table.hpp (which needs the
// config) so that the programs' main() units know the rows without the config (docs/build_times.md).
#include <optional>
#include <sextant/eval/experiment.hpp>
#include <string>
#include <type_traits>
#include <vector>

namespace sextant::runner {

/// eseif: SEIF with relocalization (Walter, Eustice and Leonard's exactly sparse filter) whatever
/// [seif] sparsification says; seif follows it (the thesis's by default).
enum class BackendKind { ekf, seif, eseif, graph, fastslam1, fastslam2 };

inline const std::vector<BackendKind>& all_backends() {
  static const std::vector<BackendKind> all = {BackendKind::ekf,   BackendKind::seif,      BackendKind::eseif,
                                               BackendKind::graph, BackendKind::fastslam1, BackendKind::fastslam2};
  return all;
}

/// The command-line name of a back-end (also the prefix of its output files).
inline std::string backend_key(BackendKind kind) {
  switch (kind) {
    case BackendKind::ekf: return "ekf";
    case BackendKind::seif: return "seif";
    case BackendKind::eseif: return "eseif";
    case BackendKind::graph: return "graph";
    case BackendKind::fastslam1: return "fastslam1";
    case BackendKind::fastslam2: return "fastslam2";
  }
  return "?";
}

/// How a data set is scored: which pose entries are position, the degrees of freedom for NEES.
struct Scoring {
  int position_dim, pose_dof, landmark_dof;
};

/// A data set's scoring, from its models: landmarks live where the robot's position does, so the
/// position is the pose's leading landmark-dimension entries; the pose NEES has the motion model's
/// dof, the map's the landmark's.
template <class Dataset>
constexpr Scoring scoring_of() {
  using Motion = std::decay_t<decltype(Dataset::motion)>;
  using Sensor = std::decay_t<decltype(Dataset::sensor)>;
  constexpr int landmark = Sensor::Landmark::RowsAtCompileTime;
  return {landmark, Motion::kDim, landmark};
}

/// How a run with withheld ids associated its measurements (eval::AssociationScore).
struct AssociationRow {
  double precision, recall;
  std::size_t wrong, duplicates, discarded;
  std::size_t searches_cut = 0;  ///< JCBB searches stopped at [association] max_nodes
};

/// A particle filter's cloud at the end of a run (FastSLAM): what its NEES columns rest on.
struct CloudRow {
  double particles, effective_sample_size, distinct_ancestors;
};

/// A SEIF run at its end. ESEIF (SeifSparsification::relocalization): how often it relocalized and
/// how many landmarks stay linked to the robot; a run that never relocalizes is an exact SEIF at the
/// cost of one whose active set grows (docs/results/seif_relocalization.md). With
/// SeifOptions::stale_mean_probability, in how many steps the whole mean was recovered exactly.
struct RelocalizationRow {
  double steps, relocalizations, active, max_active;
  bool relocalizes = true;
  double stale_recoveries = -1.0;  ///< -1: stale_mean_probability off
};

/// Full SLAM's final Gauss-Newton over a row's runs: in how many it stopped at its iteration limit
/// before converging (eval::OptimizationOutcome), and that limit; in how many it kept an earlier
/// iterate than its last (Gauss-Newton's cost rose after it), and which of how many (the first such run's);
/// in how many Gauss-Newton's cost rose and its steps went on damped, and at which iteration (the first
/// such run's).
struct OptimizationRow {
  int runs = 1, unconverged = 0, iterations = 0;
  int kept_earlier = 0, kept_iteration = 0, kept_of = 0;
  int damped = 0, damped_from = -1;
};

/// One run's optimization as its row: `summary` has iterations, converged, best_iteration and
/// damped_from (GraphSlam's OptimizationSummary, eval::OptimizationOutcome).
template <class Summary>
OptimizationRow optimization_row(const Summary& summary) {
  const bool earlier = summary.best_iteration != summary.iterations;
  return OptimizationRow{.unconverged = summary.converged ? 0 : 1, .iterations = summary.iterations,
                         .kept_earlier = earlier ? 1 : 0, .kept_iteration = summary.best_iteration,
                         .kept_of = summary.iterations, .damped = summary.damped_from >= 0 ? 1 : 0,
                         .damped_from = summary.damped_from};
}

/// A line of the comparison table. Every member has an initializer, so that a row is written with
/// designated initializers naming only what it has.
struct TableRow {
  std::string dataset{}, backend{}, label{};
  eval::Summary summary{};
  int runs = 1;
  std::optional<AssociationRow> association{};
  std::optional<std::string> failure{};  ///< why the back-end gave no result: its row prints this instead
  std::optional<CloudRow> cloud{};       ///< FastSLAM: the first run's cloud at its end
  std::optional<RelocalizationRow> relocalization{};  ///< ESEIF: the first run's relocalizations
  std::optional<OptimizationRow> optimization{};      ///< GraphSLAM: its optimizations over the runs
};

}  // namespace sextant::runner
