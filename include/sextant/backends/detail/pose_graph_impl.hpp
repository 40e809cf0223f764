#pragma once
// Bodies of PoseGraph (see ../pose_graph.hpp).

#include <Eigen/Cholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <string>
#include <utility>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

template <class Poses>
void PoseGraph<Poses>::require_new_id(VertexId id) const {
  if (index_.contains(id)) throw invalid_input_error("vertex " + std::to_string(id) + " is defined twice");
}

template <class Poses>
std::size_t PoseGraph<Poses>::vertex_of(VertexId id) const {
  const auto it = index_.find(id);
  if (it == index_.end()) throw invalid_input_error("unknown vertex " + std::to_string(id));
  return it->second;
}

template <class Poses>
std::size_t PoseGraph<Poses>::slot_of(VertexId id, bool is_point) const {
  const Vertex& v = vertices_[vertex_of(id)];
  if (v.is_point != is_point)
    throw invalid_input_error("vertex " + std::to_string(id) + " is a " + (v.is_point ? "point" : "pose") + ", not a " +
                              (is_point ? "point" : "pose"));
  return v.slot;
}

template <class Poses>
void PoseGraph<Poses>::add_pose(VertexId id, const Pose& initial) {
  add_vertex(id, Poses::is_finite(initial), poses_, initial, pose_vertex_, false);
}

template <class Poses>
void PoseGraph<Poses>::add_point(VertexId id, const Point& initial) {
  add_vertex(id, initial.allFinite(), points_, initial, point_vertex_, true);
}

/// A new vertex at the end of `values` (poses or points), with its slot's vertex recorded.
template <class Poses>
template <class Value>
void PoseGraph<Poses>::add_vertex(VertexId id, bool finite, std::vector<Value>& values, const Value& initial,
                                  std::vector<std::size_t>& slot_vertex, bool is_point) {
  require_new_id(id);
  if (!finite)
    throw invalid_input_error(std::string(is_point ? "point " : "pose ") + std::to_string(id) + " contains NaN or Inf");
  index_.emplace(id, vertices_.size());
  slot_vertex.push_back(vertices_.size());
  vertices_.push_back({id, is_point, values.size(), false});
  values.push_back(initial);
}

template <class Poses>
void PoseGraph<Poses>::fix(VertexId id) {
  vertices_[vertex_of(id)].fixed = true;
}

template <class Poses>
void PoseGraph<Poses>::add_between(VertexId from, VertexId to, const Pose& z, const EdgeInformation& information) {
  const std::string what = "edge " + std::to_string(from) + " -> " + std::to_string(to);
  const std::size_t a = slot_of(from, false), b = slot_of(to, false);
  if (a == b) throw invalid_input_error(what + ": joins a pose to itself");
  if (!Poses::is_finite(z)) throw invalid_input_error(what + ": measurement contains NaN or Inf");
  require_symmetric_positive_definite<E>(information, what + ": information matrix");
  const EdgeClass edge_class = (to == from + 1 || from == to + 1) ? EdgeClass::odometry : EdgeClass::loop_closure;
  betweens_.push_back({a, b, z, symmetrized(information), edge_class, false});
}

template <class Poses>
void PoseGraph<Poses>::add_pose_prior(VertexId pose, const Pose& z, const EdgeInformation& information) {
  const std::string what = "prior on pose " + std::to_string(pose);
  const std::size_t a = slot_of(pose, false);
  if (!Poses::is_finite(z)) throw invalid_input_error(what + ": measurement contains NaN or Inf");
  require_symmetric_positive_definite<E>(information, what + ": information matrix");
  priors_.push_back({a, z, symmetrized(information)});
}

template <class Poses>
void PoseGraph<Poses>::add_point_observation(VertexId pose, VertexId point, const Point& z,
                                             const PointInformation& information, const Pose& offset) {
  const std::string what = "observation of point " + std::to_string(point) + " from pose " + std::to_string(pose);
  const std::size_t a = slot_of(pose, false), b = slot_of(point, true);
  if (!z.allFinite() || !Poses::is_finite(offset)) throw invalid_input_error(what + ": measurement contains NaN or Inf");
  require_symmetric_positive_definite<P>(information, what + ": information matrix");
  observations_.push_back({a, b, z, symmetrized(information), offset});
}

template <class Poses>
double PoseGraph<Poses>::chi2() const {
  PoseGraphOptions plain;
  return cost(plain);
}

template <class Poses>
double PoseGraph<Poses>::cost_at(const std::vector<Pose>& poses, const std::vector<Point>& points,
                                 const PoseGraphOptions& options) const {
  double total = 0.0;
  for (const auto& edge : betweens_) {
    if (edge.rejected) continue;
    const auto e = Poses::between_error(poses[edge.from], poses[edge.to], edge.z);
    const RobustLoss& loss = edge.edge_class == EdgeClass::odometry ? options.odometry_loss : options.loop_closure_loss;
    total += loss.cost(e.dot(edge.information * e));
  }
  for (const auto& prior : priors_) {
    const auto e = Poses::between_error(Poses::identity(), poses[prior.pose], prior.z);
    total += e.dot(prior.information * e);
  }
  for (const auto& obs : observations_) {
    const Point e = [&] {
      if constexpr (P == 3)
        return Poses::point_error(poses[obs.pose], points[obs.point], obs.z, obs.offset);
      else
        return Poses::point_error(poses[obs.pose], points[obs.point], obs.z);
    }();
    total += options.point_loss.cost(e.dot(obs.information * e));
  }
  return total;
}

/// The normal equations H d = b over the free vertices, H's lower triangle (and whole diagonal
/// blocks) in one compressed column matrix whose pattern is built once: every edge adds its blocks
/// at positions found when the pattern was built, so assembling is a pass over the edges.
template <class Poses>
struct PoseGraph<Poses>::System {
  std::vector<Eigen::Index> offset;  ///< per vertex; -1 when fixed
  std::vector<int> size;             ///< per vertex: D or P
  Eigen::SparseMatrix<double> H;
  Eigen::VectorXd b;
  /// Where each edge's blocks start in their columns, in the order edges are visited: the two
  /// diagonal blocks and the off-diagonal one (-1 where a vertex is fixed or absent).
  struct Slots {
    std::size_t va, vb;
    Eigen::Index aa = -1, bb = -1, ab = -1;
  };
  std::vector<Slots> slots;
  std::vector<Eigen::Index> diagonal;  ///< per row: where H(i, i) is in H's values

  /// Adds M (rows of vertex r, columns of vertex c) at a block starting `rowpos` into c's columns.
  template <class Matrix>
  void add(std::size_t c, Eigen::Index rowpos, const Matrix& M) {
    double* values = H.valuePtr();
    const auto* outer = H.outerIndexPtr();
    for (Eigen::Index k = 0; k < M.cols(); ++k) {
      double* column = values + outer[offset[c] + k] + rowpos;
      for (Eigen::Index i = 0; i < M.rows(); ++i) column[i] += M(i, k);
    }
  }
};

/// Offsets of the free vertices in the system, in the order they were added (the factorization
/// orders the system for fill itself).
template <class Poses>
std::vector<Eigen::Index> PoseGraph<Poses>::variable_offsets(Eigen::Index& dimension) const {
  std::vector<Eigen::Index> offset(vertices_.size(), -1);
  dimension = 0;
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (!vertices_[v].fixed) {
      offset[v] = dimension;
      dimension += vertices_[v].is_point ? P : D;
    }
  return offset;
}

template <class Poses>
void PoseGraph<Poses>::hold_gauge_if_free() {
  const bool held = priors_.size() > 0 || std::any_of(vertices_.begin(), vertices_.end(), [](const Vertex& v) { return v.fixed; });
  if (!held && !pose_vertex_.empty()) vertices_[pose_vertex_.front()].fixed = true;
}

}  // namespace sextant

#include "sextant/backends/detail/pose_graph_solve.hpp"
