#pragma once
/// \file States with a conditionally linear tail, and the draw that keeps it Gaussian (the
/// marginalized particle filter of Schön, Gustafsson and Nordlund, IEEE TSP 2005). A motion model
/// may declare `static constexpr int kConditionallyLinearDims = T`: the last T entries of its state
/// (e.g. the 12D camera's velocity and angular rate) enter g(x, u) linearly once the leading ones are
/// fixed, R does not depend on them, and no measurement model sees them. A particle filter then
/// samples only the leading entries and keeps the tail as a Gaussian given them, exactly
/// (docs/derivations/fastslam_linear_tail.md).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <random>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"

namespace sextant {

namespace detail {
template <class Motion>
constexpr int conditionally_linear_dims() {
  if constexpr (requires { Motion::kConditionallyLinearDims; })
    return Motion::kConditionallyLinearDims;
  else
    return 0;
}
}  // namespace detail

/// The number T of trailing state entries Motion declares conditionally linear (0 if it declares none).
template <class Motion>
inline constexpr int conditionally_linear_dims_v = detail::conditionally_linear_dims<Motion>();

/// Cov(tail | lead) of N(., cov) with the last T entries the tail, embedded in an X x X matrix that is
/// zero elsewhere: Sigma_tt - Sigma_tl Sigma_ll^+ Sigma_lt (a pseudo-inverse where Sigma_ll is singular).
template <int T, int X>
Eigen::Matrix<double, X, X> conditional_tail_covariance(const Eigen::Matrix<double, X, X>& cov) {
  static_assert(T >= 0 && T < X, "the tail must leave at least one entry to sample");
  Eigen::Matrix<double, X, X> out = Eigen::Matrix<double, X, X>::Zero();
  if constexpr (T > 0) {
    constexpr int L = X - T;
    const Eigen::LDLT<Eigen::Matrix<double, L, L>> lead(cov.template topLeftCorner<L, L>());
    const Eigen::Matrix<double, L, T> cross = cov.template topRightCorner<L, T>();
    out.template bottomRightCorner<T, T>() =
        symmetrized((cov.template bottomRightCorner<T, T>() - cross.transpose() * lead.solve(cross)).eval());
  }
  return out;
}

/// A draw whose tail stayed a Gaussian: x (the tail at its conditional mean) and the covariance of the
/// tail given the drawn lead (zero outside the tail).
template <class Point, int X>
struct TailGaussianDraw {
  Point x;
  Eigen::Matrix<double, X, X> cov;
};

/// Draws the leading X - T entries of N(mean, cov) on Space's chart (d = L n with cov_ll = L L^T from
/// an LDL^T factorization, semi-definite allowed) and sets the last T to their mean given that draw:
/// x = plus(mean, [d; Sigma_tl Sigma_ll^+ d]). With T = 0 this is a plain draw of N(mean, cov).
template <class Space, int T, int X>
TailGaussianDraw<typename Space::Point, X> draw_lead_keep_tail(const typename Space::Point& mean,
                                                                const Eigen::Matrix<double, X, X>& cov,
                                                                std::mt19937_64& rng) {
  constexpr int L = X - T;
  const Eigen::LDLT<Eigen::Matrix<double, L, L>> lead(cov.template topLeftCorner<L, L>());
  std::normal_distribution<double> unit(0.0, 1.0);
  Eigen::Matrix<double, L, 1> n;
  for (int i = 0; i < L; ++i) n(i) = unit(rng) * std::sqrt(std::max(lead.vectorD()(i), 0.0));
  Eigen::Matrix<double, X, 1> d;
  d.template head<L>() = lead.transpositionsP().transpose() * (lead.matrixL() * n);
  if constexpr (T > 0)
    d.template tail<T>() = cov.template bottomLeftCorner<T, L>() * lead.solve(d.template head<L>().eval());
  TailGaussianDraw<typename Space::Point, X> out{Space::plus(mean, d), conditional_tail_covariance<T>(cov)};
  if (!Space::is_finite(out.x) || !out.cov.allFinite()) throw numerical_error("sampled particle pose is not finite");
  return out;
}

}  // namespace sextant
