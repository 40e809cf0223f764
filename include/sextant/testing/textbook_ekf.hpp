#pragma once
/// \file The textbook EKF correction with a dense, full H (thesis eqs. 14-17), kept as a reference:
/// tests check the block-sparse EkfSlam against it and the benchmarks time it beside it. It is
/// O(n^2 k) per update (P H^T and K S K^T with H dense) against EkfSlam's O(n k) + O(n^2 k / 2).

#include <Eigen/Dense>
#include <span>

#include "sextant/core/gaussian.hpp"
#include "sextant/core/observation.hpp"

namespace sextant::testing {

struct DenseLinearization {
  Eigen::MatrixXd H;         ///< (Z k) x n, zero outside the robot and landmark blocks
  Eigen::MatrixXd Q;         ///< block-diagonal measurement noise
  Eigen::VectorXd residual;  ///< stacked z - h(x, m)
};

/// Builds the full H, Q and residual of observations of known landmarks of an EkfSlam-like
/// back-end (pose(), landmark(id), landmark_ids(), covariance()).
template <class Backend, class Sensor, class Measurement>
DenseLinearization linearize_dense(const Backend& backend, const Sensor& sensor,
                                   std::span<const Observation<Measurement>> observations) {
  constexpr int X = Backend::X, M = Backend::M, Z = Backend::Z;
  const Eigen::Index n = backend.state_dim(), k = static_cast<Eigen::Index>(observations.size());
  DenseLinearization out{Eigen::MatrixXd::Zero(Z * k, n), Eigen::MatrixXd::Zero(Z * k, Z * k), Eigen::VectorXd(Z * k)};
  const auto& ids = backend.landmark_ids();
  for (Eigen::Index i = 0; i < k; ++i) {
    const auto& obs = observations[i];
    const Eigen::Index slot = std::find(ids.begin(), ids.end(), obs.landmark_id) - ids.begin();
    const auto prediction =
        with_noise_scale(sensor.predict(backend.pose().mean, backend.landmark(obs.landmark_id).mean), obs.noise_scale);
    out.H.block(Z * i, 0, Z, X) = prediction.J_z_x;
    out.H.block(Z * i, X + M * slot, Z, M) = prediction.J_z_m;
    out.Q.block(Z * i, Z * i, Z, Z) = prediction.Q;
    out.residual.segment(Z * i, Z) = sensor.residual(obs.z, prediction.z);
  }
  return out;
}
template <class Backend, class Sensor, class Measurement>
DenseLinearization linearize_dense(const Backend& backend, const Sensor& sensor,
                                   const std::vector<Observation<Measurement>>& observations) {
  return linearize_dense(backend, sensor, std::span<const Observation<Measurement>>(observations));
}

/// S = H P H^T + Q (eq. 14), K = P H^T S^-1 (eq. 15), mean += K nu (eq. 16), P = P - K S K^T
/// (eq. 17), every product with the dense H. The mean is a stacked Euclidean vector.
inline void textbook_ekf_update(Eigen::MatrixXd& P, Eigen::VectorXd& mean, const Eigen::MatrixXd& H,
                                const Eigen::MatrixXd& Q, const Eigen::VectorXd& residual) {
  const Eigen::MatrixXd PHt = P * H.transpose();
  const Eigen::MatrixXd S = H * PHt + Q;
  const Eigen::MatrixXd K = cholesky_or_throw(S, "innovation covariance S").solve(PHt.transpose()).transpose();
  mean += K * residual;
  const Eigen::MatrixXd SKt = S * K.transpose();
  P.noalias() -= K * SKt;
}

}  // namespace sextant::testing
