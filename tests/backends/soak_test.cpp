// Soak (issue 15): EKF-SLAM and SEIF-SLAM for SEXTANT_SOAK_STEPS steps (10^5 in the default run,
// 10^6 in the Long.* tests, labelled slow: the same program with SEXTANT_SOAK_STEPS=1000000 in the
// environment, so the build compiles it once) on the looping circle world with noisy measurements.
// Every 10^4 steps: the EKF covariance and the SEIF information matrix are symmetric and positive
// definite, the estimates are finite, and the heap has not grown since the map was complete.
// The smallest eigenvalue at each check is printed (the trend goes to docs/reliability.md).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/testing/circle_world.hpp"
#include "sextant/sim/ordered_draws.hpp"

#include <cstdlib>

namespace sextant::test {
namespace {

using sextant::testing::CircleWorld;
using sextant::testing::heap_in_use;

/// SEXTANT_SOAK_STEPS from the environment (a positive count), 10^5 otherwise.
long soak_steps() {
  const char* text = std::getenv("SEXTANT_SOAK_STEPS");
  const long steps = text ? std::strtol(text, nullptr, 10) : 0;
  return steps > 0 ? steps : 100000;
}
const long kSteps = soak_steps();
constexpr long kCheckEvery = 10000;
constexpr int kBeacons = 50;
constexpr double kMeasurementSigma = 0.1;
/// Heap growth allowed between the first check (map complete: a lap is 50 steps) and any later
/// one: allocator bookkeeping of the estimator's few buffers. A leak of one byte per step would
/// exceed it after 65 536 steps, so the 10^5-step run already catches the smallest leak.
constexpr std::size_t kHeapSlackBytes = 64 * 1024;

const BeaconShip2D kMotion{0.05, 0.01, HeadingNoise::linearized};
const BeaconOffset2D kSensor{kMeasurementSigma};

/// What one check found.
struct Check {
  long step;
  double min_eigenvalue;
  double max_eigenvalue;
  double asymmetry;  ///< max |A - A^T| / max |A|
  std::size_t heap;
};

Check check_matrix(long step, const Eigen::MatrixXd& A, std::size_t heap) {
  const double scale = A.cwiseAbs().maxCoeff();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (A + A.transpose()), Eigen::EigenvaluesOnly);
  return {step, eig.eigenvalues().minCoeff(), eig.eigenvalues().maxCoeff(),
          (A - A.transpose()).cwiseAbs().maxCoeff() / scale, heap};
}

/// Runs `estimator` through the world and calls `matrix(estimator)` (the covariance or the
/// information matrix) every kCheckEvery steps.
template <class Estimator, class MatrixOf>
std::vector<Check> soak(Estimator& estimator, MatrixOf matrix, const char* name) {
  const CircleWorld world(kBeacons);
  std::mt19937_64 rng(20261122);
  std::normal_distribution<double> noise(0.0, kMeasurementSigma);
  std::vector<Check> checks;
  for (long step = 1; step <= kSteps; ++step) {
    const int k = static_cast<int>(step % kBeacons);  // the world loops: lap after lap
    estimator.predict(world.control(k), 1.0);
    auto z = world.observations(k);
    for (auto& o : z) o.z += sim::ordered_draws<2>(noise, rng);
    estimator.update(z);
    if (step % kCheckEvery == 0) {
      const auto pose = estimator.pose();
      EXPECT_TRUE(pose.mean.allFinite() && pose.cov.allFinite()) << name << " at step " << step;
      const std::size_t heap = heap_in_use();  // before the check's own temporaries
      checks.push_back(check_matrix(step, matrix(estimator), heap));
      const Check& c = checks.back();
      std::printf("%s step %8ld: eigenvalues [%.3e, %.3e], asymmetry %.1e, heap %zu B\n", name, c.step, c.min_eigenvalue,
                  c.max_eigenvalue, c.asymmetry, c.heap);
    }
  }
  return checks;
}

void expect_healthy(const std::vector<Check>& checks, const char* name) {
  ASSERT_FALSE(checks.empty());
  for (const Check& c : checks) {
    EXPECT_GT(c.min_eigenvalue, 0.0) << name << " is not positive definite at step " << c.step;
    // Symmetric up to the rounding of one symmetrization (a few units in the last place).
    EXPECT_LE(c.asymmetry, 8.0 * Eigen::NumTraits<double>::epsilon()) << name << " at step " << c.step;
    EXPECT_LE(c.heap, checks.front().heap + kHeapSlackBytes)
        << name << ": the heap grew by " << c.heap - checks.front().heap << " bytes between step " << checks.front().step
        << " and step " << c.step << " with the map complete";
  }
  ::testing::Test::RecordProperty("steps", std::to_string(checks.back().step));
  ::testing::Test::RecordProperty("min_eigenvalue_at_end", std::to_string(checks.back().min_eigenvalue));
}

Gaussian<Eigen::Vector2d, 2> prior() { return {CircleWorld(kBeacons).ship(0), 0.01 * Eigen::Matrix2d::Identity()}; }

TEST(Soak, EkfCovarianceStaysSymmetricPositiveDefiniteAndTheHeapFlat) {
  EkfSlam<BeaconShip2D, BeaconOffset2D> ekf(kMotion, kSensor, prior());
  const auto checks = soak(ekf, [](const auto& e) { return e.covariance(); }, "EKF covariance");
  expect_healthy(checks, "EKF covariance");
  EXPECT_EQ(ekf.num_landmarks(), static_cast<std::size_t>(kBeacons));
}

TEST(Soak, SeifInformationStaysSymmetricPositiveDefiniteAndTheHeapFlat) {
  SeifSlam<BeaconShip2D, BeaconOffset2D> seif(kMotion, kSensor, prior(), {.max_active = 8});
  const auto checks = soak(seif, [](const auto& e) { return Eigen::MatrixXd(e.information_matrix()); }, "SEIF information");
  expect_healthy(checks, "SEIF information");
  EXPECT_EQ(seif.num_landmarks(), static_cast<std::size_t>(kBeacons));
}

}  // namespace
}  // namespace sextant::test
