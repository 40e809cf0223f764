#pragma once
/// \file GraphSLAM's online mode, the model-independent part: the factors linearized at their
/// linearization points theta, their contributions to the reduced pose system S (the landmarks
/// eliminated by their Schur complements, thesis eqs. 66-69) and the steps delta from theta.
/// The back-end's step (graph_slam_online_impl.hpp) relinearizes what moved, re-adds it here and
/// refactorizes S incrementally (docs/derivations/incremental_graph_slam.md).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <vector>

#include "sextant/core/profile_cholesky.hpp"

namespace sextant {

/// What one online step did.
struct OnlineStepSummary {
  std::size_t first_row = 0;               ///< the oldest pose whose row of S changed
  std::size_t poses = 0;                   ///< poses in the graph
  std::size_t relinearized_poses = 0;      ///< poses whose step exceeded the threshold
  std::size_t relinearized_landmarks = 0;  ///< landmarks whose step exceeded the threshold
  std::size_t linearized_landmarks = 0;    ///< landmarks whose factors were linearized again (new, seen, or moved)
  bool sparse = false;  ///< S was factorized whole in a fill-reducing order, not from first_row on (ProfileCholesky)
};

template <int X, int M, class State>
struct OnlineGraphState {
  using Landmark = Eigen::Matrix<double, M, 1>;
  /// One measurement of a landmark from pose `pose`: its blocks Omega_pp, Omega_pj and b_p.
  struct Term {
    std::size_t pose;
    Eigen::Matrix<double, X, X> aa;
    Eigen::Matrix<double, X, M> ab;
    Eigen::Matrix<double, X, 1> a;
  };
  /// All measurements of one landmark at theta; H = Omega_jj (factored), b = b_j.
  struct LandmarkLinearization {
    std::size_t records = 0;  ///< measurement records of the landmark when linearized
    std::vector<Term> terms;  ///< the usable ones (empty: the landmark sits out)
    Eigen::LLT<Eigen::Matrix<double, M, M>> H;
    Eigen::Matrix<double, M, 1> b = Eigen::Matrix<double, M, 1>::Zero();
  };
  enum class Source { prior, motion, marginal };
  /// A factor on poses only (the prior, a motion, a marginalized landmark): Lambda and g over the
  /// stacked tangents of `poses`.
  struct PoseFactor {
    Source source;
    std::size_t index;  ///< motion k or marginal factor number
    std::vector<std::size_t> poses;
    Eigen::MatrixXd Lambda;
    Eigen::VectorXd g;
    double cost = 0.0;  ///< chi2 at the poses it was evaluated at
  };

  std::vector<State> theta;         ///< each pose's linearization point
  Eigen::VectorXd theta_landmarks;  ///< each landmark slot's linearization point
  std::vector<LandmarkLinearization> landmarks;  ///< per slot
  std::vector<PoseFactor> pose_factors;
  std::vector<std::vector<std::size_t>> factors_of_pose;    ///< pose factor indices per pose
  std::vector<std::vector<std::size_t>> landmarks_of_pose;  ///< landmark slots seen from each pose
  ProfileCholesky<X> S;   ///< the reduced pose system at theta
  Eigen::VectorXd g;      ///< its right-hand side (minus the gradient)
  Eigen::VectorXd delta_poses, delta_landmarks;  ///< the last step from theta
  OnlineStepSummary last_step;

  /// S += sign Lambda, g += sign g over the factor's poses (distinct; lower blocks).
  static void add(ProfileCholesky<X>& S, Eigen::VectorXd& g, const PoseFactor& f, double sign) {
    for (std::size_t i = 0; i < f.poses.size(); ++i) {
      g.template segment<X>(X * f.poses[i]) += sign * f.g.template segment<X>(X * i);
      for (std::size_t k = 0; k < f.poses.size(); ++k)
        if (f.poses[i] >= f.poses[k])
          S.add(f.poses[i], f.poses[k], sign * f.Lambda.template block<X, X>(X * i, X * k));
    }
  }

  /// The landmark's Schur complement on its poses (thesis eqs. 66-69), times sign:
  /// S_pq += sign (Omega_pp delta_pq - Omega_pj H^-1 Omega_jq), g_p += sign (b_p - Omega_pj H^-1 b_j).
  static void add(ProfileCholesky<X>& S, Eigen::VectorXd& g, const LandmarkLinearization& lin, double sign) {
    if (lin.terms.empty()) return;
    std::vector<Eigen::Matrix<double, M, X>> solved;  // H^-1 Omega_jq
    solved.reserve(lin.terms.size());
    for (const Term& t : lin.terms) solved.push_back(lin.H.solve(t.ab.transpose()));
    const Landmark solved_b = lin.H.solve(lin.b);
    for (std::size_t i = 0; i < lin.terms.size(); ++i) {
      const Term& t = lin.terms[i];
      S.add(t.pose, t.pose, sign * t.aa);
      g.template segment<X>(X * t.pose) += sign * (t.a - t.ab * solved_b);
      for (std::size_t k = 0; k < lin.terms.size(); ++k)
        if (t.pose >= lin.terms[k].pose)
          S.add(t.pose, lin.terms[k].pose, Eigen::Matrix<double, X, X>(-sign * (t.ab * solved[k])));
    }
  }

  /// The landmark's step given the poses' steps: H^-1 (b_j - sum_p Omega_jp delta_p) (thesis eq. 73).
  static Landmark landmark_step(const LandmarkLinearization& lin, const Eigen::VectorXd& delta_poses) {
    if (lin.terms.empty()) return Landmark::Zero();
    Landmark r = lin.b;
    for (const Term& t : lin.terms) r.noalias() -= t.ab.transpose() * delta_poses.template segment<X>(X * t.pose);
    return lin.H.solve(r);
  }

  /// Whether a step exceeds `threshold` standard deviations `sigma` in some coordinate.
  template <int D>
  static bool moved(const Eigen::Matrix<double, D, 1>& step, const Eigen::Matrix<double, D, 1>& sigma, double threshold) {
    for (int i = 0; i < D; ++i)
      if (std::abs(step(i)) > threshold * sigma(i)) return true;
    return false;
  }
};

}  // namespace sextant
