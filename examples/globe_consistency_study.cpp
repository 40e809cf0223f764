// The globe's consistency study (seed 000, §5.2; tests/backends/globe_consistency_test.cpp asserts it
// for 20 seeds): EKF-SLAM on the 12D camera around the simulated globe through the landmark pool
// (Mmax = 1000, max_new = 50), over seeds, with the position and rotation ANEES (3 dof each) against
// the interval of their average, the errors, and the time per run. A Monte Carlo study like the
// others: --shard, --merge and mpirun split it (docs/monte_carlo_clusters.md).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <sextant/backends/ekf_slam.hpp>
#include <sextant/eval/camera_scores.hpp>
#include <sextant/eval/experiment.hpp>
#include <sextant/eval/pooled_run.hpp>
#include <sextant/sim/globe_camera.hpp>
#include <string>
#include <vector>

#include "study_program.hpp"

namespace {

using namespace sextant;

/// One seed: the EKF through the pool, scored as the consistency test scores it.
eval::StudyRecord globe_run(std::uint64_t seed, int steps, const EkfOptions& options) {
  const auto data = sim::simulate_globe_camera({.seed = seed, .num_steps = steps});
  EkfSlam<EulerCamera12D, PointInCamera3D> ekf(data.motion, data.sensor, data.prior, options);
  const auto run = eval::run_through_pool(ekf, data.steps, {.max_landmarks = 1000, .max_new_per_step = 50}, 1,
                                          [](std::size_t, const auto&) {});
  const auto s = eval::score_camera(run.means, run.poses, data.true_poses, ekf.map(), data.true_landmarks);
  eval::RunScores scores;
  scores.steps = run.seconds.size();
  scores.pose_mae = eval::mean(s.position_error);
  scores.pose_rmse = eval::rms(s.position_error);
  scores.pose_mae_aligned = eval::mean(s.position_error_aligned);
  scores.pose_rmse_aligned = eval::rms(s.position_error_aligned);
  scores.map_mae = eval::mean(s.map_error);
  scores.map_mae_aligned = eval::mean(s.map_error_aligned);
  scores.pose_nees_inside = eval::fraction_at_most(s.position_nees, eval::nees_upper_bound(3));
  scores.map_nees_inside = eval::fraction_at_most(s.map_nees, eval::nees_upper_bound(3));
  scores.pose_anees = eval::mean(s.position_nees);  // the position's: the pose ANEES of this study
  scores.total_seconds = run.total_seconds;
  scores.failed_steps = run.failures.total();
  scores.first_failure = run.failures.first;
  return {"globe", "ekf", "EKF-SLAM", 3, seed, scores,
          {{"rotation_anees", eval::mean(s.rotation_nees)}, {"rotation_mae", eval::mean(s.rotation_error)}}, {}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sextant: the globe's consistency study, EKF-SLAM over seeds (position and rotation ANEES)"};
  runner::StudyCommandLine study;
  study.runs = 20;
  study.seed = 100;
  study.add_to(app);
  int steps = 500;
  app.add_option("--steps", steps, "steps per run (thesis: 500)")->check(CLI::Range(2, 100000))->capture_default_str();
  EkfOptions ekf;
  app.add_flag("--first-estimates", ekf.first_estimate_jacobians,
               "first-estimate Jacobians for the landmarks (EkfOptions::first_estimate_jacobians)");
  app.add_flag("--observability-constraints", ekf.observability_constraints,
               "OC-EKF: Jacobians that keep the world's rigid motions unobservable (EkfOptions::observability_constraints)");
  CLI11_PARSE(app, argc, argv);
  try {
    runner::StudyRun run("sextant-globe-study", study, argc, argv);
    run.add_cell([&](std::uint64_t seed) { return globe_run(seed, steps, ekf); });
    const auto records = run.finish();
    if (records.empty()) return 0;  // an MPI rank other than 0
    const auto s = eval::summarize(runner::scores_of(records), 3);
    std::vector<double> rotation, seconds;
    double rotation_mae = 0.0;
    for (const auto& r : records) {
      rotation.push_back(r.extra("rotation_anees"));
      rotation_mae += r.extra("rotation_mae") / static_cast<double>(records.size());
      seconds.push_back(r.scores.total_seconds);
    }
    std::printf("Globe, EKF-SLAM%s%s, %d runs (seeds %llu..%llu), %zu steps each%s\n\n",
                ekf.first_estimate_jacobians ? ", first-estimate Jacobians" : "",
                ekf.observability_constraints ? ", observability constraints" : "", static_cast<int>(records.size()),
                static_cast<unsigned long long>(records.front().seed), static_cast<unsigned long long>(records.back().seed),
                records.front().scores.steps,
                run.part().mode == runner::StudyPart::Mode::shard ? " (this shard's seeds only)" : "");
    std::printf("| position MAE [mm] | rotation MAE [mrad] | map MAE [mm] | position ANEES [95%% interval] | rotation ANEES "
                "[95%% interval] | position NEES <= 7.815 | run time [s]: mean, min, max |\n|---|---|---|---|---|---|---|\n");
    std::string rotation_cell = "-";
    if (rotation.size() > 1) {
      const auto interval = eval::time_averaged_anees_interval(3, rotation, 0.95);
      char text[96];
      std::snprintf(text, sizeof text, "%.3f [%.3f, %.3f]", eval::mean(rotation), interval.lower, interval.upper);
      rotation_cell = text;
    }
    std::printf("| %.3f | %.3f | %.3f | %s | %s | %.1f%% | %.2f, %.2f, %.2f |\n", 1e3 * s.pose_mae, 1e3 * rotation_mae,
                1e3 * s.map_mae, runner::anees_with_interval(s, "%.3f", 3).c_str(), rotation_cell.c_str(),
                100.0 * s.pose_nees_inside, eval::mean(seconds), *std::min_element(seconds.begin(), seconds.end()),
                *std::max_element(seconds.begin(), seconds.end()));
  } catch (const sextant::error& e) {
    std::fprintf(stderr, "sextant-globe-study: %s\n", e.what());
    return 1;
  }
  return 0;
}
