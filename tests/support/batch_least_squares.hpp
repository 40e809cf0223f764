#pragma once
// Exact batch solution of a linear-Gaussian 2D SLAM problem (ship motion, offset beacons): all
// poses and landmarks at once by dense normal equations. The reference filters must equal.

#include <Eigen/Dense>
#include <map>
#include <random>
#include <vector>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/sim/ordered_draws.hpp"

namespace sextant::test {

/// The models and prior of the small linear test problem (random_linear_steps below).
inline const BeaconShip2D kLinearMotion{0.3, 0.2, HeadingNoise::linearized};
inline const BeaconOffset2D kLinearSensor{0.5};
inline const Gaussian<Eigen::Vector2d, 2> kLinearPrior{Eigen::Vector2d(1.0, -2.0), 0.04 * Eigen::Matrix2d::Identity()};

struct BatchSolution {
  Eigen::VectorXd mean;        // [x_0 .. x_K, landmarks in id order]
  Eigen::MatrixXd covariance;  // inverse of the information matrix
  std::map<LandmarkId, Eigen::Index> landmark_offset;
  Eigen::Index final_pose_offset = 0;
};

/// Poses x_0..x_K with x_0 ~ prior, x_{k+1} = g(x_k, u_k) + w_k (w_k ~ N(0, R_k), g affine in x with
/// G = I), and z = m - x_{k+1} + v: the joint Gaussian posterior by information-form least squares.
inline BatchSolution solve_linear_ship_problem(const BeaconShip2D& motion, const BeaconOffset2D& sensor,
                                               const Gaussian<Eigen::Vector2d, 2>& prior,
                                               const std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>>& steps) {
  BatchSolution out;
  const Eigen::Index poses = static_cast<Eigen::Index>(steps.size()) + 1;
  for (const auto& step : steps)
    for (const auto& obs : step.observations) out.landmark_offset.emplace(obs.landmark_id, 0);
  Eigen::Index next = 2 * poses;
  for (auto& [id, offset] : out.landmark_offset) offset = (next += 2) - 2;
  const Eigen::Index n = next;
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  Eigen::VectorXd b = Eigen::VectorXd::Zero(n);
  // Adds the factor r = J_a a + J_b b - c with covariance Sigma between blocks at offsets a and b.
  auto add_factor = [&](Eigen::Index a, const Eigen::Matrix2d& Ja, Eigen::Index bo, const Eigen::Matrix2d& Jb,
                        const Eigen::Vector2d& c, const Eigen::Matrix2d& sigma) {
    const Eigen::Matrix2d W = sigma.llt().solve(Eigen::Matrix2d::Identity());
    A.block<2, 2>(a, a) += Ja.transpose() * W * Ja;
    A.block<2, 2>(bo, bo) += Jb.transpose() * W * Jb;
    A.block<2, 2>(a, bo) += Ja.transpose() * W * Jb;
    A.block<2, 2>(bo, a) += Jb.transpose() * W * Ja;
    b.segment<2>(a) += Ja.transpose() * W * c;
    b.segment<2>(bo) += Jb.transpose() * W * c;
  };
  const Eigen::Matrix2d prior_information = prior.cov.llt().solve(Eigen::Matrix2d::Identity());
  A.topLeftCorner<2, 2>() += prior_information;
  b.head<2>() += prior_information * prior.mean;
  const Eigen::Matrix2d I = Eigen::Matrix2d::Identity();
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const auto prediction = motion.predict(Eigen::Vector2d::Zero(), steps[k].control, steps[k].dt);
    const Eigen::Index from = 2 * static_cast<Eigen::Index>(k), to = from + 2;
    add_factor(to, I, from, -I, prediction.x, prediction.R);  // x_{k+1} - x_k = displacement
    for (const auto& obs : steps[k].observations)
      add_factor(out.landmark_offset.at(obs.landmark_id), I, to, -I, obs.z, sensor.noise());  // m - x = z
  }
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
  out.mean = ldlt.solve(b);
  out.covariance = ldlt.solve(Eigen::MatrixXd::Identity(n, n));
  out.final_pose_offset = 2 * (poses - 1);
  return out;
}

/// A small random linear problem: random controls, a handful of landmarks all in view.
inline std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>> random_linear_steps(int num_steps, int num_landmarks,
                                                                               unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> angle(-3.0, 3.0);
  std::vector<Step<Eigen::Vector2d, Eigen::Vector2d>> steps;
  for (int k = 0; k < num_steps; ++k) {
    const double heading = angle(rng);  // drawn first, as gcc evaluated the arguments (sim/ordered_draws.hpp)
    Step<Eigen::Vector2d, Eigen::Vector2d> step{Eigen::Vector2d(1.0 + 0.2 * unit(rng), heading), 0.5, {}};
    for (int j = 0; j < num_landmarks; ++j)
      if ((k + j) % 3 != 0)  // not every landmark every step; new ones appear over time
        step.observations.push_back({static_cast<LandmarkId>(10 + j), Eigen::Vector2d(3.0 * j, 0.0) + sim::ordered_draws<2>(unit, rng)});
    if (k < num_landmarks) step.observations.resize(std::min<std::size_t>(step.observations.size(), k + 1));
    steps.push_back(step);
  }
  return steps;
}

}  // namespace sextant::test
