#pragma once
/// \file A pose-graph optimizer: poses on SE(2) or SE(3) (backends/pose_graph_edges.hpp), points,
/// between edges (odometry and loop closures) with full information matrices, pose priors, point
/// observations and fixed vertices, solved by Levenberg-Marquardt on the library's one sparse
/// factorization path (core/sparse_cholesky.hpp) with a robust kernel per edge class. The graph a
/// g2o or TORO file holds (io/pose_graph_file.hpp); sextant-run --dataset FILE.g2o runs it.

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <chrono>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include "sextant/backends/pose_graph_edges.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/robust_kernel.hpp"
#include "sextant/core/sparse_cholesky.hpp"

namespace sextant {

using VertexId = std::int64_t;

/// Which robust kernel an edge gets: odometry joins consecutive ids, a loop closure any other pair.
enum class EdgeClass { odometry, loop_closure, point, prior };

struct PoseGraphOptions {
  int max_iterations = 100;
  /// Stop when an accepted step lowers the cost by less than this fraction of it (Ceres's
  /// function_tolerance, 1e-6 by default there; tighter here, steps are cheap beside a restart).
  double function_tolerance = 1e-10;
  double gradient_tolerance = 1e-10;  ///< stop when max |gradient| falls below this
  double initial_lambda = 1e-4;       ///< damping of the first step: (H + lambda D) d = -g, D = diag(H)
  RobustLoss odometry_loss{}, loop_closure_loss{}, point_loss{};
  /// In (0, 1): after the robust optimization, the edges of a class with a kernel whose chi2 is
  /// beyond this quantile (of a chi-square with the edge's dimension) are switched off as outliers
  /// and the rest is optimized again by least squares: the kernel finds the outliers, least
  /// squares without them is not biased by their residual pull (which the Cauchy kernel keeps).
  /// 0 = off (the kernel's solution).
  double outlier_gate_probability = 0.0;
};

/// What optimize() reports.
struct PoseGraphSummary {
  double initial_chi2 = 0.0, final_chi2 = 0.0;  ///< plain chi2 (robust kernels not applied)
  double initial_cost = 0.0, final_cost = 0.0;  ///< what was minimized (chi2 through the kernels)
  int iterations = 0;                            ///< steps tried, accepted or not
  int accepted = 0;
  std::size_t rejected_edges = 0;  ///< switched off by the outlier gate (Between::rejected)
  bool converged = false;
  std::string stop_reason;
  double seconds = 0.0;
  /// Where the time went: building the normal equations, factorizing and solving them (the
  /// symbolic analysis once, in the first), evaluating the cost of trial steps.
  double seconds_linearize = 0.0, seconds_solve = 0.0, seconds_evaluate = 0.0;
  std::vector<double> cost;     ///< after every accepted step, starting with the initial cost
  std::vector<double> cost_at;  ///< seconds since optimize() began at which each entry of cost was reached
};

template <class Poses>
class PoseGraph {
 public:
  static constexpr int D = Poses::kDim, P = Poses::kPointDim, E = Poses::kEdgeDim;
  using Pose = typename Poses::Pose;
  using Point = typename Poses::Point;
  using EdgeInformation = Eigen::Matrix<double, E, E>;
  using PointInformation = Eigen::Matrix<double, P, P>;

  /// Adds a vertex; throws invalid_input_error for an id used before or a non-finite value.
  void add_pose(VertexId id, const Pose& initial);
  void add_point(VertexId id, const Point& initial);
  /// Holds the vertex where it is (g2o's FIX). Throws for an unknown id.
  void fix(VertexId id);
  /// X_i^-1 X_j measured as z with information `information` (symmetric positive definite; kept
  /// as (Omega + Omega^T) / 2, exactly symmetric). Throws for unknown ids, i == j, non-finite
  /// values or an information that is not symmetric (to 1e-9) and positive definite.
  void add_between(VertexId from, VertexId to, const Pose& z, const EdgeInformation& information);
  /// X measured as z.
  void add_pose_prior(VertexId pose, const Pose& z, const EdgeInformation& information);
  /// The point seen from the pose (through the sensor offset on SE(3)) at z.
  void add_point_observation(VertexId pose, VertexId point, const Point& z, const PointInformation& information,
                             const Pose& offset = Poses::identity());

  /// Levenberg-Marquardt from the current estimate. Without a fixed vertex or a prior, the first
  /// pose added is held (the gauge). Throws numerical_error when the damped system cannot be
  /// factorized even with heavy damping; the graph is then as it was.
  PoseGraphSummary optimize(const PoseGraphOptions& options = {});

  /// Places every pose that is not held (fixed, or the gauge) by a spanning tree: from the held
  /// vertices and the priors out along odometry edges first (a chain of odometry is followed as
  /// dead reckoning), then through any edge, composing the measurements; points from their first
  /// observation. For graphs whose vertex values are missing or far off.
  void initialize_by_spanning_tree();
  /// Places every pose that is not held by chordal relaxation (rotations from a linear least
  /// squares over all edges projected to SO(d), then translations; Carlone et al. 2015): a start
  /// that does not follow the odometry's drift, for graphs where a spanning tree's start ends in a
  /// local minimum. Throws numerical_error when some pose is not connected to a held one.
  void initialize_by_chordal_relaxation();

  /// sum e^T Omega e over every edge at the current estimate (the g2o chi2).
  double chi2() const;
  /// sum rho(e^T Omega e) with each edge class's kernel.
  double cost(const PoseGraphOptions& options) const { return cost_at(poses_, points_, options); }

  std::size_t num_poses() const { return poses_.size(); }
  std::size_t num_points() const { return points_.size(); }
  std::size_t num_edges() const { return betweens_.size() + priors_.size() + observations_.size(); }
  const Pose& pose(VertexId id) const { return poses_[slot_of(id, false)]; }
  const Point& point(VertexId id) const { return points_[slot_of(id, true)]; }
  void set_pose(VertexId id, const Pose& value) { poses_[slot_of(id, false)] = value; }
  bool has_vertex(VertexId id) const { return index_.contains(id); }
  bool is_fixed(VertexId id) const { return vertices_[vertex_of(id)].fixed; }

  struct Vertex {
    VertexId id;
    bool is_point;
    std::size_t slot;  ///< in poses_ or points_
    bool fixed = false;
  };
  struct Between {
    std::size_t from, to;  ///< pose slots
    Pose z;
    EdgeInformation information;
    EdgeClass edge_class;
    bool rejected = false;  ///< switched off by the last optimize()'s outlier gate
  };
  struct Prior {
    std::size_t pose;
    Pose z;
    EdgeInformation information;
  };
  struct Observation {
    std::size_t pose, point;  ///< slots
    Point z;
    PointInformation information;
    Pose offset;
  };
  const std::vector<Vertex>& vertices() const { return vertices_; }
  const std::vector<Between>& betweens() const { return betweens_; }
  const std::vector<Prior>& priors() const { return priors_; }
  const std::vector<Observation>& observations() const { return observations_; }
  const std::vector<Pose>& poses() const { return poses_; }
  const std::vector<Point>& points() const { return points_; }
  VertexId pose_id(std::size_t slot) const { return vertices_[pose_vertex_[slot]].id; }
  VertexId point_id(std::size_t slot) const { return vertices_[point_vertex_[slot]].id; }

 private:
  struct System;  // the sparse normal equations' layout and values (implementation)

  std::size_t vertex_of(VertexId id) const;
  std::size_t slot_of(VertexId id, bool is_point) const;
  void require_new_id(VertexId id) const;
  template <class Value>
  void add_vertex(VertexId id, bool finite, std::vector<Value>& values, const Value& initial,
                  std::vector<std::size_t>& slot_vertex, bool is_point);
  std::vector<Eigen::Index> variable_offsets(Eigen::Index& dimension) const;
  void hold_gauge_if_free();
  void initialize_points_from_first_observations();
  template <class Visit>
  void visit_edge_vertices(Visit visit) const;
  System build_system() const;
  void descend(const PoseGraphOptions& options, PoseGraphSummary& summary, std::chrono::steady_clock::time_point began);
  struct Trial;
  Trial try_step(System& s, const Eigen::VectorXd& diagonal, double lambda, double current, const PoseGraphOptions& options,
                 PoseGraphSummary& summary);
  bool relinearize(System& s, Eigen::VectorXd& diagonal, const PoseGraphOptions& options, PoseGraphSummary& summary) const;
  std::size_t reject_outliers(const PoseGraphOptions& options, PoseGraphSummary& summary);
  template <class JA, class JB, class W, class Err>
  static void add_edge(System& s, const typename System::Slots& slot, const JA& Ja, const JB& Jb, const W& w,
                       const Err& e);
  void linearize(System& s, const PoseGraphOptions& options) const;
  void apply_step(const System& s, const Eigen::VectorXd& delta, std::vector<Pose>& poses, std::vector<Point>& points) const;
  double cost_at(const std::vector<Pose>& poses, const std::vector<Point>& points, const PoseGraphOptions& options) const;

  std::vector<Vertex> vertices_;
  std::unordered_map<VertexId, std::size_t> index_;
  std::vector<Pose> poses_;
  std::vector<Point> points_;
  std::vector<std::size_t> pose_vertex_, point_vertex_;  ///< slot -> vertex
  std::vector<Between> betweens_;
  std::vector<Prior> priors_;
  std::vector<Observation> observations_;
  SparseCholesky solver_{SparseCholesky::Factorization::by_fill};
};

}  // namespace sextant

#include "sextant/backends/detail/pose_graph_impl.hpp"
