// PoseGraph against the optimizers a pose-graph user would otherwise run, in the same test: MRPT's
// optimize_graph_spa_levmarq and Ceres in the formulation of its pose-graph examples
// (tests/support/*_pose_graph.hpp), from the same start, every final chi2 computed by one function;
// and the g2o files sextant writes, read by MRPT's own loader.
#include <gtest/gtest.h>

#include <random>

#include "sextant/io/pose_graph_file.hpp"
#include "support/ceres_pose_graph.hpp"
#include "support/mrpt_pose_graph.hpp"
#include "support/shared_data.hpp"

namespace sextant {
namespace {

/// sextant's optimum is at least as low as the lower of the peers' (to 1e-6 relative: the issue's
/// bound; the peers stop by their own tolerances).
template <class Poses>
void expect_at_least_as_low_as_peers(const PoseGraph<Poses>& start, const std::string& name) {
  PoseGraph<Poses> ours = start, mrpt = start, ceres = start;
  ours.optimize();
  test::solve_with_mrpt(mrpt);
  test::solve_with_ceres(ceres);
  const double best_peer = std::min(mrpt.chi2(), ceres.chi2());
  EXPECT_LE(ours.chi2(), best_peer * (1.0 + 1e-6)) << name << ": sextant " << ours.chi2() << ", MRPT " << mrpt.chi2()
                                                   << ", Ceres " << ceres.chi2();
}

TEST(PoseGraphPeers, ReachesAtLeastTheLowerChiSquareOfMrptAndCeres) {
  const std::string circle = "/usr/share/mrpt/datasets/graph_2d_circle_50nodes.graph";
  SEXTANT_REQUIRE_DATA(circle);
  expect_at_least_as_low_as_peers(io::read_pose_graph(circle).planar, "circle50");
  const auto intel = test::shared_data("pose_graphs/intel.g2o");
  SEXTANT_REQUIRE_DATA(intel);
  expect_at_least_as_low_as_peers(io::read_pose_graph(intel).planar, "intel");
  expect_at_least_as_low_as_peers(io::read_pose_graph(test::shared_data("pose_graphs/parking-garage.g2o")).spatial,
                                  "parking-garage");
}

/// A g2o or TORO file sextant writes loads in MRPT (CNetworkOfPoses::loadFromTextFile, what
/// `graph-slam` reads) with every node at the pose written and every edge.
template <class Poses, class Random>
void expect_mrpt_loads_written_file(Random random_pose) {
  PoseGraph<Poses> graph;
  for (int k = 0; k < 20; ++k) graph.add_pose(k, random_pose());
  typename PoseGraph<Poses>::EdgeInformation information = PoseGraph<Poses>::EdgeInformation::Identity();
  for (int k = 0; k + 1 < 20; ++k) graph.add_between(k, k + 1, random_pose(), information);
  graph.add_between(19, 3, random_pose(), information);
  for (const char* format : {"g2o", "graph"}) {
    const auto path = test::unique_temp_path(std::string("for_mrpt.") + format).string();
    if (std::string(format) == "g2o") io::write_g2o(path, graph);
    else io::write_toro(path, graph);
    test::MrptNetwork<Poses> network;
    network.loadFromTextFile(path, false);
    std::filesystem::remove(path);
    ASSERT_EQ(network.nodeCount(), 20u);
    EXPECT_EQ(network.edgeCount(), 20u);
    for (int k = 0; k < 20; ++k) {
      const auto& node = network.nodes.at(k);
      if constexpr (Poses::kDim == 3) {
        EXPECT_LT((Eigen::Vector3d(node.x(), node.y(), node.phi()) - graph.pose(k)).norm(), 1e-12);
      } else {
        EXPECT_LT((node.template getHomogeneousMatrixVal<mrpt::math::CMatrixDouble44>().asEigen() - graph.pose(k)).cwiseAbs().maxCoeff(), 1e-12);
      }
    }
  }
}

TEST(PoseGraphPeers, MrptLoadsTheG2oAndToroFilesSextantWrites) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3, 3);
  expect_mrpt_loads_written_file<PlanarPoses>([&] { return Eigen::Vector3d(u(rng), u(rng), u(rng)); });
  expect_mrpt_loads_written_file<SpatialPoses>([&] {
    se3::Vector6d xi;
    for (int i = 0; i < 6; ++i) xi(i) = u(rng) / 2;
    return Eigen::Matrix4d(se3::exp(xi));
  });
}

}  // namespace
}  // namespace sextant
