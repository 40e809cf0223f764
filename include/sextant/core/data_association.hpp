#pragma once
/// \file Data association for measurements without landmark ids (thesis §7.2): individual
/// compatibility by the Mahalanobis distance of each measurement to each landmark, then either
/// nearest neighbour or joint compatibility branch and bound (JCBB; Neira & Tardós, IEEE Trans.
/// Robotics and Automation 17(6), 2001). Works on a JointMarginal, so every back-end that can give
/// the joint Gaussian of its robot and landmarks (EKF, SEIF) uses the same code.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "sextant/core/chi_square.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/joint_marginal.hpp"
#include "sextant/core/linearized_observation.hpp"
#include "sextant/core/observation.hpp"
#include "sextant/core/validation.hpp"

namespace sextant {

enum class AssociationMethod {
  /// Each measurement takes the individually compatible landmark nearest in Mahalanobis distance;
  /// pairs are assigned in increasing distance, one measurement per landmark.
  nearest_neighbour,
  /// The hypothesis with the most pairings whose innovations are jointly compatible (one
  /// chi-square test on the stacked innovation with its full covariance), the smallest joint NIS
  /// among those; found by branch and bound.
  joint_compatibility,
};

struct AssociationOptions {
  AssociationMethod method = AssociationMethod::joint_compatibility;
  /// Probability of the chi-square gates (individual: dim z dof; joint: dim z per pairing).
  double gate_probability = 0.99;
  /// A measurement compatible with no landmark at this (stricter) probability starts a new
  /// landmark; one compatible at it but left unpaired is discarded as ambiguous.
  double new_landmark_probability = 0.9999;
  /// JCBB nodes visited before the search settles for the best hypothesis found so far (a node
  /// costs O(k²) for k pairings: ~6 µs at 60; docs/data_association.md, "A search that finishes").
  std::size_t max_nodes = 20000;
};

/// What one measurement became.
enum class AssociationOutcome : std::uint8_t { paired, new_landmark, discarded };

template <class Measurement>
struct AssociationResult {
  /// Paired and new measurements with their ids, in input order: ready for the back-end's update().
  std::vector<Observation<Measurement>> observations;
  std::vector<AssociationOutcome> outcome;  ///< per input measurement
  std::vector<LandmarkId> id;               ///< per input measurement; meaningless when discarded
  std::size_t paired = 0, created = 0, discarded = 0;
  double joint_nis = 0.0;      ///< of the chosen pairings
  std::size_t nodes = 0;       ///< JCBB nodes visited (0 for nearest neighbour)
  bool search_complete = true; ///< false when JCBB stopped at max_nodes
};

template <class Sensor>
class DataAssociation {
 public:
  using Measurement = typename Sensor::Measurement;
  using Landmark = typename Sensor::Landmark;
  static constexpr int Z = Measurement::RowsAtCompileTime;
  static constexpr int M = Landmark::RowsAtCompileTime;

  /// New landmarks get ids first_new_id, first_new_id + 1, ...
  explicit DataAssociation(Sensor sensor, AssociationOptions options = {}, LandmarkId first_new_id = LandmarkId{1} << 61)
      : sensor_(std::move(sensor)), options_(options), next_new_id_(first_new_id) {
    if (!(options_.gate_probability > 0.0 && options_.gate_probability < 1.0))
      throw invalid_input_error("association gate_probability must be in (0, 1), got " +
                                std::to_string(options_.gate_probability));
    if (!(options_.new_landmark_probability >= options_.gate_probability && options_.new_landmark_probability < 1.0))
      throw invalid_input_error("association new_landmark_probability must be in [gate_probability, 1), got " +
                                std::to_string(options_.new_landmark_probability));
    individual_gate_ = chi_square_quantile(Z, options_.gate_probability);
    new_landmark_gate_ = chi_square_quantile(Z, options_.new_landmark_probability);
  }

  /// Associates `measurements` with the landmarks of an estimator that provides
  /// joint_marginal(ids) (EKF, SEIF) against its whole map.
  template <class Estimator>
  AssociationResult<Measurement> associate(const Estimator& estimator, std::span<const Measurement> measurements) {
    return associate(estimator.joint_marginal(estimator.landmark_ids()), measurements);
  }

  /// Associates `measurements` with the landmarks of `joint`.
  template <class State>
  AssociationResult<Measurement> associate(const JointMarginal<State, M>& joint, std::span<const Measurement> measurements) {
    require_finite_measurements(measurements);
    const auto pairs = individually_compatible(joint, measurements);
    const Search<State> search(*this, joint, pairs, measurements.size());
    const std::vector<int> chosen = options_.method == AssociationMethod::nearest_neighbour
                                        ? search.nearest_neighbour()
                                        : search.branch_and_bound();
    return result(measurements, joint, pairs, chosen, search);
  }

  const AssociationOptions& options() const { return options_; }
  LandmarkId next_new_id() const { return next_new_id_; }

 private:
  /// A measurement i and a landmark j (index into the joint) that pass the individual test, with
  /// the blocks of H, Q and the residual at the joint's means.
  struct Pair {
    std::size_t measurement;
    std::size_t landmark;
    Eigen::Matrix<double, Z, Eigen::Dynamic> J_z_x;
    Eigen::Matrix<double, Z, M> J_z_m;
    Eigen::Matrix<double, Z, Z> Q;
    Eigen::Matrix<double, Z, 1> residual;
    double nis = 0.0;
  };

  static void require_finite_measurements(std::span<const Measurement> measurements) {
    for (std::size_t i = 0; i < measurements.size(); ++i)
      if (!measurements[i].allFinite())
        throw invalid_input_error("measurement " + std::to_string(i) + " to associate has NaN or Inf");
  }

  /// Innovation covariance cross block H_p Sigma H_q^T (+ Q when p is q) of two pairings.
  template <class State>
  static Eigen::Matrix<double, Z, Z> innovation_block(const JointMarginal<State, M>& joint, const Pair& p, const Pair& q) {
    Eigen::Matrix<double, Z, Z> out = innovation_cross_block(joint.cov, p.J_z_x, p.J_z_m, joint.offset(p.landmark),
                                                             q.J_z_x, q.J_z_m, joint.offset(q.landmark));
    if (&p == &q) out += p.Q;
    return out;
  }

  /// Every (measurement, landmark) pair whose NIS is inside the new-landmark gate, nearest first per measurement.
  template <class State>
  std::vector<Pair> individually_compatible(const JointMarginal<State, M>& joint,
                                            std::span<const Measurement> measurements) const {
    std::vector<Pair> pairs;
    for (std::size_t i = 0; i < measurements.size(); ++i)
      for (std::size_t j = 0; j < joint.ids.size(); ++j) {
        std::optional<Pair> pair = pairing(joint, i, measurements[i], j);
        if (pair && pair->nis <= new_landmark_gate_) pairs.push_back(std::move(*pair));
      }
    std::stable_sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
      return a.measurement != b.measurement ? a.measurement < b.measurement : a.nis < b.nis;
    });
    return pairs;
  }

  /// Measurement i against landmark j; none when the model cannot be linearized there (e.g. a
  /// landmark at the sensor) or S is not positive definite: such a pair is simply not compatible.
  template <class State>
  std::optional<Pair> pairing(const JointMarginal<State, M>& joint, std::size_t i, const Measurement& z,
                              std::size_t j) const {
    try {
      const auto lin = linearize_observation(sensor_, joint.robot, joint.landmarks[j], z, joint.ids[j], 0, 1.0);
      Pair pair{i, j, lin.J_z_x, lin.J_z_m, lin.Q, lin.residual};
      const auto llt = cholesky_or_throw(innovation_block(joint, pair, pair), "innovation covariance");
      pair.nis = mahalanobis_squared(llt, pair.residual);
      return pair;
    } catch (const numerical_error&) {
      return std::nullopt;
    }
  }

  /// The search over hypotheses: chosen[i] is the index into `pairs` of measurement i's pairing or -1.
  template <class State>
  class Search {
   public:
    Search(const DataAssociation& owner, const JointMarginal<State, M>& joint, const std::vector<Pair>& pairs,
           std::size_t measurements)
        : owner_(owner), joint_(joint), pairs_(pairs), measurements_(measurements), first_(measurements + 1, 0) {
      for (const Pair& p : pairs_) ++first_[p.measurement + 1];
      for (std::size_t i = 0; i < measurements; ++i) first_[i + 1] += first_[i];
      order_ = fewest_candidates_first();
      for (std::size_t k = 1; k <= measurements; ++k)
        joint_gate_.push_back(chi_square_quantile(static_cast<double>(Z * k), owner.options_.gate_probability));
    }

    std::vector<int> nearest_neighbour() const {
      std::vector<int> order(pairs_.size());
      for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
      std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return pairs_[a].nis < pairs_[b].nis; });
      std::vector<int> chosen(measurements_, -1);
      std::vector<bool> taken(joint_.ids.size(), false);
      for (int k : order) {
        const Pair& p = pairs_[k];
        if (p.nis > owner_.individual_gate_ || chosen[p.measurement] >= 0 || taken[p.landmark]) continue;
        chosen[p.measurement] = k;
        taken[p.landmark] = true;
      }
      return chosen;
    }

    std::vector<int> branch_and_bound() const {
      hypothesis_.assign(measurements_, -1);
      best_.assign(measurements_, -1);
      best_pairings_ = 0;
      best_nis_ = 0.0;
      taken_.assign(joint_.ids.size(), false);
      nodes_ = 0;
      complete_ = true;
      stack_.clear();
      const Eigen::Index rows = Z * static_cast<Eigen::Index>(std::min(measurements_, joint_.ids.size()));
      factor_.resize(rows, rows);
      whitened_.resize(rows);
      cross_.resize(rows, Z);
      descend(0, 0.0);
      return best_;
    }

    double joint_nis(const std::vector<int>& chosen) const { return nis_of(chosen).value_or(0.0); }
    std::size_t nodes() const { return nodes_; }
    bool complete() const { return complete_; }

   private:
    /// JCBB (Neira & Tardós 2001, Fig. 2): the i-th measurement of order_ pairs with each compatible
    /// free landmark in turn while the hypothesis stays jointly compatible, then stays unpaired if
    /// that can still match the best hypothesis's number of pairings. `nis` is the joint NIS of the
    /// pairings made so far; a branch that can at most tie the best's pairings is cut once its NIS
    /// is no smaller than the best's (a pairing only adds to the joint NIS): the result is the same.
    void descend(std::size_t i, double nis) const {
      if (++nodes_ > owner_.options_.max_nodes) {
        complete_ = false;
        return;
      }
      const std::size_t pairings = stack_.size();
      if (i == measurements_) {
        if (pairings > best_pairings_ || (pairings == best_pairings_ && pairings > 0 && nis < best_nis_)) {
          best_ = hypothesis_;
          best_pairings_ = pairings;
          best_nis_ = nis;
        }
        return;
      }
      const std::size_t remaining = measurements_ - i - 1;
      if (can_still_win(pairings + 1 + remaining, nis))
        for (std::size_t k = first_[order_[i]]; k < first_[order_[i] + 1]; ++k) {
          const Pair& p = pairs_[k];
          if (p.nis > owner_.individual_gate_ || taken_[p.landmark]) continue;
          const std::optional<double> joint = nis_with(p, nis);
          if (!joint || *joint > joint_gate_[pairings] || !can_still_win(pairings + 1 + remaining, *joint)) continue;
          hypothesis_[p.measurement] = static_cast<int>(k);
          taken_[p.landmark] = true;
          stack_.push_back(&p);
          descend(i + 1, *joint);
          stack_.pop_back();
          taken_[p.landmark] = false;
          hypothesis_[p.measurement] = -1;
        }
      if (can_still_win(pairings + remaining, nis)) descend(i + 1, nis);
    }

    /// The order the search takes the measurements in: fewest individually compatible landmarks
    /// first, ties in input order (the most constrained first, as in any constraint search), so the
    /// ambiguous ones come last, when the pairings before them have pinned the robot and the best
    /// hypothesis's NIS leaves their alternatives little room.
    std::vector<std::size_t> fewest_candidates_first() const {
      std::vector<std::size_t> candidates(measurements_, 0), order(measurements_);
      for (const Pair& p : pairs_)
        if (p.nis <= owner_.individual_gate_) ++candidates[p.measurement];
      for (std::size_t i = 0; i < measurements_; ++i) order[i] = i;
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return candidates[a] < candidates[b]; });
      return order;
    }

    /// Whether a branch that can reach at most `pairings` pairings, with joint NIS `nis` so far, can
    /// still beat the best hypothesis: more pairings, or as many with a smaller NIS.
    bool can_still_win(std::size_t pairings, double nis) const {
      return pairings > best_pairings_ || (pairings == best_pairings_ && (pairings == 0 || nis < best_nis_));
    }

    /// The joint NIS of the stacked pairings and p, by extending the Cholesky factor of their S by
    /// p's rows (O(k²) for k pairings, instead of factoring S anew); none when S is not positive
    /// definite. Writes p's rows of the factor and of the whitened innovation, which stay valid
    /// while p is on the stack.
    std::optional<double> nis_with(const Pair& p, double nis) const {
      const Eigen::Index n = Z * static_cast<Eigen::Index>(stack_.size());
      auto cross = cross_.topRows(n);  // S(stack, p), then C^T with C = S(p, stack) L^-T
      for (std::size_t a = 0; a < stack_.size(); ++a)
        cross.template middleRows<Z>(Z * static_cast<Eigen::Index>(a)) = innovation_block(joint_, *stack_[a], p);
      factor_.topLeftCorner(n, n).template triangularView<Eigen::Lower>().solveInPlace(cross);
      const Eigen::LLT<Eigen::Matrix<double, Z, Z>> tail(innovation_block(joint_, p, p) - cross.transpose() * cross);
      if (tail.info() != Eigen::Success) return std::nullopt;
      const Eigen::Matrix<double, Z, 1> y = tail.matrixL().solve(p.residual - cross.transpose() * whitened_.head(n));
      factor_.block(n, 0, Z, n) = cross.transpose();
      factor_.block(n, n, Z, Z) = tail.matrixL();
      whitened_.template segment<Z>(n) = y;
      return nis + y.squaredNorm();
    }

    /// The joint NIS of the pairings in `chosen`, none when their S is not positive definite.
    std::optional<double> nis_of(const std::vector<int>& chosen) const {
      std::vector<const Pair*> used;
      for (int k : chosen)
        if (k >= 0) used.push_back(&pairs_[k]);
      if (used.empty()) return 0.0;
      const Eigen::Index n = Z * static_cast<Eigen::Index>(used.size());
      Eigen::MatrixXd S(n, n);
      Eigen::VectorXd nu(n);
      for (std::size_t a = 0; a < used.size(); ++a) {
        nu.segment<Z>(Z * a) = used[a]->residual;
        for (std::size_t b = 0; b <= a; ++b) {
          const Eigen::Matrix<double, Z, Z> block = innovation_block(joint_, *used[a], *used[b]);
          S.block<Z, Z>(Z * a, Z * b) = block;
          S.block<Z, Z>(Z * b, Z * a) = block.transpose();
        }
      }
      const Eigen::LLT<Eigen::MatrixXd> llt(S);
      if (llt.info() != Eigen::Success) return std::nullopt;
      return llt.matrixL().solve(nu).squaredNorm();
    }

    const DataAssociation& owner_;
    const JointMarginal<State, M>& joint_;
    const std::vector<Pair>& pairs_;
    std::size_t measurements_;
    std::vector<std::size_t> first_;  ///< pairs_[first_[i], first_[i+1]) belong to measurement i
    std::vector<std::size_t> order_;  ///< the measurements in the order the search takes them
    std::vector<double> joint_gate_;  ///< chi-square quantile for 1, 2, ... pairings
    mutable std::vector<int> hypothesis_, best_;
    mutable std::vector<bool> taken_;
    mutable std::vector<const Pair*> stack_;  ///< the hypothesis's pairings, in the order made
    mutable Eigen::MatrixXd factor_;          ///< lower Cholesky factor of the stacked pairings' S
    mutable Eigen::VectorXd whitened_;        ///< factor^-1 times their stacked innovations
    mutable Eigen::Matrix<double, Eigen::Dynamic, Z> cross_;  ///< workspace of nis_with
    mutable std::size_t best_pairings_ = 0, nodes_ = 0;
    mutable double best_nis_ = 0.0;
    mutable bool complete_ = true;
  };

  template <class State>
  AssociationResult<Measurement> result(std::span<const Measurement> measurements, const JointMarginal<State, M>& joint,
                                        const std::vector<Pair>& pairs, const std::vector<int>& chosen,
                                        const Search<State>& search) {
    AssociationResult<Measurement> out;
    out.outcome.resize(measurements.size());
    out.id.resize(measurements.size());
    std::vector<bool> near_a_landmark(measurements.size(), false);
    for (const Pair& p : pairs) near_a_landmark[p.measurement] = true;
    for (std::size_t i = 0; i < measurements.size(); ++i) {
      if (chosen[i] >= 0) {
        out.outcome[i] = AssociationOutcome::paired;
        out.id[i] = joint.ids[pairs[chosen[i]].landmark];
        ++out.paired;
      } else if (!near_a_landmark[i]) {
        out.outcome[i] = AssociationOutcome::new_landmark;
        out.id[i] = next_new_id_++;
        ++out.created;
      } else {
        out.outcome[i] = AssociationOutcome::discarded;
        out.id[i] = 0;
        ++out.discarded;
        continue;
      }
      out.observations.push_back({out.id[i], measurements[i]});
    }
    out.joint_nis = search.joint_nis(chosen);
    out.nodes = search.nodes();
    out.search_complete = search.complete();
    return out;
  }

  Sensor sensor_;
  AssociationOptions options_;
  LandmarkId next_new_id_;
  double individual_gate_ = 0.0;
  double new_landmark_gate_ = 0.0;
};

}  // namespace sextant
