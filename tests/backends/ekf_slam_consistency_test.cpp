// Consistency over seeded Monte Carlo runs of the full ship simulation (thesis §4.3.1, eq. 110):
// with the filter's noise equal to the simulator's, the pose ANEES must lie inside its 95%
// chi-square interval for N runs.
#include <gtest/gtest.h>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/eval/metrics.hpp"
#include "sextant/eval/monte_carlo.hpp"
#include "sextant/eval/runner.hpp"
#include "sextant/sim/ship_2d.hpp"

namespace sextant {
namespace {

constexpr int kRuns = 50;

std::vector<double> pose_nees_of_run(std::uint64_t seed, HeadingNoise heading_noise) {
  sim::Ship2DOptions options;
  options.seed = seed;
  options.heading_noise = heading_noise;
  const auto data = sim::simulate_ship_2d(options);
  EkfSlam<BeaconShip2D, BeaconOffset2D> ekf{data.motion, data.sensor, data.prior};
  const auto record = eval::run(ekf, data.steps);
  std::vector<double> nees;
  for (std::size_t k = 0; k < record.steps.size(); ++k)
    nees.push_back(eval::nees(record.steps[k].pose.mean - data.true_poses[k + 1], record.steps[k].pose.cov));
  return nees;
}

struct Consistency {
  double anees;               // mean over runs and steps
  eval::Interval interval;    // of that mean (time_averaged_anees_interval)
  double fraction_of_steps;   // steps whose ANEES over the runs lies inside that step's interval
  eval::Interval step_interval;  // chi2(2 N) / N: one step's average over N independent runs
};

Consistency pose_consistency(HeadingNoise heading_noise, int runs_count = kRuns, std::uint64_t first_seed = 1000) {
  const auto runs =
      eval::monte_carlo(runs_count, first_seed, [&](std::uint64_t seed) { return pose_nees_of_run(seed, heading_noise); });
  std::vector<double> per_run;
  for (const auto& run : runs) per_run.push_back(eval::mean(run));
  const auto per_step = eval::anees_per_step(runs);
  const auto step_interval = eval::anees_interval(2, runs_count);
  const double inside = static_cast<double>(std::count_if(per_step.begin(), per_step.end(),
                                                          [&](double a) { return step_interval.contains(a); }));
  return {eval::mean(per_run), eval::time_averaged_anees_interval(2, per_run), inside / static_cast<double>(per_step.size()),
          step_interval};
}

TEST(EkfSlamConsistency, ShipPoseAneesInsideItsInterval) {
  const auto c = pose_consistency(HeadingNoise::unbiased);
  std::printf("pose ANEES %.3f over %d runs and all steps, 95%% interval [%.3f, %.3f]; steps inside [%.3f, %.3f]: %.1f%%\n",
              c.anees, kRuns, c.interval.lower, c.interval.upper, c.step_interval.lower, c.step_interval.upper,
              100.0 * c.fraction_of_steps);
  EXPECT_TRUE(c.interval.contains(c.anees)) << c.anees;
  // 95% of the steps for a consistent filter; the steps are correlated (an excursion lasts several
  // steps), so the share scatters more than a binomial one: 0.90 is that margin.
  EXPECT_GE(c.fraction_of_steps, 0.90);
}

TEST(EkfSlamConsistency, ThesisLinearizedHeadingNoiseIsOverconfident) {
  // The reason the unbiased model is the default: the linearized mean is biased short, and on the
  // open-sea leg the bias outgrows the covariance.
  const auto c = pose_consistency(HeadingNoise::linearized);
  std::printf("linearized heading noise: pose ANEES %.3f\n", c.anees);
  EXPECT_GT(c.anees, c.interval.upper);
  EXPECT_GT(c.anees, c.step_interval.upper);
}

}  // namespace
}  // namespace sextant
