#pragma once
// The runner's one back-end factory: a BackendChoice (which algorithm, its name in the table and the
// files, its options) and with_backend, which builds the back-end it names over a data set's models
// and hands it to the caller. Every data-set family goes through it (experiments.hpp, run_globe.cpp,
// run_vislam.cpp); a family that runs a back-end twice (SEIF per active-set size, the EKF with and
// without first-estimate Jacobians) lists two choices.
#include <algorithm>
#include <optional>
#include <sextant/core/error.hpp>
#include <sextant/models/se2_world_frame.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "runner_config.hpp"
#include "table.hpp"

namespace sextant::runner {

/// One back-end configuration of a run.
struct BackendChoice {
  BackendKind kind;
  std::string key;    ///< its name in the files (ekf, seif150, ...)
  std::string label;  ///< its name in the table
  EkfOptions ekf;
  SeifOptions seif;
  GraphOptions graph;
  FastSlamOptions fastslam;
};

/// Whether a filter linearizes at first estimates (RunnerConfig::ekf_first_estimates, seif_first_estimates):
/// `automatic` means on for the planar world-frame chart (Se2WorldSpace), where the textbook EKF is
/// inconsistent (docs/design_notes.md), and off elsewhere.
template <class Motion>
bool use_first_estimates(AutoSwitch choice) {
  if (choice == AutoSwitch::automatic) return std::is_same_v<typename Motion::Space, Se2WorldSpace>;
  return choice == AutoSwitch::on;
}

/// Whether a filter keeps observability constraints (RunnerConfig::ekf_observability_constraints,
/// seif_observability_constraints): `automatic` means on where Motion's state space names the
/// world's rigid motions (the 12D camera), which no other model pair does.
template <class Motion>
bool use_observability_constraints(AutoSwitch choice) {
  if (choice == AutoSwitch::automatic) return has_world_motion_directions_v<typename Motion::Space>;
  return choice == AutoSwitch::on;
}

/// The mean SEIF reports (RunnerConfig::seif_estimate): `auto` (nullopt) means the exact mean with
/// relocalization, whose information form discards but never invents information, and the recovered
/// mean with the thesis's sparsification, whose exact mean is what its approximation corrupts
/// (docs/results/seif_relocalization.md).
inline SeifEstimate use_estimate(const std::optional<SeifEstimate>& choice, SeifSparsification sparsification) {
  if (choice) return *choice;
  return sparsification == SeifSparsification::relocalization ? SeifEstimate::exact_mean : SeifEstimate::recovered_mean;
}

/// SeifOptions::stale_mean_probability (RunnerConfig::seif_stale_mean_probability): `auto` (nullopt)
/// means 0.999 with relocalization, which after a loop closure would otherwise linearize at a map
/// left behind (docs/results/seif_relocalization.md, "A map left behind by a loop closure"), and 0
/// (never) with the thesis's sparsification, whose Table 5 stays reproduced.
inline double use_stale_mean_probability(const std::optional<double>& choice, SeifSparsification sparsification) {
  if (choice) return *choice;
  return sparsification == SeifSparsification::relocalization ? 0.999 : 0.0;
}

/// One choice per kind, as the config sets it: the first-estimate policy for Motion's chart,
/// FastSLAM's version and eseif's relocalization from the kind. When [seif] sparsification is
/// relocalization, seif is ESEIF already and eseif is left out (a row once).
template <class Motion>
std::vector<BackendChoice> backend_choices(const std::vector<BackendKind>& kinds, const RunnerConfig& c) {
  std::vector<BackendChoice> choices;
  const bool seif_relocalizes = c.seif.sparsification == SeifSparsification::relocalization;
  for (BackendKind kind : kinds) {
    if (kind == BackendKind::eseif && seif_relocalizes && std::find(kinds.begin(), kinds.end(), BackendKind::seif) != kinds.end())
      continue;
    BackendChoice choice{kind, backend_key(kind), backend_label(kind, c), c.ekf, c.seif, c.graph, c.fastslam};
    if (kind == BackendKind::eseif) choice.seif.sparsification = SeifSparsification::relocalization;
    choice.ekf.first_estimate_jacobians = use_first_estimates<Motion>(c.ekf_first_estimates);
    choice.seif.first_estimate_jacobians = use_first_estimates<Motion>(c.seif_first_estimates);
    choice.ekf.observability_constraints = use_observability_constraints<Motion>(c.ekf_observability_constraints);
    choice.seif.observability_constraints = use_observability_constraints<Motion>(c.seif_observability_constraints);
    choice.seif.estimate = use_estimate(c.seif_estimate, choice.seif.sparsification);
    choice.seif.stale_mean_probability = use_stale_mean_probability(c.seif_stale_mean_probability, choice.seif.sparsification);
    choice.fastslam.version = kind == BackendKind::fastslam1 ? FastSlamVersion::v1 : FastSlamVersion::v2;
    choices.push_back(std::move(choice));
  }
  return choices;
}

/// A SEIF run's relocalizations (ESEIF) and exact recoveries of a stale mean after `steps` steps (the
/// line below its row); none for the other back-ends and for a SEIF that does neither.
template <class Backend>
std::optional<RelocalizationRow> relocalization_row(const Backend& backend, std::size_t steps) {
  if constexpr (requires { backend.relocalizations(); }) {
    const auto& o = backend.options();
    const bool relocalizes = o.sparsification == SeifSparsification::relocalization;
    if (relocalizes || o.stale_mean_probability > 0.0)
      return RelocalizationRow{static_cast<double>(steps), static_cast<double>(backend.relocalizations()),
                               static_cast<double>(backend.active_landmarks().size()), static_cast<double>(o.max_active),
                               relocalizes,
                               o.stale_mean_probability > 0.0 ? static_cast<double>(backend.stale_recoveries()) : -1.0};
  }
  return std::nullopt;
}

/// Calls run(); a sextant::error it throws (a back-end failing as a whole: its options, its final
/// optimization) comes back as its message, so that the caller reports it in that back-end's row and
/// goes on with the others.
template <class Run>
std::optional<std::string> failure_of(Run&& run) {
  try {
    run();
    return std::nullopt;
  } catch (const error& e) {
    return std::string(e.what());
  }
}

/// A family's run record (key, label, failure) for a back-end that failed as a whole.
template <class FamilyRun>
FamilyRun failed_run(const BackendChoice& choice, std::string why) {
  FamilyRun out;
  out.key = choice.key;
  out.label = choice.label;
  out.failure = std::move(why);
  return out;
}

/// Builds the back-end `choice` names over the models and the prior and calls use(backend).
template <class Motion, class Sensor, class Prior, class Use>
void with_backend(const BackendChoice& choice, const Motion& motion, const Sensor& sensor, const Prior& prior, Use&& use) {
  switch (choice.kind) {
    case BackendKind::ekf: {
      EkfSlam<Motion, Sensor> backend(motion, sensor, prior, choice.ekf);
      return use(backend);
    }
    case BackendKind::seif:
    case BackendKind::eseif: {
      SeifSlam<Motion, Sensor> backend(motion, sensor, prior, choice.seif);
      return use(backend);
    }
    case BackendKind::graph: {
      GraphSlam<Motion, Sensor> backend(motion, sensor, prior, choice.graph);
      return use(backend);
    }
    case BackendKind::fastslam1:
    case BackendKind::fastslam2: {
      FastSlam<Motion, Sensor> backend(motion, sensor, prior, choice.fastslam);
      return use(backend);
    }
  }
}

}  // namespace sextant::runner
