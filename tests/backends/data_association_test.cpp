// Data association for measurements without ids (issue 14): nearest neighbour and JCBB on hand-made
// cases whose answer is known, the joint marginal EKF and SEIF hand to it, and whole runs of the
// thesis's ship with its ids withheld, scored against the run that knows them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <optional>
#include <string>
#include <vector>

#include "sextant/backends/ekf_slam.hpp"
#include "sextant/backends/seif_slam.hpp"
#include "sextant/core/data_association.hpp"
#include "sextant/eval/association_score.hpp"
#include "sextant/eval/withheld_ids.hpp"
#include "sextant/models/beacon_ship_2d.hpp"
#include "sextant/models/point_in_robot_frame_2d.hpp"
#include "sextant/sim/ship_2d.hpp"

namespace sextant {
namespace {

using Joint = JointMarginal<Eigen::Vector3d, 2>;

PointInRobotFrame2D sensor_with_sigma(double sigma) {
  PointInRobotFrame2D sensor;
  sensor.Q = sigma * sigma * Eigen::Matrix2d::Identity();
  return sensor;
}

/// Landmarks A = (5, 0), B = (5, 1), C = (5, 2) known to 1 cm; the robot, truly at the origin, is
/// believed 0.6 m to the north with sigma 0.5 m, so every landmark is predicted 0.6 m south of where it is seen.
Joint row_of_three() {
  Joint joint{Eigen::Vector3d(0.0, 0.6, 0.0), {10, 11, 12}, {{5.0, 0.0}, {5.0, 1.0}, {5.0, 2.0}}, {}};
  joint.cov = Eigen::MatrixXd::Zero(9, 9);
  joint.cov.diagonal() << 0.25, 0.25, 1e-6, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4, 1e-4;
  return joint;
}

TEST(DataAssociation, JcbbFindsTheJointHypothesisWhereNearestNeighbourFails) {
  // A and C are seen. Alone, A's measurement (5, 0) is nearer to B's prediction (5, 0.4) than to A's
  // (5, -0.6), so nearest neighbour pairs it with B. But both measurements share the robot's error:
  // (A, C) explains them with one common 0.6 m shift, (B, C) needs shifts of -0.4 and +0.6 at once,
  // which landmarks known to 1 cm and a 5 cm sensor cannot give.
  const Joint joint = row_of_three();
  const std::vector<Eigen::Vector2d> z = {{5.0, 0.0}, {5.0, 2.0}};
  AssociationOptions nn_options;
  nn_options.method = AssociationMethod::nearest_neighbour;
  DataAssociation nn(sensor_with_sigma(0.05), nn_options);
  DataAssociation jcbb(sensor_with_sigma(0.05));

  const auto by_nn = nn.associate(joint, std::span(z));
  const auto by_jcbb = jcbb.associate(joint, std::span(z));

  ASSERT_EQ(by_nn.paired, 2u);
  EXPECT_EQ(by_nn.id[0], 11u) << "nearest neighbour is expected to take the nearer, wrong landmark B";
  EXPECT_EQ(by_nn.id[1], 12u);
  EXPECT_GT(by_nn.joint_nis, chi_square_quantile(4, 0.99)) << "and its pairing is jointly incompatible";
  ASSERT_EQ(by_jcbb.paired, 2u);
  EXPECT_EQ(by_jcbb.id[0], 10u);
  EXPECT_EQ(by_jcbb.id[1], 12u);
  EXPECT_LT(by_jcbb.joint_nis, chi_square_quantile(4, 0.99));
  EXPECT_TRUE(by_jcbb.search_complete);
  EXPECT_EQ(by_jcbb.observations.size(), 2u);
}

TEST(DataAssociation, FarMeasurementStartsALandmarkAndASecondClaimOnOneLandmarkIsDiscarded) {
  Joint joint = row_of_three();
  joint.robot = Eigen::Vector3d::Zero();
  joint.cov.diagonal().head<3>().setConstant(1e-6);
  // (5, 0.02) and (5, -0.02) both fit A only; (40, 40) fits nothing.
  const std::vector<Eigen::Vector2d> z = {{5.0, 0.02}, {40.0, 40.0}, {5.0, -0.02}};
  for (const auto method : {AssociationMethod::nearest_neighbour, AssociationMethod::joint_compatibility}) {
    AssociationOptions options;
    options.method = method;
    DataAssociation association(sensor_with_sigma(0.05), options, 1000);
    const auto result = association.associate(joint, std::span(z));
    ASSERT_EQ(result.outcome.size(), 3u);
    EXPECT_EQ(result.paired, 1u);
    EXPECT_EQ(result.created, 1u);
    EXPECT_EQ(result.discarded, 1u);
    EXPECT_EQ(result.outcome[1], AssociationOutcome::new_landmark);
    EXPECT_EQ(result.id[1], 1000u);
    EXPECT_EQ(association.next_new_id(), 1001u);
    const bool first_paired = result.outcome[0] == AssociationOutcome::paired;
    EXPECT_EQ(result.id[first_paired ? 0 : 2], 10u);
    EXPECT_EQ(result.outcome[first_paired ? 2 : 0], AssociationOutcome::discarded);
    ASSERT_EQ(result.observations.size(), 2u) << "the discarded measurement is not handed to update()";
  }
}

/// Every hypothesis JCBB may choose, by enumeration: each measurement unpaired or paired with a
/// distinct landmark inside the individual gate, every prefix of its pairings inside the joint gate,
/// prefixes taken in the search's order (fewest individually compatible landmarks first, ties in
/// input order); the most pairings win, then the smallest joint NIS. Returns the ids chosen
/// (0 = unpaired) and that NIS, each NIS from a fresh factorization of the stacked S.
std::pair<std::vector<LandmarkId>, double> best_by_enumeration(const PointInRobotFrame2D& sensor, const Joint& joint,
                                                               const std::vector<Eigen::Vector2d>& z) {
  const std::size_t m = z.size(), n = joint.ids.size();
  std::vector<std::vector<LinearizedObservation<2, 3, 2>>> lin(m);
  for (std::size_t i = 0; i < m; ++i)
    for (std::size_t j = 0; j < n; ++j)
      lin[i].push_back(linearize_observation(sensor, joint.robot, joint.landmarks[j], z[i], joint.ids[j], 0, 1.0));
  auto nis_of = [&](const std::vector<std::pair<std::size_t, std::size_t>>& pairs) -> std::optional<double> {
    const Eigen::Index k = static_cast<Eigen::Index>(pairs.size());
    Eigen::MatrixXd S(2 * k, 2 * k);
    Eigen::VectorXd nu(2 * k);
    for (Eigen::Index a = 0; a < k; ++a) {
      const auto& [ia, ja] = pairs[a];
      nu.segment<2>(2 * a) = lin[ia][ja].residual;
      for (Eigen::Index b = 0; b < k; ++b) {
        const auto& [ib, jb] = pairs[b];
        S.block<2, 2>(2 * a, 2 * b) = innovation_cross_block(joint.cov, lin[ia][ja].J_z_x, lin[ia][ja].J_z_m, joint.offset(ja),
                                                             lin[ib][jb].J_z_x, lin[ib][jb].J_z_m, joint.offset(jb));
      }
      S.block<2, 2>(2 * a, 2 * a) += lin[ia][ja].Q;
    }
    const Eigen::LLT<Eigen::MatrixXd> llt(S);
    if (llt.info() != Eigen::Success) return std::nullopt;
    return llt.matrixL().solve(nu).squaredNorm();
  };
  auto compatible = [&](std::size_t i, std::size_t j) { return *nis_of({{i, j}}) <= chi_square_quantile(2, 0.99); };
  std::vector<std::size_t> candidates(m, 0), order(m);
  for (std::size_t i = 0; i < m; ++i) {
    order[i] = i;
    for (std::size_t j = 0; j < n; ++j) candidates[i] += compatible(i, j);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return candidates[a] < candidates[b]; });
  std::vector<std::pair<std::size_t, std::size_t>> pairs, best;
  double best_nis = 0.0;
  std::vector<bool> taken(n, false);
  std::function<void(std::size_t)> visit = [&](std::size_t position) {
    if (position == m) {
      const double nis = nis_of(pairs).value_or(0.0);
      if (pairs.size() > best.size() || (pairs.size() == best.size() && !pairs.empty() && nis < best_nis)) {
        best = pairs;
        best_nis = nis;
      }
      return;
    }
    const std::size_t i = order[position];
    for (std::size_t j = 0; j < n; ++j) {
      if (taken[j] || !compatible(i, j)) continue;
      pairs.emplace_back(i, j);
      const auto nis = nis_of(pairs);
      if (nis && *nis <= chi_square_quantile(2.0 * static_cast<double>(pairs.size()), 0.99)) {
        taken[j] = true;
        visit(position + 1);
        taken[j] = false;
      }
      pairs.pop_back();
    }
    visit(position + 1);
  };
  visit(0);
  std::vector<LandmarkId> ids(m, 0);
  for (const auto& [i, j] : best) ids[i] = joint.ids[j];
  return {ids, best_nis};
}

TEST(DataAssociation, JcbbChoosesWhatEnumeratingEveryHypothesisChooses) {
  // Rows of landmarks 0.3 m apart seen through a robot known to 0.2 m, with a 5 cm sensor: most
  // measurements fit two or three landmarks, so the search must weigh many hypotheses with as
  // many pairings; its incremental factorization and its cut by NIS must choose as enumeration does.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 1.0);
  const PointInRobotFrame2D sensor = sensor_with_sigma(0.05);
  for (int trial = 0; trial < 20; ++trial) {
    Joint joint;
    joint.robot = Eigen::Vector3d(0.2 * noise(rng), 0.2 * noise(rng), 0.02 * noise(rng));
    for (int j = 0; j < 8; ++j) {
      joint.ids.push_back(static_cast<LandmarkId>(100 + j));
      joint.landmarks.emplace_back(4.0 + 0.5 * (j / 4), 0.3 * (j % 4) - 0.45);
    }
    joint.cov = 1e-3 * Eigen::MatrixXd::Identity(19, 19);
    joint.cov.topLeftCorner<3, 3>().diagonal() << 0.04, 0.04, 4e-4;
    std::vector<Eigen::Vector2d> z;
    for (int j : {0, 1, 2, 5, 6, 7})  // the truth: the robot at the origin
      z.push_back(joint.landmarks[j] + Eigen::Vector2d(0.05 * noise(rng), 0.05 * noise(rng)));
    DataAssociation association(sensor);
    const auto result = association.associate(joint, std::span<const Eigen::Vector2d>(z));
    const auto [ids, nis] = best_by_enumeration(sensor, joint, z);
    ASSERT_TRUE(result.search_complete);
    for (std::size_t i = 0; i < z.size(); ++i)
      EXPECT_EQ(result.outcome[i] == AssociationOutcome::paired ? result.id[i] : 0, ids[i])
          << "trial " << trial << ", measurement " << i;
    EXPECT_NEAR(result.joint_nis, nis, 1e-9 * (1.0 + nis)) << "trial " << trial;
  }
}

TEST(DataAssociation, EmptyMapMakesEveryMeasurementNew) {
  const Joint empty{Eigen::Vector3d::Zero(), {}, {}, 1e-4 * Eigen::MatrixXd::Identity(3, 3)};
  const std::vector<Eigen::Vector2d> z = {{1.0, 0.0}, {2.0, 0.0}};
  DataAssociation association(sensor_with_sigma(0.05), {}, 7);
  const auto result = association.associate(empty, std::span(z));
  EXPECT_EQ(result.created, 2u);
  EXPECT_EQ(result.observations[0].landmark_id, 7u);
  EXPECT_EQ(result.observations[1].landmark_id, 8u);
}

TEST(DataAssociation, BadInputNamesTheProblem) {
  const Joint joint = row_of_three();
  DataAssociation association(sensor_with_sigma(0.05));
  const std::vector<Eigen::Vector2d> z = {{5.0, 0.0}, {NAN, 1.0}};
  try {
    association.associate(joint, std::span(z));
    FAIL() << "a NaN measurement was associated";
  } catch (const invalid_input_error& e) {
    EXPECT_NE(std::string(e.what()).find("measurement 1"), std::string::npos) << e.what();
  }
  EXPECT_EQ(association.next_new_id(), LandmarkId{1} << 61) << "no id was spent";
  AssociationOptions bad;
  bad.gate_probability = 1.0;
  EXPECT_THROW(DataAssociation(sensor_with_sigma(0.05), bad), invalid_input_error);
  bad.gate_probability = 0.99;
  bad.new_landmark_probability = 0.5;
  EXPECT_THROW(DataAssociation(sensor_with_sigma(0.05), bad), invalid_input_error);
}

// The thesis's ship (linear models): EKF and SEIF without sparsification hold the same Gaussian,
// so they hand the association the same joint marginal.
using ShipEkf = EkfSlam<BeaconShip2D, BeaconOffset2D>;
using ShipSeif = SeifSlam<BeaconShip2D, BeaconOffset2D>;

sim::Ship2DDataset short_ship() {
  sim::Ship2DOptions options;
  options.num_steps = 120;
  return sim::simulate_ship_2d(options);
}

TEST(DataAssociation, EkfAndSeifGiveTheSameJointMarginal) {
  const auto data = short_ship();
  ShipEkf ekf(data.motion, data.sensor, data.prior);
  SeifOptions seif_options;
  seif_options.exact_recovery_period = 1;
  ShipSeif seif(data.motion, data.sensor, data.prior, seif_options);
  for (const auto& step : data.steps) {
    ekf.predict(step.control, step.dt);
    seif.predict(step.control, step.dt);
    ekf.update(step.observations);
    seif.update(step.observations);
  }
  ASSERT_GE(ekf.num_landmarks(), 3u);
  const std::vector<LandmarkId> ids = {ekf.landmark_ids()[2], ekf.landmark_ids()[0]};
  const auto a = ekf.joint_marginal(ids);
  const auto b = seif.joint_marginal(ids);
  EXPECT_EQ(a.ids, b.ids);
  EXPECT_LT((a.robot - b.robot).norm(), 1e-9);
  for (std::size_t i = 0; i < ids.size(); ++i) EXPECT_LT((a.landmarks[i] - b.landmarks[i]).norm(), 1e-9);
  EXPECT_LT((a.cov - b.cov).cwiseAbs().maxCoeff(), 1e-9 * a.cov.cwiseAbs().maxCoeff());
  const Eigen::MatrixXd full = ekf.covariance();
  const Eigen::Index s2 = 2 + 2 * 2, s0 = 2;  // slots 2 and 0
  EXPECT_EQ(a.cov.block(2, 4, 2, 2), full.block(s2, s0, 2, 2)) << "the cross block of landmarks 2 and 0";
  EXPECT_THROW(ekf.joint_marginal(std::vector<LandmarkId>{999999}), unknown_landmark_error);
  EXPECT_THROW(seif.joint_marginal(std::vector<LandmarkId>{999999}), unknown_landmark_error);
}

struct ShipRun {
  double rmse = 0.0;
  eval::AssociationScore score;
};

/// Runs the whole ship route, associating with `method` when set (ids withheld, eval::WithheldIds)
/// or with the simulator's ids when not.
template <class Estimator>
ShipRun run_ship(Estimator estimator, const sim::Ship2DDataset& data, std::optional<AssociationMethod> method) {
  AssociationOptions options;
  if (method) options.method = *method;
  eval::WithheldIds withheld(estimator, data.sensor, options);
  ShipRun run;
  double squared = 0.0;
  for (std::size_t k = 0; k < data.steps.size(); ++k) {
    const auto& step = data.steps[k];
    estimator.predict(step.control, step.dt);
    if (method)
      withheld.update(step.observations);
    else
      estimator.update(step.observations);
    squared += (estimator.pose().mean - data.true_poses[k + 1]).squaredNorm();
  }
  run.rmse = std::sqrt(squared / static_cast<double>(data.steps.size()));
  run.score = withheld.score();
  return run;
}

// The whole route (1390 steps, 2 km beacon noise, beacons 100 km apart with 20 km jitter) closes its
// loop after the open-sea leg, where the pose has drifted by tens of km. The margins: precision and
// recall of 0.98 leave room for the 1% of true pairings a 0.99 gate rejects and a few misses at the
// loop closure; the pose error within 1.5x of the run that knows the ids is the goal.
template <class Estimator>
void expect_association_close_to_known_ids(const Estimator& prototype, const char* name) {
  const auto data = sim::simulate_ship_2d({});
  const ShipRun known = run_ship(prototype, data, std::nullopt);
  const ShipRun jcbb = run_ship(prototype, data, AssociationMethod::joint_compatibility);
  EXPECT_GE(jcbb.score.precision(), 0.98) << name << ": wrong pairings " << jcbb.score.wrong();
  EXPECT_GE(jcbb.score.recall(), 0.98) << name << ": duplicates " << jcbb.score.duplicates() << ", discarded "
                                       << jcbb.score.discarded();
  EXPECT_LE(jcbb.rmse, 1.5 * known.rmse) << name << ": known ids " << known.rmse << " km, JCBB " << jcbb.rmse << " km";
  std::printf("%s on the ship: known ids RMSE %.3f km; JCBB RMSE %.3f km, precision %.4f, recall %.4f, "
              "%zu wrong, %zu duplicates, %zu discarded\n",
              name, known.rmse, jcbb.rmse, jcbb.score.precision(), jcbb.score.recall(), jcbb.score.wrong(),
              jcbb.score.duplicates(), jcbb.score.discarded());
}

TEST(DataAssociation, EkfWithJcbbOnTheShipMatchesTheRunThatKnowsTheIds) {
  const auto data = sim::simulate_ship_2d({});
  expect_association_close_to_known_ids(ShipEkf(data.motion, data.sensor, data.prior), "EKF");
}

// SEIF without sparsification holds the EKF's Gaussian, so its association must do as well; a
// sparsified SEIF's marginals are overconfident (Eustice et al. 2005) and its association is
// measured in docs/data_association.md, not bounded here.
TEST(DataAssociation, SeifWithJcbbOnTheShipMatchesTheRunThatKnowsTheIds) {
  const auto data = sim::simulate_ship_2d({});
  expect_association_close_to_known_ids(ShipSeif(data.motion, data.sensor, data.prior), "SEIF (all active)");
}

}  // namespace
}  // namespace sextant
