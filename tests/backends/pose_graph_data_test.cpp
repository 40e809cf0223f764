// The pose-graph benchmarks (../shared/data/pose_graphs; skipped without them): their sizes, one
// optimum from every start, and robust kernels against wrong loop closures.
#include <gtest/gtest.h>

#include <random>

#include "sextant/io/pose_graph_file.hpp"
#include "support/shared_data.hpp"

namespace sextant {
namespace {

std::string benchmark_file(const char* name) { return test::shared_data(std::string("pose_graphs/") + name + ".g2o"); }

TEST(PoseGraphBenchmarks, FilesReadWithTheirCounts) {
  SEXTANT_REQUIRE_DATA(benchmark_file("intel"));
  const auto intel = io::read_pose_graph(benchmark_file("intel"));
  EXPECT_EQ(intel.planar.num_poses(), 1728u);
  EXPECT_EQ(intel.planar.num_edges(), 2512u);
  const auto sphere = io::read_pose_graph(benchmark_file("sphere2500"));
  EXPECT_EQ(sphere.dimension, 3);
  EXPECT_EQ(sphere.spatial.num_poses(), 2500u);
  EXPECT_EQ(sphere.spatial.num_edges(), 4949u);
  const auto manhattan = io::read_pose_graph(benchmark_file("manhattan"));
  EXPECT_TRUE(manhattan.spanning_tree_start);
  EXPECT_EQ(manhattan.planar.num_poses(), 3500u);
  EXPECT_EQ(manhattan.planar.num_edges(), 5453u);
}

/// From the file's start (manhattan: its odometry) and from chordal relaxation, Levenberg-Marquardt
/// ends at the same chi2 (to its stopping tolerance, 1e-10 of the cost per step: bound 1e-6): on
/// these graphs neither start is caught in a local minimum that the other avoids.
TEST(PoseGraphBenchmarks, FileStartAndChordalStartReachOneOptimum) {
  SEXTANT_REQUIRE_DATA(benchmark_file("intel"));
  for (const char* name : {"intel", "manhattan", "parking-garage"}) {
    auto from_file = io::read_pose_graph(benchmark_file(name));
    auto from_chordal = io::read_pose_graph(benchmark_file(name));
    auto solve = [](io::PoseGraphFile& file, bool chordal) {
      if (file.dimension == 2) {
        if (chordal) file.planar.initialize_by_chordal_relaxation();
        return file.planar.optimize().final_chi2;
      }
      if (chordal) file.spatial.initialize_by_chordal_relaxation();
      return file.spatial.optimize().final_chi2;
    };
    const double a = solve(from_file, false), b = solve(from_chordal, true);
    EXPECT_NEAR(a, b, 1e-6 * a) << name;
  }
}

template <class Poses>
Eigen::Vector3d position(const typename Poses::Pose& x) {
  if constexpr (Poses::kDim == 3) return {x(0), x(1), 0.0};
  else return se3::translation(x);
}
template <class Poses>
double rmse(const PoseGraph<Poses>& a, const PoseGraph<Poses>& b) {
  double sum = 0.0;
  for (std::size_t k = 0; k < a.num_poses(); ++k) sum += (position<Poses>(a.poses()[k]) - position<Poses>(b.poses()[k])).squaredNorm();
  return std::sqrt(sum / static_cast<double>(a.num_poses()));
}

/// Every tenth loop closure replaced by a wrong one (a random pair of poses, a random measurement:
/// translation uniform in +-5 m, rotation uniform): the oracle is least squares without them (the
/// best any robust method can do, the replaced closures being lost); its distance from the clean
/// optimum is the reference. Least squares on the corrupted graph is pulled tens of metres away;
/// the Cauchy kernel (width 1) with the outlier gate (0.999) stays within 1.5x of the oracle's
/// distance (the bound), measured in docs/results/pose_graphs.md.
template <class Poses>
void expect_gated_cauchy_near_oracle(const PoseGraph<Poses>& start, const char* name) {
  PoseGraph<Poses> clean = start, corrupted, oracle;
  clean.optimize();
  for (const auto& v : start.vertices()) {
    corrupted.add_pose(v.id, start.poses()[v.slot]);
    oracle.add_pose(v.id, start.poses()[v.slot]);
  }
  std::mt19937 rng(1);
  std::uniform_int_distribution<std::size_t> pick(0, start.num_poses() - 1);
  std::uniform_real_distribution<double> metres(-5, 5), radians(-3.1, 3.1);
  std::size_t loops = 0;
  for (const auto& e : start.betweens()) {
    const VertexId from = start.pose_id(e.from), to = start.pose_id(e.to);
    if (e.edge_class == EdgeClass::loop_closure && loops++ % 10 == 0) {
      VertexId other;
      do other = start.pose_id(pick(rng));
      while (other == from || other == from + 1 || other + 1 == from);
      typename Poses::Pose z;
      if constexpr (Poses::kDim == 3) {
        z = Eigen::Vector3d(metres(rng), metres(rng), radians(rng));
      } else {
        se3::Vector6d xi;
        xi << metres(rng), metres(rng), metres(rng), radians(rng) / 2, radians(rng) / 2, radians(rng) / 2;
        z = se3::exp(xi);
      }
      corrupted.add_between(from, other, z, e.information);
      continue;
    }
    corrupted.add_between(from, to, e.z, e.information);
    oracle.add_between(from, to, e.z, e.information);
  }
  oracle.optimize();
  PoseGraph<Poses> plain = corrupted, robust = corrupted;
  plain.optimize();
  PoseGraphOptions options;
  options.loop_closure_loss = {RobustKernel::cauchy, 1.0};
  options.outlier_gate_probability = 0.999;
  robust.optimize(options);
  const double reference = rmse(oracle, clean);
  EXPECT_LT(rmse(robust, clean), 1.5 * reference) << name;
  EXPECT_GT(rmse(plain, clean), 10.0 * reference) << name << ": least squares was expected to break";
}

TEST(PoseGraphBenchmarks, GatedCauchyKernelSurvivesTenPercentWrongLoopClosures) {
  SEXTANT_REQUIRE_DATA(benchmark_file("intel"));
  expect_gated_cauchy_near_oracle(io::read_pose_graph(benchmark_file("intel")).planar, "intel");
  expect_gated_cauchy_near_oracle(io::read_pose_graph(benchmark_file("sphere2500")).spatial, "sphere2500");
}

}  // namespace
}  // namespace sextant
