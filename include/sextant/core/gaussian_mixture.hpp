#pragma once
/// \file The moments of a weighted Gaussian mixture: what a particle cloud reports as one Gaussian
/// (FastSLAM's pose, its averaged landmarks, its predictive distribution of a sighting).

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace sextant {

template <int D>
struct MixtureMoments {
  Eigen::Matrix<double, D, 1> mean;
  Eigen::Matrix<double, D, D> cov;
};

/// Mean sum_i w_i mu_i and covariance sum_i w_i (Sigma_i + (mu_i - mean)(mu_i - mean)^T) of the
/// components i with weights w (summing to one; a component of weight 0 is left out), its mean and
/// covariance given by mean_of(i) and cov_of(i).
template <int D, class MeanOf, class CovOf>
MixtureMoments<D> mixture_moments(const std::vector<double>& w, MeanOf&& mean_of, CovOf&& cov_of) {
  MixtureMoments<D> out{Eigen::Matrix<double, D, 1>::Zero(), Eigen::Matrix<double, D, D>::Zero()};
  for (std::size_t i = 0; i < w.size(); ++i)
    if (w[i] != 0.0) out.mean += w[i] * mean_of(i);
  for (std::size_t i = 0; i < w.size(); ++i) {
    if (w[i] == 0.0) continue;
    const Eigen::Matrix<double, D, 1> d = mean_of(i) - out.mean;
    out.cov += w[i] * (cov_of(i) + d * d.transpose());
  }
  return out;
}

}  // namespace sextant
