#pragma once
// Runs the chosen back-ends on one data set and scores them: the same code for the simulated
// ship (Monte Carlo over seeds) and for rawlogs (one run), whatever the models.
#include <Eigen/Core>
#include <optional>
#include <sextant/eval/experiment.hpp>
#include <sextant/eval/monte_carlo.hpp>
#include <sextant/eval/particle_association.hpp>
#include <sextant/eval/withheld_ids.hpp>
#include <sextant/io/landmark_dataset.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "backend_factory.hpp"
#include "monte_carlo_study.hpp"
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
  std::optional<eval::AssociationScore> association;  ///< when the ids were withheld
  std::optional<CloudRow> cloud;                      ///< FastSLAM's cloud after the last step
  std::optional<RelocalizationRow> relocalization;    ///< ESEIF's relocalizations over the run
};

/// Whether a back-end can run with its ids withheld: EKF and SEIF hand data association their joint
/// marginal; FastSLAM associates per particle by maximum likelihood whatever the method.
inline bool associates(BackendKind kind) { return kind != BackendKind::graph; }

inline AssociationRow association_row(const eval::AssociationScore& a) {
  return {a.precision(), a.recall(), a.wrong(), a.duplicates(), a.discarded(), a.searches_cut()};
}

/// Whether `kind` sits this data set out because the ids are withheld and it cannot associate.
inline bool left_out(BackendKind kind, const RunnerConfig& c, const std::string& dataset) {
  if (!c.association.method || associates(kind)) return false;
  std::printf("%s: %s needs known ids, left out (--associate is for EKF, SEIF and FastSLAM)\n", dataset.c_str(),
              backend_key(kind).c_str());
  return true;
}

/// The row of a back-end that failed as a whole: its message instead of scores.
inline TableRow failed_row(const std::string& dataset, const BackendChoice& choice, std::string why) {
  TableRow row{.dataset = dataset, .backend = choice.key, .label = choice.label};
  row.summary.mark_unscored();
  row.failure = std::move(why);
  return row;
}

/// Runs one back-end over the data set; on_step(k) after every step.
template <class Dataset, class OnStep>
BackendRun<Dataset> run_backend(const BackendChoice& choice, const Dataset& data, const RunnerConfig& c,
                                OnStep on_step) {
  constexpr Scoring scoring = scoring_of<Dataset>();
  BackendRun<Dataset> out;
  const auto finish = [&](auto& backend, auto run) {
    out.run = std::move(run);
    out.map = backend.map();
    if constexpr (requires { backend.particles(); })
      for (const auto& particle : backend.particles()) out.particles.push_back(particle.x);
    if constexpr (requires { backend.distinct_ancestors(); })
      out.cloud = CloudRow{static_cast<double>(backend.particles().size()), backend.effective_sample_size(),
                           static_cast<double>(backend.distinct_ancestors())};
    out.relocalization = relocalization_row(backend, data.steps.size());
  };
  /// Scored against the ground truth, or only recorded when the data set has none; a step that
  /// fails is counted in the run and skipped, never the end of the run (eval::StepErrors::skip).
  constexpr auto on_error = eval::StepErrors::skip;
  const auto evaluate = [&](auto& backend) {
    if constexpr (requires { data.has_ground_truth(); })
      if (!data.has_ground_truth()) return eval::record_unscored_run(backend, data, on_step, on_error);
    if constexpr (requires { backend.optimize(); }) {
      return eval::evaluate_smoothed_run(backend, data, scoring.position_dim, on_step, on_error);
    } else {
      if constexpr (requires { backend.path_posterior(); })
        if (backend.options().keep_paths)  // [fastslam] estimate = path
          return eval::evaluate_path_run(backend, data, scoring.position_dim, on_step, on_error);
      return eval::evaluate_run(backend, data, scoring.position_dim, on_step, on_error);
    }
  };
  with_backend(choice, data.motion, data.sensor, data.prior, [&](auto& backend) {
    if (c.association.method && associates(choice.kind)) {  // the ids withheld and associated
      if constexpr (requires { backend.particles(); }) {   // per particle by maximum likelihood, whatever the method
        eval::ParticleAssociation withheld(backend);
        finish(withheld, evaluate(withheld));
        out.association = withheld.score();
        return;
      } else if constexpr (requires { backend.joint_marginal(std::span<const LandmarkId>{}); }) {
        AssociationOptions options = c.association.options;
        options.method = *c.association.method;
        eval::WithheldIds withheld(backend, data.sensor, options);
        finish(withheld, evaluate(withheld));
        out.association = withheld.score();
        return;
      }
    }
    finish(backend, evaluate(backend));
  });
  return out;
}

/// Every chosen back-end on one rawlog: one run each; `first_runs` receives them for the outputs.
template <class Dataset>
std::vector<TableRow> run_on_rawlog(const std::string& name, const Dataset& data, const std::vector<BackendKind>& kinds,
                                    const RunnerConfig& c,
                                    std::vector<std::pair<BackendKind, BackendRun<Dataset>>>& first_runs) {
  constexpr Scoring scoring = scoring_of<Dataset>();
  std::vector<TableRow> rows;
  if constexpr (requires { data.ids; }) {
    if (data.ids == io::LandmarkIds::absent && !c.association.method)
      throw invalid_input_error(name + ": its landmarks have no ids: run it with --associate nn|jcbb");
    if (data.ids == io::LandmarkIds::from_ground_truth)
      std::printf("%s: the log has no landmark ids; each frame's measurements took the ids of the distinct true landmarks "
                  "that explain them best from the true pose, %s\n",
                  name.c_str(), c.association.method ? "which scores the association" : "an oracle association");
  }
  for (const auto& choice : backend_choices<std::decay_t<decltype(Dataset::motion)>>(kinds, c)) {
    const BackendKind kind = choice.kind;
    if (left_out(kind, c, name)) continue;
    ProgressBar progress(name + ": " + choice.key, data.steps.size());
    BackendRun<Dataset> result;
    if (auto why = failure_of([&] { result = run_backend(choice, data, c, [&](std::size_t) { progress.advance(); }); })) {
      rows.push_back(failed_row(name, choice, std::move(*why)));  // its row says so; the others still run
      continue;
    }
    rows.push_back({.dataset = name, .backend = choice.key, .label = choice.label,
                    .summary = eval::summarize(std::vector{result.run}, scoring.pose_dof, scoring.landmark_dof)});
    if (const auto& a = result.association) rows.back().association = association_row(*a);
    rows.back().cloud = result.cloud;
    rows.back().relocalization = result.relocalization;
    if (const auto& o = result.run.optimization) rows.back().optimization = optimization_row(*o);
    if constexpr (requires { data.has_ground_truth(); })
      if (!data.has_ground_truth()) rows.back().summary.mark_unscored();
    first_runs.emplace_back(kind, std::move(result));
  }
  return rows;
}

/// Every chosen back-end on the simulated ships of `seeds` (in parallel on `threads` threads, 0: all
/// cores): a record per back-end and seed (monte_carlo_study.hpp), a seed whose back-end failed as a
/// whole recorded with its message; the run of each back-end on the study's first seed goes to
/// `first_runs` when `seeds` holds it.
template <class Dataset>
std::vector<eval::StudyRecord> ship_records(const std::vector<BackendKind>& kinds, const RunnerConfig& c,
                                          eval::SeedRange seeds, unsigned threads,
                                          std::vector<std::pair<BackendKind, BackendRun<Dataset>>>& first_runs) {
  constexpr Scoring scoring = scoring_of<Dataset>();
  std::vector<eval::StudyRecord> records;
  for (const auto& choice : backend_choices<std::decay_t<decltype(Dataset::motion)>>(kinds, c)) {
    if (left_out(choice.kind, c, "ship")) continue;
    ProgressBar progress("ship: " + choice.key, static_cast<std::size_t>(seeds.count));
    std::optional<BackendRun<Dataset>> first;
    std::mutex first_mutex;
    auto runs = eval::monte_carlo(seeds.count, seeds.first, [&](std::uint64_t seed) {
      eval::StudyRecord record{"ship", choice.key, choice.label, scoring.pose_dof, seed, {}, {}, {}};
      sim::Ship2DOptions o = c.ship;
      o.seed = seed;
      BackendRun<Dataset> result;
      const auto why = failure_of([&] { result = run_backend(choice, sim::simulate_ship_2d(o), c, [](std::size_t) {}); });
      progress.advance();
      if (why) {  // this seed's back-end as a whole: the row says so, the others still run
        record.failure = *why;
        return record;
      }
      record.scores = eval::scores_of(result.run, scoring.pose_dof, scoring.landmark_dof);
      if (const auto& a = result.association) record.extras = association_extras(association_row(*a));
      if (const auto& cloud = result.cloud) {
        const auto extras = cloud_extras(*cloud);
        record.extras.insert(record.extras.end(), extras.begin(), extras.end());
      }
      if (const auto& relocalization = result.relocalization) {
        const auto extras = relocalization_extras(*relocalization);
        record.extras.insert(record.extras.end(), extras.begin(), extras.end());
      }
      if (const auto& optimization = result.run.optimization) {
        const auto extras = optimization_extras(optimization_row(*optimization));
        record.extras.insert(record.extras.end(), extras.begin(), extras.end());
      }
      if (seed == c.ship.seed) {
        std::lock_guard lock(first_mutex);
        first = std::move(result);
      }
      return record;
    }, threads);
    records.insert(records.end(), std::make_move_iterator(runs.begin()), std::make_move_iterator(runs.end()));
    if (first) first_runs.emplace_back(choice.kind, std::move(*first));
  }
  return records;
}

}  // namespace sextant::runner
