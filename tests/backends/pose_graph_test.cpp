// The pose-graph optimizer and its files: edge Jacobians against central differences, graphs whose
// optimum is known in closed form, MRPT's circle against its ground truth, robust kernels, g2o round
// trips, TORO and edges-only files, and malformed input.
#include <gtest/gtest.h>

#include <fstream>
#include <random>

#include "sextant/backends/pose_graph.hpp"
#include "sextant/io/pose_graph_file.hpp"
#include "support/shared_data.hpp"  // SEXTANT_REQUIRE_DATA (MRPT's circle)
#include "support/temp_path.hpp"

namespace sextant {
namespace {

std::mt19937 rng(7);
double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

Eigen::Vector3d random_planar() { return {uniform(-5, 5), uniform(-5, 5), uniform(-3.1, 3.1)}; }
Eigen::Matrix4d random_spatial() {
  se3::Vector6d xi;
  for (int i = 0; i < 6; ++i) xi(i) = uniform(-2, 2);
  return se3::exp(xi);
}

/// Central differences of f along each step direction of `x` (plus).
template <class Poses, class F>
Eigen::MatrixXd numeric_pose_jacobian(const typename Poses::Pose& x, F f) {
  constexpr double h = 1e-6;
  const auto f0 = f(x);
  Eigen::MatrixXd J(f0.size(), Poses::kDim);
  for (int k = 0; k < Poses::kDim; ++k) {
    typename Poses::Tangent d = Poses::Tangent::Zero();
    d(k) = h;
    J.col(k) = (f(Poses::plus(x, d)) - f(Poses::plus(x, -d))) / (2 * h);
  }
  return J;
}

template <class Poses>
void check_between_jacobians(const typename Poses::Pose& a, const typename Poses::Pose& b, const typename Poses::Pose& z) {
  const auto lin = Poses::linearize_between(a, b, z);
  const auto J_from = numeric_pose_jacobian<Poses>(a, [&](const auto& x) { return Poses::between_error(x, b, z); });
  const auto J_to = numeric_pose_jacobian<Poses>(b, [&](const auto& x) { return Poses::between_error(a, x, z); });
  EXPECT_LT((lin.J_from - J_from).cwiseAbs().maxCoeff(), 1e-7) << lin.J_from << "\n\n" << J_from;
  EXPECT_LT((lin.J_to - J_to).cwiseAbs().maxCoeff(), 1e-7) << lin.J_to << "\n\n" << J_to;
}

TEST(PoseGraphEdges, PlanarJacobiansMatchCentralDifferences) {
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d a = random_planar(), b = random_planar();
    const Eigen::Vector3d z = PlanarPoses::compose(PlanarPoses::between(a, b), Eigen::Vector3d(0.1, -0.2, 0.3));
    check_between_jacobians<PlanarPoses>(a, b, z);
    const Eigen::Vector2d l(uniform(-5, 5), uniform(-5, 5)), zl(uniform(-1, 1), uniform(-1, 1));
    const auto lin = PlanarPoses::linearize_point(a, l, zl);
    const auto J = numeric_pose_jacobian<PlanarPoses>(a, [&](const auto& x) { return PlanarPoses::point_error(x, l, zl); });
    EXPECT_LT((lin.J_pose - J).cwiseAbs().maxCoeff(), 1e-7);
    EXPECT_TRUE(lin.J_point.isApprox(PlanarPoses::rotation(a(2)).transpose()));  // the error is linear in l
  }
}

TEST(PoseGraphEdges, SpatialJacobiansMatchCentralDifferences) {
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Matrix4d a = random_spatial(), b = random_spatial();
    // measurements near the truth and far from it (the quaternion's w near 0 and the sign flip)
    const Eigen::Matrix4d z = trial % 2 ? se3::inverse(a) * b * random_spatial() : random_spatial();
    check_between_jacobians<SpatialPoses>(a, b, z);
    const Eigen::Vector3d l(uniform(-5, 5), uniform(-5, 5), uniform(-5, 5)), zl(uniform(-1, 1), 0.3, 2.0);
    const Eigen::Matrix4d offset = random_spatial();
    const auto lin = SpatialPoses::linearize_point(a, l, zl, offset);
    const auto J =
        numeric_pose_jacobian<SpatialPoses>(a, [&](const auto& x) { return SpatialPoses::point_error(x, l, zl, offset); });
    EXPECT_LT((lin.J_pose - J).cwiseAbs().maxCoeff(), 1e-7);
    Eigen::Matrix3d J_point;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d d = 1e-6 * Eigen::Vector3d::Unit(k);
      J_point.col(k) = (SpatialPoses::point_error(a, l + d, zl, offset) - SpatialPoses::point_error(a, l - d, zl, offset)) / 2e-6;
    }
    EXPECT_LT((lin.J_point - J_point).cwiseAbs().maxCoeff(), 1e-7);
  }
}

/// Two measurements of one relative translation with the rotations at identity: the errors are
/// linear, and the optimum is the information-weighted mean, in closed form. No cost tolerance: the
/// optimizer runs until the gradient vanishes or the cost is flat to its rounding, which resolves
/// the parameters to about sqrt(eps) = 1.5e-8 times their scale (here ~4): bound 1e-7.
TEST(PoseGraph, TwoMeasurementsOfOneTranslationMeetAtTheirInformationWeightedMean) {
  PoseGraphOptions to_the_end;
  to_the_end.function_tolerance = 0.0;
  PoseGraph<PlanarPoses> planar;
  planar.add_pose(0, Eigen::Vector3d::Zero());
  planar.add_pose(1, Eigen::Vector3d(3.0, -2.0, 0.0));
  planar.fix(0);
  const Eigen::Matrix3d I1 = Eigen::Vector3d(1, 2, 5).asDiagonal(), I2 = Eigen::Vector3d(3, 1, 5).asDiagonal();
  planar.add_between(0, 1, Eigen::Vector3d(1.0, 0.0, 0.0), I1);
  planar.add_between(0, 1, Eigen::Vector3d(1.2, 0.3, 0.0), I2);
  const auto summary = planar.optimize(to_the_end);
  EXPECT_TRUE(summary.converged) << summary.stop_reason;
  const Eigen::Vector3d mean = (I1 + I2).inverse() * (I1 * Eigen::Vector3d(1.0, 0.0, 0.0) + I2 * Eigen::Vector3d(1.2, 0.3, 0.0));
  EXPECT_LT((planar.pose(1) - mean).norm(), 1e-7);
  EXPECT_TRUE(planar.pose(0).isZero());

  PoseGraph<SpatialPoses> spatial;
  spatial.add_pose(0, Eigen::Matrix4d::Identity());
  spatial.add_pose(1, se3::make(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1, 4, 2)));
  spatial.fix(0);
  Eigen::Matrix<double, 6, 6> J1 = Eigen::Matrix<double, 6, 6>::Identity(), J2 = 4 * J1;
  J1.topLeftCorner<3, 3>() = Eigen::Vector3d(1, 2, 3).asDiagonal();
  const Eigen::Vector3d t1(1, 2, 3), t2(2, 2, 0);
  spatial.add_between(0, 1, se3::make(Eigen::Matrix3d::Identity(), t1), J1);
  spatial.add_between(0, 1, se3::make(Eigen::Matrix3d::Identity(), t2), J2);
  EXPECT_TRUE(spatial.optimize(to_the_end).converged);
  const Eigen::Matrix3d W1 = J1.topLeftCorner<3, 3>(), W2 = J2.topLeftCorner<3, 3>();
  const Eigen::Vector3d expected = (W1 + W2).inverse() * (W1 * t1 + W2 * t2);
  EXPECT_LT((se3::translation(spatial.pose(1)) - expected).norm(), 1e-7);
  EXPECT_LT((se3::rotation(spatial.pose(1)) - Eigen::Matrix3d::Identity()).norm(), 1e-7);
}

/// Measurements taken from a true trajectory and points without noise: the optimum is the truth
/// (chi2 = 0), reached from a start far from it, in the plane and in space, with loop closures and
/// point observations.
template <class Poses, class Random>
void expect_consistent_graph_recovers_truth(Random random_pose) {
  std::vector<typename Poses::Pose> truth(12);
  truth[0] = Poses::identity();
  for (std::size_t k = 1; k < truth.size(); ++k) truth[k] = random_pose();
  PoseGraph<Poses> graph;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    typename Poses::Tangent noise;
    for (int i = 0; i < Poses::kDim; ++i) noise(i) = uniform(-0.3, 0.3);
    graph.add_pose(static_cast<VertexId>(k), k == 0 ? truth[0] : Poses::plus(truth[k], noise));
  }
  const typename PoseGraph<Poses>::EdgeInformation information = 10.0 * PoseGraph<Poses>::EdgeInformation::Identity();
  for (std::size_t k = 0; k + 1 < truth.size(); ++k)
    graph.add_between(k, k + 1, Poses::between(truth[k], truth[k + 1]), information);
  graph.add_between(11, 0, Poses::between(truth[11], truth[0]), information);
  graph.add_between(3, 8, Poses::between(truth[3], truth[8]), information);
  // points seen from several poses (on SE(3) through a sensor offset), starting far off
  using Point = typename PoseGraph<Poses>::Point;
  const auto offset = Poses::kDim == 6 ? random_pose() : Poses::identity();
  std::vector<Point> points;
  for (int j = 0; j < 4; ++j) {
    points.push_back(5.0 * Point::Random());
    graph.add_point(100 + j, Point::Zero());
    for (std::size_t k = j; k < truth.size(); k += 3) {
      Point z;
      if constexpr (Poses::kDim == 6) z = Poses::point_error(truth[k], points.back(), Point::Zero(), offset);
      else z = Poses::point_error(truth[k], points.back(), Point::Zero());
      graph.add_point_observation(k, 100 + j, z, PoseGraph<Poses>::PointInformation::Identity(), offset);
    }
  }
  const auto summary = graph.optimize();
  EXPECT_TRUE(summary.converged) << summary.stop_reason;
  EXPECT_LT(summary.final_chi2, 1e-16);
  for (std::size_t k = 0; k < truth.size(); ++k)
    EXPECT_LT((graph.pose(k) - truth[k]).cwiseAbs().maxCoeff(), 1e-8) << "pose " << k;
  for (int j = 0; j < 4; ++j) EXPECT_LT((graph.point(100 + j) - points[j]).cwiseAbs().maxCoeff(), 1e-8) << "point " << j;
}

/// Chordal relaxation is exact on consistent measurements: the rotations solve R_j = R_i R_ij
/// exactly, so does the translation system; no iteration needed.
template <class Poses, class Random>
void expect_chordal_relaxation_exact_on_noise_free_graph(Random random_pose) {
  std::vector<typename Poses::Pose> truth(15);
  truth[0] = Poses::identity();
  for (std::size_t k = 1; k < truth.size(); ++k) truth[k] = random_pose();
  PoseGraph<Poses> graph;
  for (std::size_t k = 0; k < truth.size(); ++k) graph.add_pose(static_cast<VertexId>(k), Poses::identity());
  graph.fix(0);
  graph.set_pose(0, truth[0]);
  typename PoseGraph<Poses>::EdgeInformation information = PoseGraph<Poses>::EdgeInformation::Identity();
  information.diagonal().head(Poses::kSpaceDim).setConstant(4.0);
  for (std::size_t k = 0; k + 1 < truth.size(); ++k) graph.add_between(k, k + 1, Poses::between(truth[k], truth[k + 1]), information);
  graph.add_between(14, 2, Poses::between(truth[14], truth[2]), information);
  graph.initialize_by_chordal_relaxation();
  for (std::size_t k = 0; k < truth.size(); ++k)
    EXPECT_LT((graph.pose(k) - truth[k]).cwiseAbs().maxCoeff(), 1e-9) << "pose " << k;
}

TEST(PoseGraph, ChordalRelaxationIsExactOnNoiseFreeGraphs) {
  expect_chordal_relaxation_exact_on_noise_free_graph<PlanarPoses>(random_planar);
  expect_chordal_relaxation_exact_on_noise_free_graph<SpatialPoses>(random_spatial);
}

TEST(PoseGraph, NoiseFreeGraphsReachTheirTruthFromAFarStart) {
  expect_consistent_graph_recovers_truth<PlanarPoses>([] {
    Eigen::Vector3d x = random_planar();
    return x;
  });
  expect_consistent_graph_recovers_truth<SpatialPoses>(random_spatial);
}

/// MRPT's circle of 50 poses (mrpt-common): the optimum's chi2 cannot exceed the chi2 at the ground
/// truth (it is the minimum), and the optimized poses are closer to the truth than the start.
TEST(PoseGraph, MrptCircleOptimizesBelowTheChiSquareOfItsGroundTruth) {
  const std::string noisy = "/usr/share/mrpt/datasets/graph_2d_circle_50nodes.graph";
  const std::string truth_file = "/usr/share/mrpt/datasets/graph_2d_circle_50nodes_groundtruth.graph";
  SEXTANT_REQUIRE_DATA(noisy);
  auto file = io::read_pose_graph(noisy);
  auto truth = io::read_pose_graph(truth_file);
  ASSERT_EQ(file.dimension, 2);
  EXPECT_EQ(file.format, "TORO");
  auto& graph = file.planar;
  ASSERT_EQ(graph.num_poses(), 50u);
  auto position_error = [&] {
    double sum = 0.0;
    for (std::size_t k = 0; k < 50; ++k)
      sum += (graph.pose(k).head<2>() - truth.planar.pose(k).head<2>()).squaredNorm();
    return std::sqrt(sum / 50);
  };
  PoseGraph<PlanarPoses> at_truth = graph;
  for (std::size_t k = 0; k < 50; ++k) at_truth.set_pose(k, truth.planar.pose(k));
  const double before = position_error();
  const auto summary = graph.optimize();
  EXPECT_TRUE(summary.converged) << summary.stop_reason;
  EXPECT_LE(summary.final_chi2, at_truth.chi2());
  EXPECT_LT(position_error(), before);
  for (bool chordal : {true, false}) {  // other starts, the same optimum (to LM's stopping tolerance)
    auto again = io::read_pose_graph(noisy);
    if (chordal) again.planar.initialize_by_chordal_relaxation();
    else again.planar.initialize_by_spanning_tree();
    EXPECT_NEAR(again.planar.optimize().final_chi2, summary.final_chi2, 1e-6 * summary.final_chi2);
  }
}

/// 10% of the loop closures replaced by wrong ones: the Cauchy kernel keeps the estimate near the
/// clean optimum where least squares is pulled away.
TEST(PoseGraph, CauchyKernelOnLoopClosuresResistsWrongOnes) {
  std::vector<Eigen::Vector3d> truth;
  PoseGraph<PlanarPoses> clean;
  for (int k = 0; k < 60; ++k) {
    const double a = 2 * M_PI * k / 60;
    truth.emplace_back(10 * std::cos(a), 10 * std::sin(a), wrap_angle(a + M_PI / 2));
    clean.add_pose(k, truth.back());
  }
  const Eigen::Matrix3d information = Eigen::Vector3d(100, 100, 1000).asDiagonal();
  std::normal_distribution<double> noise(0.0, 0.1);
  auto noisy = [&](Eigen::Vector3d z) { return Eigen::Vector3d(z(0) + noise(rng), z(1) + noise(rng), z(2) + 0.03 * noise(rng)); };
  for (int k = 0; k + 1 < 60; ++k) clean.add_between(k, k + 1, noisy(PlanarPoses::between(truth[k], truth[k + 1])), information);
  for (int k = 0; k + 10 < 60; k += 2) clean.add_between(k, k + 10, noisy(PlanarPoses::between(truth[k], truth[k + 10])), information);
  PoseGraph<PlanarPoses> corrupted = clean;
  for (int k = 1; k + 20 < 60; k += 8)  // wrong closures: 5 against 25 right ones
    corrupted.add_between(k, k + 20, Eigen::Vector3d(uniform(-3, 3), uniform(-3, 3), uniform(-3, 3)), information);
  PoseGraphOptions robust;
  robust.loop_closure_loss = {RobustKernel::cauchy, 1.0};
  clean.optimize();
  PoseGraph<PlanarPoses> plain = corrupted;
  plain.optimize();
  corrupted.optimize(robust);
  auto distance = [&](const PoseGraph<PlanarPoses>& g) {
    double worst = 0.0;
    for (int k = 0; k < 60; ++k) worst = std::max(worst, (g.pose(k).head<2>() - clean.pose(k).head<2>()).norm());
    return worst;
  };
  EXPECT_LT(distance(corrupted), 0.2 * distance(plain)) << distance(corrupted) << " vs " << distance(plain);
  // with the outlier gate: every wrong closure is dropped, and the estimate is the least-squares
  // optimum of the edges left (to LM's stopping tolerance: bound 1e-4 m)
  PoseGraphOptions gated = robust;
  gated.outlier_gate_probability = 0.999;
  const auto summary = corrupted.optimize(gated);
  PoseGraph<PlanarPoses> kept;
  for (int k = 0; k < 60; ++k) kept.add_pose(k, truth[k]);
  std::size_t rejected = 0;
  for (std::size_t k = 0; k < corrupted.betweens().size(); ++k) {
    const auto& edge = corrupted.betweens()[k];
    if (k >= clean.betweens().size()) EXPECT_TRUE(edge.rejected) << "wrong closure " << k << " kept";
    rejected += edge.rejected;
    if (!edge.rejected) kept.add_between(edge.from, edge.to, edge.z, edge.information);
  }
  EXPECT_EQ(summary.rejected_edges, rejected);
  kept.optimize();
  double worst = 0.0;
  for (int k = 0; k < 60; ++k) worst = std::max(worst, (kept.pose(k) - corrupted.pose(k)).cwiseAbs().maxCoeff());
  EXPECT_LT(worst, 1e-4);
  EXPECT_THROW(corrupted.optimize({.outlier_gate_probability = 1.0}), invalid_input_error);
}

TEST(PoseGraph, BadEdgesAreRefusedAndLeaveTheGraphAsItWas) {
  PoseGraph<PlanarPoses> graph;
  graph.add_pose(0, Eigen::Vector3d::Zero());
  graph.add_pose(1, Eigen::Vector3d(1, 0, 0));
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  EXPECT_THROW(graph.add_pose(1, Eigen::Vector3d::Zero()), invalid_input_error);
  EXPECT_THROW(graph.add_pose(2, Eigen::Vector3d(0, NAN, 0)), invalid_input_error);
  EXPECT_THROW(graph.add_between(0, 7, Eigen::Vector3d::Zero(), I), invalid_input_error);
  EXPECT_THROW(graph.add_between(1, 1, Eigen::Vector3d::Zero(), I), invalid_input_error);
  EXPECT_THROW(graph.add_between(0, 1, Eigen::Vector3d(INFINITY, 0, 0), I), invalid_input_error);
  EXPECT_THROW(graph.add_between(0, 1, Eigen::Vector3d::Zero(), Eigen::Matrix3d(Eigen::Vector3d(1, 0, 1).asDiagonal())),
               invalid_input_error);
  Eigen::Matrix3d asymmetric = I;
  asymmetric(0, 1) = 0.5;
  EXPECT_THROW(graph.add_between(0, 1, Eigen::Vector3d::Zero(), asymmetric), invalid_input_error);
  EXPECT_THROW(graph.fix(9), invalid_input_error);
  EXPECT_EQ(graph.num_poses(), 2u);
  EXPECT_EQ(graph.num_edges(), 0u);
}

/// An optimize() that throws (here: a start whose cost overflows) leaves the graph bit for bit as
/// it was, the gauge included.
TEST(PoseGraph, AFailedOptimizationLeavesTheGraphAsItWas) {
  PoseGraph<PlanarPoses> graph;
  graph.add_pose(0, Eigen::Vector3d::Zero());
  graph.add_pose(1, Eigen::Vector3d(1e200, 0, 0));
  graph.add_between(0, 1, Eigen::Vector3d(1, 0, 0), 1e200 * Eigen::Matrix3d::Identity());
  EXPECT_THROW(graph.optimize(), numerical_error);
  EXPECT_FALSE(graph.is_fixed(0));
  EXPECT_EQ(graph.pose(1), Eigen::Vector3d(1e200, 0, 0));
}

// ----- files -----

std::string write_temp(const std::string& name, const std::string& text) {
  const auto path = test::unique_temp_path(name).string();
  std::ofstream(path) << text;
  return path;
}

/// The message of the parse_error reading `text` throws.
std::string read_error(const std::string& text, const std::string& name = "bad.g2o") {
  const auto path = write_temp(name, text);
  try {
    io::read_pose_graph(path);
  } catch (const parse_error& e) {
    std::filesystem::remove(path);
    return e.what();
  }
  std::filesystem::remove(path);
  return "no error";
}

TEST(PoseGraphFile, MalformedFilesNameFileAndLine) {
  const std::string v = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";
  const std::string info = " 1 0 0 1 0 1\n";
  EXPECT_NE(read_error(v + "EDGE_SE2 0 1 1 0 0" + info + "BOGUS 1 2\n").find("bad.g2o:4: unknown record 'BOGUS'"), std::string::npos);
  EXPECT_NE(read_error(v + "EDGE_SE2 0 1 1 0 0 1 0\n").find(":3: EDGE_SE2 needs 11 values, found 7"), std::string::npos);
  EXPECT_NE(read_error(v + "EDGE_SE2 0 1 nan 0 0" + info).find(":3: 'nan' is not a finite number"), std::string::npos);
  EXPECT_NE(read_error(v + "VERTEX_SE2 1 0 0 0\n").find(":3: vertex 1 is defined twice"), std::string::npos);
  EXPECT_NE(read_error(v + "EDGE_SE2 0 5 1 0 0" + info).find(":3: EDGE_SE2 names vertex 5, which no vertex record defines"),
            std::string::npos);
  EXPECT_NE(read_error(v + "EDGE_SE2 0 1 1 0 0 1 0 0 -1 0 1\n").find(":3: edge 0 -> 1: information matrix is not positive definite"),
            std::string::npos);
  EXPECT_NE(read_error(v + "EDGE_SE2 0 1.5 1 0 0" + info).find(":3: vertex id must be a non-negative integer"), std::string::npos);
  EXPECT_NE(read_error(v + "VERTEX_SE3:QUAT 2 0 0 0 0 0 0 1\n").find(":3: VERTEX_SE3:QUAT is a 3D record in a file whose first records are 2D"),
            std::string::npos);
  EXPECT_NE(read_error("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 0.5\n").find(":1: quaternion of norm 0.5"), std::string::npos);
  EXPECT_NE(read_error(v + "VERTEX2 3 0 0 0\n").find(":3: VERTEX2 is a TORO record in a g2o file"), std::string::npos);
  EXPECT_NE(read_error(v + "FIX\n").find(":3: FIX needs 1 values, found 0"), std::string::npos);
  EXPECT_NE(read_error(v + "FIX 4\n").find(":3: unknown vertex 4"), std::string::npos);
  EXPECT_NE(read_error("# only a comment\n").find("no vertex or edge records"), std::string::npos);
  EXPECT_NE(read_error(std::string("VERTEX_SE2 0 0 0 0\n\x01\xff 1\n")).find(":2: unknown record '\\x01\\xff'"), std::string::npos);
}

template <class Poses>
void expect_same_graph(const PoseGraph<Poses>& a, const PoseGraph<Poses>& b) {
  ASSERT_EQ(a.vertices().size(), b.vertices().size());
  for (std::size_t k = 0; k < a.vertices().size(); ++k) {
    EXPECT_EQ(a.vertices()[k].id, b.vertices()[k].id);
    EXPECT_EQ(a.vertices()[k].is_point, b.vertices()[k].is_point);
    EXPECT_EQ(a.vertices()[k].fixed, b.vertices()[k].fixed);
  }
  for (std::size_t k = 0; k < a.num_poses(); ++k) EXPECT_LT((a.poses()[k] - b.poses()[k]).cwiseAbs().maxCoeff(), 1e-14);
  for (std::size_t k = 0; k < a.num_points(); ++k) EXPECT_EQ(a.points()[k], b.points()[k]);
  ASSERT_EQ(a.betweens().size(), b.betweens().size());
  for (std::size_t k = 0; k < a.betweens().size(); ++k) {
    EXPECT_LT((a.betweens()[k].z - b.betweens()[k].z).cwiseAbs().maxCoeff(), 1e-14);
    EXPECT_EQ(a.betweens()[k].information, b.betweens()[k].information);
  }
  ASSERT_EQ(a.priors().size(), b.priors().size());
  ASSERT_EQ(a.observations().size(), b.observations().size());
  for (std::size_t k = 0; k < a.observations().size(); ++k) {
    EXPECT_EQ(a.observations()[k].z, b.observations()[k].z);
    EXPECT_LT((a.observations()[k].offset - b.observations()[k].offset).cwiseAbs().maxCoeff(), 1e-14);
  }
  EXPECT_NEAR(a.chi2(), b.chi2(), 1e-9 * std::max(1.0, a.chi2()));
}

template <class Poses, class Random>
void expect_round_trip(Random random_pose) {
  PoseGraph<Poses> graph;
  for (int k = 0; k < 8; ++k) graph.add_pose(10 + k, random_pose());
  graph.add_point(100, PoseGraph<Poses>::Point::Random());
  graph.fix(10);
  typename PoseGraph<Poses>::EdgeInformation information = PoseGraph<Poses>::EdgeInformation::Random();
  information = information * information.transpose() + PoseGraph<Poses>::EdgeInformation::Identity();
  for (int k = 0; k + 1 < 8; ++k) graph.add_between(10 + k, 11 + k, random_pose(), information);
  graph.add_between(17, 10, random_pose(), information);
  graph.add_pose_prior(12, random_pose(), information);
  const auto offset = Poses::kDim == 6 ? random_pose() : Poses::identity();
  graph.add_point_observation(13, 100, PoseGraph<Poses>::Point::Random(), PoseGraph<Poses>::PointInformation::Identity(), offset);
  const auto path = test::unique_temp_path("round_trip.g2o").string();
  io::write_g2o(path, graph);
  const auto read = io::read_pose_graph(path);
  std::filesystem::remove(path);
  EXPECT_EQ(read.format, "g2o");
  if constexpr (Poses::kDim == 3) expect_same_graph(graph, read.planar);
  else expect_same_graph(graph, read.spatial);
}

/// TORO holds poses and edges only; its 3D poses are Euler angles (read back to 1e-14) and its
/// information is rescaled by exact powers of two.
template <class Poses, class Random>
void expect_toro_round_trip(Random random_pose) {
  PoseGraph<Poses> graph;
  for (int k = 0; k < 8; ++k) graph.add_pose(k, random_pose());
  typename PoseGraph<Poses>::EdgeInformation information = PoseGraph<Poses>::EdgeInformation::Random();
  information = information * information.transpose() + PoseGraph<Poses>::EdgeInformation::Identity();
  for (int k = 0; k + 1 < 8; ++k) graph.add_between(k, k + 1, random_pose(), information);
  graph.add_between(7, 2, random_pose(), information);
  const auto path = test::unique_temp_path("round_trip.graph").string();
  io::write_toro(path, graph);
  const auto read = io::read_pose_graph(path);
  std::filesystem::remove(path);
  EXPECT_EQ(read.format, "TORO");
  if constexpr (Poses::kDim == 3) expect_same_graph(graph, read.planar);
  else expect_same_graph(graph, read.spatial);
  graph.add_point(99, PoseGraph<Poses>::Point::Zero());
  EXPECT_THROW(io::write_toro(path, graph), parse_error);
}

TEST(PoseGraphFile, WrittenToroReadsBackAsTheSameGraph) {
  expect_toro_round_trip<PlanarPoses>(random_planar);
  expect_toro_round_trip<SpatialPoses>(random_spatial);
}

TEST(PoseGraphFile, WrittenG2oReadsBackAsTheSameGraph) {
  expect_round_trip<PlanarPoses>(random_planar);
  expect_round_trip<SpatialPoses>(random_spatial);
}

/// A file of edges only (as manhattan.g2o) starts from dead reckoning along its odometry; the loop
/// closure does not place any pose.
TEST(PoseGraphFile, EdgesOnlyFileStartsFromItsOdometryChain) {
  const std::string info = " 1 0 0 1 0 1\n";
  const auto path = write_temp("edges_only.g2o", "EDGE_SE2 0 1 1 0 1.5707963267948966" + info + "EDGE_SE2 1 2 2 0 0" + info +
                                                    "EDGE_SE2 0 2 5 5 0" + info);
  const auto file = io::read_pose_graph(path);
  std::filesystem::remove(path);
  EXPECT_TRUE(file.spanning_tree_start);
  ASSERT_EQ(file.planar.num_poses(), 3u);
  EXPECT_LT((file.planar.pose(2) - Eigen::Vector3d(1, 2, M_PI / 2)).norm(), 1e-12);
}

/// MRPT's TORO file: EDGE2's information order is I11 I12 I22 I33 I13 I23.
TEST(PoseGraphFile, ToroEdgeInformationIsReadInToroOrder) {
  const auto path = write_temp("toro.graph", "VERTEX2 0 0 0 0\nVERTEX2 1 1 0 0\nEDGE2 0 1 1 0 0 4 1 5 6 2 3\n");
  const auto file = io::read_pose_graph(path);
  std::filesystem::remove(path);
  Eigen::Matrix3d expected;
  expected << 4, 1, 2, 1, 5, 3, 2, 3, 6;
  EXPECT_EQ(file.planar.betweens()[0].information, expected);
}

}  // namespace
}  // namespace sextant
