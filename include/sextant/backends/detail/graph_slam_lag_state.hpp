#pragma once
/// \file GraphSLAM's fixed-lag mode (GraphOptions::lag), the model-independent part: the prior the
/// marginalized variables leave on the window, the marginals of landmarks that left it, and the
/// dense system of a set of variables (docs/derivations/fixed_lag_graph_slam.md).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <new>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "sextant/core/dense_cholesky.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/factor_information.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/matrix_workspace.hpp"
#include "sextant/core/observation.hpp"

namespace sextant {

/// The dense blocks of one fixed-lag step, kept from step to step (scratch: a copy starts empty).
/// Allocated afresh each frame (~2.5 MB for the window's H on the default globe), glibc handed them
/// to the kernel and back and a virtual machine charged 3-7 ms a frame for the fresh pages on a
/// fifth of the frames (docs/results/real_time.md, "Fixed lag: memory kept between frames").
struct LagScratch {
  MatrixWorkspace window;          ///< the window's H (lag_system)
  MatrixWorkspace factor;          ///< the window's reduced system and its Cholesky factor (LagSolution)
  MatrixWorkspace marginalization; ///< H of what leaves the window (marginalized_prior)
};

/// The dense normal equations H delta = b over an ordered set of variables: landmarks (by slot) and
/// poses (by index), each placed where it was added. H lives in a MatrixWorkspace, which must outlive
/// the system and not hand it out again meanwhile.
template <int X, int M>
struct LagSystem {
  std::unordered_map<std::size_t, Eigen::Index> landmark_at;
  std::map<std::size_t, Eigen::Index> pose_at;
  Eigen::Index dims = 0;
  MatrixWorkspace::View H{nullptr, 0, 0, Eigen::OuterStride<>(1)};
  Eigen::VectorXd b;

  void add_landmark(std::size_t slot) {
    if (landmark_at.emplace(slot, dims).second) dims += M;
  }
  void add_pose(std::size_t pose) {
    if (pose_at.emplace(pose, dims).second) dims += X;
  }
  /// Zero H (in `memory`) and b once every variable is placed.
  void allocate(MatrixWorkspace& memory) {
    new (&H) MatrixWorkspace::View(memory.view(dims));  // re-seating a Map, as Eigen documents it
    H.setZero();
    b.setZero(dims);
  }
  /// H[i, k] += block and, off the diagonal, H[k, i] += block^T.
  template <class Block>
  void add(Eigen::Index i, Eigen::Index k, const Block& block) {
    H.block(i, k, block.rows(), block.cols()) += block;
    if (i != k) H.block(k, i, block.cols(), block.rows()) += block.transpose();
  }
  /// A factor on the variables at offsets i (dimension NA) and j (NB): its blocks of H and b.
  template <int NA, int NB>
  void add_factor(Eigen::Index i, Eigen::Index j, const FactorInformation<NA, NB>& info) {
    add(i, i, info.aa);
    add(j, j, info.bb);
    add(i, j, info.ab);
    b.template segment<NA>(i) += info.a;
    b.template segment<NB>(j) += info.b;
  }
};

template <int X, int M, class State>
struct FixedLagState {
  using Landmark = Eigen::Matrix<double, M, 1>;
  /// What the marginalized variables leave on the window: 1/2 d^T Lambda d - eta^T d over
  /// d = (m_j - theta_j for `landmarks`, then x_p ⊖ theta_p for `poses`), linearized at theta.
  struct Prior {
    std::vector<LandmarkId> landmarks;
    std::vector<Landmark> landmark_theta;
    std::vector<std::size_t> poses;
    std::vector<State> pose_theta;
    Eigen::MatrixXd Lambda;
    Eigen::VectorXd eta;
  };
  /// A landmark no window pose sees: its mean and marginal information when it left, the prior it
  /// brings back should it be seen again.
  struct Retired {
    Landmark mean;
    Eigen::Matrix<double, M, M> information;
  };

  std::size_t first = 0;  ///< the window's oldest pose
  Prior prior;
  std::unordered_map<LandmarkId, Retired> retired;
  std::vector<std::vector<LandmarkId>> seen_from;  ///< per pose: the landmarks measured from it
};

/// The window's system solved with its free landmarks (the first `free_dims` dimensions: landmarks
/// without a factor on another landmark, i.e. not in the prior) eliminated by their own Schur
/// complements onto the poses (thesis eqs. 66-69), and one dense factorization of the rest,
/// S = (prior landmarks, poses), the poses from `pose_begin` to the end, the newest last.
template <int X, int M>
struct LagSolution {
  using Block = Eigen::Matrix<double, M, M>;
  Eigen::Index free_dims = 0, pose_begin = 0;
  std::vector<Eigen::LLT<Block>> free;  ///< H_jj of each free landmark
  MatrixWorkspace::View factor;  ///< S's Cholesky factor in its lower triangle (core/dense_cholesky.hpp), in `memory`
  Eigen::VectorXd delta;

  /// `memory` holds the factor and must outlive the solution.
  LagSolution(const LagSystem<X, M>& sys, Eigen::Index free_dims_, Eigen::Index pose_begin_, MatrixWorkspace& memory)
      : free_dims(free_dims_), pose_begin(pose_begin_), factor(memory.view(sys.dims - free_dims_)) {
    const Eigen::Index rest = sys.dims - free_dims, poses = sys.dims - pose_begin;
    factor = sys.H.bottomRightCorner(rest, rest);
    Eigen::VectorXd g = sys.b.tail(rest);
    for (Eigen::Index o = 0; o < free_dims; o += M) {
      free.push_back(cholesky_or_throw(sys.H.template block<M, M>(o, o), "GraphSLAM (fixed lag): the information of a landmark in the window"));
      const auto B = sys.H.block(pose_begin, o, poses, M);  // the poses' coupling; no other landmark's
      factor.bottomRightCorner(poses, poses).noalias() -= B * free.back().solve(B.transpose());
      g.tail(poses).noalias() -= B * free.back().solve(sys.b.template segment<M>(o));
    }
    delta.resize(sys.dims);
    delta.tail(rest) = cholesky_in_place_or_throw(factor, "GraphSLAM (fixed lag): the window's information matrix").solve(g);
    for (Eigen::Index o = 0; o < free_dims; o += M) {
      const auto B = sys.H.block(pose_begin, o, poses, M);
      delta.template segment<M>(o) =
          free[static_cast<std::size_t>(o / M)].solve(sys.b.template segment<M>(o) - B.transpose() * delta.tail(poses));
    }
    if (!delta.allFinite()) throw numerical_error("GraphSLAM (fixed lag): the step is not finite");
  }

  /// The newest pose's marginal: (L_nn L_nn^T)^-1 from the last block of S's factor, since L^-1 is
  /// lower triangular (as ProfileCholesky::last_inverse_block).
  Eigen::Matrix<double, X, X> newest_pose_covariance() const {
    const Eigen::Matrix<double, X, X> L_inv = factor.template bottomRightCorner<X, X>().template triangularView<Eigen::Lower>().solve(
        Eigen::Matrix<double, X, X>::Identity());
    return L_inv.transpose() * L_inv;
  }

  /// The marginal covariance of the landmark at `offset` in sys: a block of S^-1, or for a free one
  /// H_jj^-1 + V^T S^-1 V with V = (0; B H_jj^-1) over S's dimensions.
  Block landmark_covariance(const LagSystem<X, M>& sys, Eigen::Index offset) const {
    const Eigen::Index rest = sys.dims - free_dims, poses = sys.dims - pose_begin;
    const LowerCholeskyFactor S(factor);
    Eigen::MatrixXd V = Eigen::MatrixXd::Zero(rest, M);
    if (offset >= free_dims) {
      V.middleRows(offset - free_dims, M).setIdentity();
      return Block(S.solve(V).middleRows(offset - free_dims, M));
    }
    const auto& H_jj = free[static_cast<std::size_t>(offset / M)];
    const Block H_inv = H_jj.solve(Block::Identity());
    V.bottomRows(poses) = sys.H.block(pose_begin, offset, poses, M) * H_inv;
    return H_inv + V.transpose() * S.solve(V);
  }
};

/// Eliminates the first `removed` dimensions of sys (H = [A_rr A_rk; A_kr A_kk], b = [b_r; b_k]):
/// Lambda = A_kk - A_kr A_rr^-1 A_rk, eta = b_k - A_kr A_rr^-1 b_r (thesis Appendix C).
template <int X, int M>
void schur_complement(const LagSystem<X, M>& sys, Eigen::Index removed, Eigen::MatrixXd& Lambda, Eigen::VectorXd& eta) {
  const Eigen::Index kept = sys.dims - removed;
  const auto A_rr = cholesky_or_throw(sys.H.topLeftCorner(removed, removed),
                                      "GraphSLAM (fixed lag): the information of the variables to marginalize");
  const Eigen::MatrixXd solved = A_rr.solve(sys.H.topRightCorner(removed, kept));
  Lambda = sys.H.bottomRightCorner(kept, kept) - sys.H.bottomLeftCorner(kept, removed) * solved;
  Lambda = (0.5 * (Lambda + Lambda.transpose())).eval();
  eta = sys.b.tail(kept) - solved.transpose() * sys.b.head(removed);
  if (!Lambda.allFinite() || !eta.allFinite()) throw numerical_error("GraphSLAM (fixed lag): the marginalization is not finite");
}

}  // namespace sextant
