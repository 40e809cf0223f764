#pragma once
/// \file Orientation error of an estimate (thesis §4.3.1): the angle of R_true^T R_est (eq. 112)
/// and its NEES. Eqs. 113-114 print C_phi = V C_eta^-1 V^T; the variance of phi = phi(eta_est) is
/// V C_eta V^T (first-order propagation, no inverse). Both the thesis's scalar NEES (1 dof) and the
/// NEES of the rotation vector e = Log(R_true^T R_est) (3 dof) are given. The scalar form is the
/// NEES along the error's own direction, (u^T e)^2 / (u^T C_e u) with u = e / |e|: never above the
/// rotation-vector NEES (Cauchy-Schwarz), equal to it, chi2 with 3 dof, when C_e is isotropic; so
/// it is not chi2(1) and is reported beside the thesis, not tested against a 1-dof bound.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>
#include <limits>

#include "sextant/core/so3.hpp"

namespace sextant::eval {

struct RotationError {
  double angle = 0.0;       ///< eq. 112, rad
  double nees_angle = 0.0;  ///< phi^2 / (V C_eta V^T) (eqs. 113-114 corrected); <= nees
  double nees = 0.0;        ///< e^T (D C_eta D^T)^-1 e, 3 dof
};

/// R_true, R_est and the estimate's angle covariance C_eta; E maps a change of the estimate's
/// angles to the rotation vector of its body-frame change: R(eta + d) = R(eta) Exp(E d) + O(d^2).
/// Then d e / d eta_est = D = J_r^-1(e) E and V = d phi / d eta_est = e^T D / phi. Infinite NEES
/// when the propagated covariance is singular.
inline RotationError rotation_error(const Eigen::Matrix3d& R_true, const Eigen::Matrix3d& R_est,
                                    const Eigen::Matrix3d& E, const Eigen::Matrix3d& C_eta) {
  RotationError out;
  const Eigen::Vector3d e = so3::log(R_true.transpose() * R_est);
  out.angle = e.norm();
  const Eigen::Matrix3d D = so3::right_jacobian_inverse(e) * E;
  const Eigen::Matrix3d C = D * C_eta * D.transpose();
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(C);
  const bool invertible = ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0).all();
  out.nees = invertible ? e.dot(ldlt.solve(e)) : std::numeric_limits<double>::infinity();
  if (out.angle > 0) {
    const Eigen::Vector3d direction = e / out.angle;
    const double variance = direction.dot(C * direction);
    out.nees_angle = variance > 0 ? out.angle * out.angle / variance : std::numeric_limits<double>::infinity();
  }
  return out;
}

}  // namespace sextant::eval
