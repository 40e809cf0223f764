#pragma once
// MRPT's pose-graph optimizer as its users run it (the function behind `graph-slam --levmarq`):
// the graph loaded from a g2o file by CNetworkOfPoses{2D,3D}Inf::loadFromTextFile (with its
// default, which fuses duplicated edges), then mrpt::graphslam::optimize_graph_spa_levmarq with
// its default parameters (100 iterations, tau 1e-3, e1 = e2 = 1e-6), the root node (id 0) fixed.
// Never used by the library.
#include <mrpt/graphs/CNetworkOfPoses.h>
#include <mrpt/graphslam/levmarq.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "sextant/backends/pose_graph.hpp"
#include "sextant/io/pose_graph_file.hpp"
#include "support/temp_path.hpp"

namespace sextant::test {

struct MrptPoseGraphResult {
  std::size_t iterations = 0;
  double seconds = 0.0;  ///< optimize_graph_spa_levmarq alone (not the file)
  std::size_t edges = 0;  ///< after MRPT's loader fused duplicated edges
};

/// The MRPT network a g2o file loads into.
template <class Poses>
using MrptNetwork = std::conditional_t<Poses::kDim == 3, mrpt::graphs::CNetworkOfPoses2DInf, mrpt::graphs::CNetworkOfPoses3DInf>;

/// Writes the graph (at its current poses) as g2o, lets MRPT load and optimize it, and copies the
/// optimized poses back into the graph.
template <class Poses>
MrptPoseGraphResult solve_with_mrpt(PoseGraph<Poses>& graph) {
  const auto path = unique_temp_path("mrpt_peer.g2o").string();
  io::write_g2o(path, graph);
  MrptNetwork<Poses> network;
  network.loadFromTextFile(path);
  std::filesystem::remove(path);
  network.root = static_cast<mrpt::graphs::TNodeID>(graph.pose_id(0));
  MrptPoseGraphResult result;
  result.edges = network.edgeCount();
  mrpt::graphslam::TResultInfoSpaLevMarq info;
  const auto start = std::chrono::steady_clock::now();
  mrpt::graphslam::optimize_graph_spa_levmarq(network, info);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.iterations = info.num_iters;
  for (std::size_t k = 0; k < graph.num_poses(); ++k) {
    const auto& node = network.nodes.at(static_cast<mrpt::graphs::TNodeID>(graph.pose_id(k)));
    if constexpr (Poses::kDim == 3) {
      graph.set_pose(graph.pose_id(k), Eigen::Vector3d(node.x(), node.y(), node.phi()));
    } else {
      const Eigen::Matrix3d R = node.getRotationMatrix().asEigen();
      graph.set_pose(graph.pose_id(k), se3::make(R, Eigen::Vector3d(node.x(), node.y(), node.z())));
    }
  }
  return result;
}

}  // namespace sextant::test
