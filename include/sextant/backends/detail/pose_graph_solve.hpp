#pragma once
// PoseGraph: the normal equations, Levenberg-Marquardt and the spanning-tree start (see ../pose_graph.hpp).

#include <map>

#include "sextant/core/chi_square.hpp"

namespace sextant {

template <class Poses>
template <class Visit>
void PoseGraph<Poses>::visit_edge_vertices(Visit visit) const {
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  for (const auto& edge : betweens_) visit(pose_vertex_[edge.from], pose_vertex_[edge.to]);
  for (const auto& prior : priors_) visit(pose_vertex_[prior.pose], none);
  for (const auto& obs : observations_) visit(pose_vertex_[obs.pose], point_vertex_[obs.point]);
}

/// The pattern: each free vertex's column block holds its diagonal block and, below it, one block
/// per free neighbour with a larger offset; rows within a column sorted.
template <class Poses>
auto PoseGraph<Poses>::build_system() const -> System {
  constexpr std::size_t none = static_cast<std::size_t>(-1);
  System s;
  Eigen::Index dimension = 0;
  s.offset = variable_offsets(dimension);
  s.size.resize(vertices_.size());
  for (std::size_t v = 0; v < vertices_.size(); ++v) s.size[v] = vertices_[v].is_point ? P : D;
  std::vector<std::vector<std::size_t>> below(vertices_.size());  // per column vertex: row vertices
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (s.offset[v] >= 0) below[v].push_back(v);
  visit_edge_vertices([&](std::size_t a, std::size_t b) {
    if (b == none || s.offset[a] < 0 || s.offset[b] < 0) return;
    if (s.offset[a] < s.offset[b]) below[a].push_back(b);
    else below[b].push_back(a);
  });
  std::vector<std::map<std::size_t, Eigen::Index>> rowpos(vertices_.size());
  std::vector<Eigen::Index> outer(static_cast<std::size_t>(dimension) + 1, 0);
  std::vector<int> inner;
  std::vector<std::size_t> columns;  // the free vertices by offset: H's columns are filled in order
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    if (s.offset[v] >= 0) columns.push_back(v);
  std::sort(columns.begin(), columns.end(), [&](std::size_t x, std::size_t y) { return s.offset[x] < s.offset[y]; });
  for (std::size_t v : columns) {
    auto& rows = below[v];
    std::sort(rows.begin(), rows.end(), [&](std::size_t x, std::size_t y) { return s.offset[x] < s.offset[y]; });
    rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
    Eigen::Index height = 0;
    for (std::size_t r : rows) {
      rowpos[v][r] = height;
      height += s.size[r];
    }
    for (int k = 0; k < s.size[v]; ++k) {
      const Eigen::Index column = s.offset[v] + k;
      outer[column + 1] = outer[column] + height;
      for (std::size_t r : rows)
        for (int i = 0; i < s.size[r]; ++i) inner.push_back(static_cast<int>(s.offset[r] + i));
    }
  }
  s.H.resize(dimension, dimension);
  s.H.resizeNonZeros(static_cast<Eigen::Index>(inner.size()));
  std::copy(outer.begin(), outer.end(), s.H.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), s.H.innerIndexPtr());
  s.b.resize(dimension);
  s.diagonal.resize(static_cast<std::size_t>(dimension));
  for (std::size_t v = 0; v < vertices_.size(); ++v)
    for (int k = 0; s.offset[v] >= 0 && k < s.size[v]; ++k)
      s.diagonal[s.offset[v] + k] = outer[s.offset[v] + k] + rowpos[v][v] + k;
  visit_edge_vertices([&](std::size_t a, std::size_t b) {
    typename System::Slots slot{a, b};
    if (s.offset[a] >= 0) slot.aa = rowpos[a][a];
    if (b != none && s.offset[b] >= 0) {
      slot.bb = rowpos[b][b];
      if (s.offset[a] >= 0) slot.ab = s.offset[a] < s.offset[b] ? rowpos[a][b] : rowpos[b][a];
    }
    s.slots.push_back(slot);
  });
  return s;
}

/// H += J^T W J and b -= J^T W e for an edge on one or two vertices (fixed ones left out).
template <class Poses>
template <class JA, class JB, class W, class Err>
void PoseGraph<Poses>::add_edge(System& s, const typename System::Slots& slot, const JA& Ja, const JB& Jb, const W& w,
                                const Err& e) {
  const bool free_a = slot.aa >= 0, free_b = slot.bb >= 0;
  if (free_a) {
    const auto JaT_W = (Ja.transpose() * w).eval();
    s.add(slot.va, slot.aa, (JaT_W * Ja).eval());
    s.b.segment(s.offset[slot.va], Ja.cols()) -= JaT_W * e;
    if (free_b) {
      if (s.offset[slot.va] < s.offset[slot.vb])
        s.add(slot.va, slot.ab, (Jb.transpose() * w * Ja).eval());
      else
        s.add(slot.vb, slot.ab, (JaT_W * Jb).eval());
    }
  }
  if (free_b) {
    const auto JbT_W = (Jb.transpose() * w).eval();
    s.add(slot.vb, slot.bb, (JbT_W * Jb).eval());
    s.b.segment(s.offset[slot.vb], Jb.cols()) -= JbT_W * e;
  }
}

/// The normal equations at the current estimate, each edge's information scaled by its kernel's
/// weight rho'(e^T Omega e) (iteratively reweighted least squares).
template <class Poses>
void PoseGraph<Poses>::linearize(System& s, const PoseGraphOptions& options) const {
  std::fill(s.H.valuePtr(), s.H.valuePtr() + s.H.nonZeros(), 0.0);
  s.b.setZero();
  std::size_t next = 0;
  for (const auto& edge : betweens_) {
    if (edge.rejected) {
      ++next;
      continue;
    }
    const auto lin = Poses::linearize_between(poses_[edge.from], poses_[edge.to], edge.z);
    const RobustLoss& loss = edge.edge_class == EdgeClass::odometry ? options.odometry_loss : options.loop_closure_loss;
    const EdgeInformation w = loss.weight(lin.error.dot(edge.information * lin.error)) * edge.information;
    add_edge(s, s.slots[next++], lin.J_from, lin.J_to, w, lin.error);
  }
  for (const auto& prior : priors_) {
    const auto lin = Poses::linearize_between(Poses::identity(), poses_[prior.pose], prior.z);
    add_edge(s, s.slots[next++], lin.J_to, lin.J_to, prior.information, lin.error);
  }
  for (const auto& obs : observations_) {
    const auto lin = [&] {
      if constexpr (P == 3)
        return Poses::linearize_point(poses_[obs.pose], points_[obs.point], obs.z, obs.offset);
      else
        return Poses::linearize_point(poses_[obs.pose], points_[obs.point], obs.z);
    }();
    const PointInformation w = options.point_loss.weight(lin.error.dot(obs.information * lin.error)) * obs.information;
    add_edge(s, s.slots[next++], lin.J_pose, lin.J_point, w, lin.error);
  }
}

template <class Poses>
void PoseGraph<Poses>::apply_step(const System& s, const Eigen::VectorXd& delta, std::vector<Pose>& poses,
                                  std::vector<Point>& points) const {
  for (std::size_t v = 0; v < vertices_.size(); ++v) {
    if (s.offset[v] < 0) continue;
    const Vertex& vertex = vertices_[v];
    if (vertex.is_point)
      points[vertex.slot] += delta.template segment<P>(s.offset[v]);
    else
      poses[vertex.slot] = Poses::plus(poses[vertex.slot], delta.template segment<D>(s.offset[v]));
  }
}

/// Levenberg-Marquardt with Nielsen's update of the damping (as Ceres and g2o): a step d solves
/// (H + lambda diag(H)) d = b; its gain ratio rho = (actual decrease) / (decrease the quadratic
/// model predicts, d^T b + lambda d^T diag(H) d) decides whether it is taken and how lambda moves.
template <class Poses>
PoseGraphSummary PoseGraph<Poses>::optimize(const PoseGraphOptions& options) {
  using Clock = std::chrono::steady_clock;
  const auto began = Clock::now();
  options.odometry_loss.validate();
  options.loop_closure_loss.validate();
  options.point_loss.validate();
  if (options.max_iterations < 0) throw invalid_input_error("PoseGraphOptions: max_iterations must be >= 0");
  if (!(options.outlier_gate_probability >= 0.0 && options.outlier_gate_probability < 1.0))
    throw invalid_input_error("PoseGraphOptions: outlier_gate_probability must be in [0, 1)");
  const std::vector<Vertex> vertices_before = vertices_;
  const std::vector<Pose> poses_before = poses_;
  const std::vector<Point> points_before = points_;
  const std::vector<Between> betweens_before = betweens_;
  try {
    hold_gauge_if_free();
    for (auto& edge : betweens_) edge.rejected = false;
    PoseGraphSummary summary;
    summary.initial_chi2 = chi2();
    summary.initial_cost = cost(options);
    descend(options, summary, began);
    if (options.outlier_gate_probability > 0.0 && reject_outliers(options, summary) > 0) {
      PoseGraphOptions plain = options;  // the outliers gone, least squares on what is left
      plain.odometry_loss = plain.loop_closure_loss = RobustLoss{};
      descend(plain, summary, began);
    }
    summary.final_chi2 = chi2();
    summary.seconds = std::chrono::duration<double>(Clock::now() - began).count();
    return summary;
  } catch (...) {  // bit for bit as before, the gauge's hold included
    vertices_ = vertices_before;
    poses_ = poses_before;
    points_ = points_before;
    betweens_ = betweens_before;
    throw;
  }
}

/// Switches off the edges of the classes with a robust kernel whose chi2 at the current estimate
/// is beyond the outlier gate; returns how many.
template <class Poses>
std::size_t PoseGraph<Poses>::reject_outliers(const PoseGraphOptions& options, PoseGraphSummary& summary) {
  const double gate = chi_square_quantile(E, options.outlier_gate_probability);
  std::size_t count = 0;
  for (auto& edge : betweens_) {
    const RobustLoss& loss = edge.edge_class == EdgeClass::odometry ? options.odometry_loss : options.loop_closure_loss;
    if (loss.kernel == RobustKernel::none || edge.rejected) continue;
    const auto e = Poses::between_error(poses_[edge.from], poses_[edge.to], edge.z);
    if (e.dot(edge.information * e) > gate) {
      edge.rejected = true;
      ++count;
    }
  }
  summary.rejected_edges += count;
  return count;
}

/// One damped step from the current estimate: (H + lambda D) d = b with D = diag(H) clamped, the
/// trial estimate and its cost, and the gain ratio (actual / predicted decrease; -1 when no step).
template <class Poses>
struct PoseGraph<Poses>::Trial {
  bool solved = false;
  double cost = std::numeric_limits<double>::infinity(), predicted = 0.0, gain = -1.0;
  std::vector<Pose> poses;
  std::vector<Point> points;
};

template <class Poses>
auto PoseGraph<Poses>::try_step(System& s, const Eigen::VectorXd& diagonal, double lambda, double current,
                                const PoseGraphOptions& options, PoseGraphSummary& summary) -> Trial {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const Eigen::VectorXd scaled = diagonal.cwiseMax(1e-6).cwiseMin(1e32);
  double* H = s.H.valuePtr();
  for (Eigen::Index i = 0; i < s.H.rows(); ++i) H[s.diagonal[i]] = diagonal(i) + lambda * scaled(i);
  Trial trial;
  Eigen::VectorXd delta;
  try {
    solver_.factorize(s.H);
    delta = solver_.solve(s.b);
    trial.solved = delta.allFinite();
  } catch (const numerical_error&) {
    trial.solved = false;
  }
  for (Eigen::Index i = 0; i < s.H.rows(); ++i) H[s.diagonal[i]] = diagonal(i);
  const auto solved_at = Clock::now();
  summary.seconds_solve += std::chrono::duration<double>(solved_at - start).count();
  if (!trial.solved) return trial;
  trial.poses = poses_;
  trial.points = points_;
  apply_step(s, delta, trial.poses, trial.points);
  trial.cost = cost_at(trial.poses, trial.points, options);
  trial.predicted = delta.dot(s.b) + lambda * delta.dot(scaled.cwiseProduct(delta));
  if (std::isfinite(trial.cost) && trial.predicted > 0.0) trial.gain = (current - trial.cost) / trial.predicted;
  summary.seconds_evaluate += std::chrono::duration<double>(Clock::now() - solved_at).count();
  return trial;
}

/// The normal equations at the current estimate and their diagonal; false when the gradient is
/// already below the tolerance.
template <class Poses>
bool PoseGraph<Poses>::relinearize(System& s, Eigen::VectorXd& diagonal, const PoseGraphOptions& options,
                                   PoseGraphSummary& summary) const {
  const auto start = std::chrono::steady_clock::now();
  linearize(s, options);
  diagonal.resize(s.H.rows());
  for (Eigen::Index i = 0; i < s.H.rows(); ++i) diagonal(i) = s.H.valuePtr()[s.diagonal[i]];
  summary.seconds_linearize += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s.b.cwiseAbs().maxCoeff() > options.gradient_tolerance;
}

/// Levenberg-Marquardt from the current estimate, adding to `summary` (iterations, costs, times).
template <class Poses>
void PoseGraph<Poses>::descend(const PoseGraphOptions& options, PoseGraphSummary& summary,
                               std::chrono::steady_clock::time_point began) {
  auto record = [&](double cost) {
    summary.cost.push_back(cost);
    summary.cost_at.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count());
  };
  auto stop = [&](const char* why) {
    summary.converged = true;
    summary.stop_reason = why;
  };
  double current = cost(options);
  record(current);
  if (!std::isfinite(current)) throw numerical_error("pose graph: the initial cost is not finite");
  summary.converged = false;
  summary.stop_reason.clear();
  System s = build_system();
  if (s.H.rows() == 0) stop("no free vertices");
  double lambda = options.initial_lambda, nu = 2.0;
  bool linearized = false;
  Eigen::VectorXd diagonal;
  for (int iteration = 0; s.H.rows() > 0 && iteration < options.max_iterations; ++iteration) {
    if (!linearized && !(linearized = relinearize(s, diagonal, options, summary))) {
      stop("gradient below tolerance");
      break;
    }
    ++summary.iterations;
    Trial trial = try_step(s, diagonal, lambda, current, options, summary);
    if (trial.gain > 0.0) {  // taken: Nielsen's update of the damping
      poses_.swap(trial.poses);
      points_.swap(trial.points);
      const double decrease = current - trial.cost;
      record(current = trial.cost);
      ++summary.accepted;
      lambda *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * trial.gain - 1.0, 3));
      nu = 2.0;
      linearized = false;
      if (decrease <= options.function_tolerance * current) {
        stop("cost change below tolerance");
        break;
      }
    } else if (trial.solved && trial.predicted <= 1e-14 * current) {  // flat to the cost's rounding
      stop("predicted decrease below the rounding of the cost");
      break;
    } else if (!((lambda *= nu) < 1e32)) {
      if (!trial.solved) throw numerical_error("pose graph: the damped normal equations cannot be factorized");
      stop("no step lowers the cost (damping at its limit)");
      break;
    } else {
      nu *= 2.0;
    }
  }
  if (summary.stop_reason.empty()) summary.stop_reason = "iteration limit";
  summary.final_cost = current;
}

/// Places poses from the held vertices outwards: odometry edges first, so that a chain of odometry
/// is followed as dead reckoning, then any edge into the rest; points from their first observation.
template <class Poses>
void PoseGraph<Poses>::initialize_by_spanning_tree() {
  hold_gauge_if_free();
  std::vector<bool> placed(poses_.size(), false);
  for (std::size_t slot = 0; slot < poses_.size(); ++slot)
    placed[slot] = vertices_[pose_vertex_[slot]].fixed;
  for (const auto& prior : priors_)
    if (!placed[prior.pose]) {
      poses_[prior.pose] = prior.z;
      placed[prior.pose] = true;
    }
  std::vector<std::vector<std::size_t>> adjacent(poses_.size());  // edge indices
  for (std::size_t k = 0; k < betweens_.size(); ++k) {
    adjacent[betweens_[k].from].push_back(k);
    adjacent[betweens_[k].to].push_back(k);
  }
  auto grow = [&](bool odometry_only) {
    std::deque<std::size_t> frontier;
    for (std::size_t slot = 0; slot < poses_.size(); ++slot)
      if (placed[slot]) frontier.push_back(slot);
    bool grew = false;
    while (!frontier.empty()) {
      const std::size_t at = frontier.front();
      frontier.pop_front();
      for (std::size_t k : adjacent[at]) {
        const Between& edge = betweens_[k];
        if (edge.rejected || (odometry_only && edge.edge_class != EdgeClass::odometry)) continue;
        const std::size_t other = edge.from == at ? edge.to : edge.from;
        if (placed[other]) continue;
        poses_[other] = edge.from == at ? Poses::compose(poses_[at], edge.z)
                                        : Poses::compose(poses_[at], Poses::inverse(edge.z));
        placed[other] = grew = true;
        if (odometry_only) frontier.push_back(other);
      }
    }
    return grew;
  };
  while (grow(true) || grow(false)) {
  }
  initialize_points_from_first_observations();
}

template <class Poses>
void PoseGraph<Poses>::initialize_points_from_first_observations() {
  std::vector<bool> seen(points_.size(), false);
  for (const auto& obs : observations_) {
    if (seen[obs.point] || vertices_[point_vertex_[obs.point]].fixed) continue;
    seen[obs.point] = true;
    const Pose sensor = Poses::compose(poses_[obs.pose], obs.offset);
    if constexpr (P == 3)
      points_[obs.point] = se3::rotation(sensor) * obs.z + se3::translation(sensor);
    else
      points_[obs.point] = PlanarPoses::rotation(sensor(2)) * obs.z + sensor.template head<2>();
  }
}

}  // namespace sextant

#include "sextant/backends/detail/pose_graph_chordal.hpp"
