#pragma once
// PoseGraph: the chordal initialization (see ../pose_graph.hpp; docs/derivations/pose_graph_edges.md).

#include <Eigen/SVD>

#include "sextant/core/block_triplets.hpp"

namespace sextant {

namespace detail {

/// The rotation nearest to M in the Frobenius norm (SVD, the reflection removed).
template <int N>
Eigen::Matrix<double, N, N> nearest_rotation(const Eigen::Matrix<double, N, N>& M) {
  const Eigen::JacobiSVD<Eigen::Matrix<double, N, N>> svd(M, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix<double, N, 1> signs = Eigen::Matrix<double, N, 1>::Ones();
  signs(N - 1) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * signs.asDiagonal() * svd.matrixV().transpose();
}

/// Linear least squares over blocks of N unknowns per free pose, some poses held at known values:
/// each term is || J_a x_a + J_b x_b - c ||^2_W (b absent for a unary term), with C right-hand sides
/// solved at once (the chordal rotations: one per row of the rotation matrices).
template <int N, int C>
class BlockLeastSquares {
 public:
  using Block = Eigen::Matrix<double, N, N>;
  using Values = Eigen::Matrix<double, N, C>;
  BlockLeastSquares(std::vector<Eigen::Index> offset, std::vector<Values> held, Eigen::Index dimension)
      : offset_(std::move(offset)), held_(std::move(held)), rhs_(Eigen::MatrixXd::Zero(dimension, C)), dimension_(dimension) {}

  void add(std::size_t a, const Block& J_a, std::size_t b, const Block& J_b, const Values& c, const Block& W) {
    const std::size_t vertex[2] = {a, b};
    const Block J[2] = {J_a, J_b};
    Values known = c;  // c minus the held poses' part
    for (int k = 0; k < 2; ++k)
      if (offset_[vertex[k]] < 0) known -= J[k] * held_[vertex[k]];
    for (int k = 0; k < 2; ++k) {
      if (offset_[vertex[k]] < 0) continue;
      rhs_.block(offset_[vertex[k]], 0, N, C) += J[k].transpose() * W * known;
      for (int l = 0; l < 2; ++l)
        if (offset_[vertex[l]] >= 0) normal_.add(offset_[vertex[k]], offset_[vertex[l]], (J[k].transpose() * W * J[l]).eval());
    }
  }
  void add_unary(std::size_t a, const Values& value, const Block& W) {
    if (offset_[a] < 0) return;
    rhs_.block(offset_[a], 0, N, C) += W * value;
    normal_.add(offset_[a], offset_[a], W);
  }
  /// The solution; throws numerical_error when a pose is not tied to a held one.
  Eigen::MatrixXd solve() const {
    SparseCholesky solver(SparseCholesky::Factorization::by_fill);
    solver.factorize(normal_.to_sparse(dimension_, dimension_));
    return solver.solve(rhs_);
  }

 private:
  std::vector<Eigen::Index> offset_;
  std::vector<Values> held_;
  BlockTriplets normal_;
  Eigen::MatrixXd rhs_;
  Eigen::Index dimension_;
};

}  // namespace detail

/// Chordal relaxation (Martinec and Pajdla 2007; Carlone et al. 2015): the rotations first, from
/// the linear least squares || R_j - R_i R_ij ||_F^2 over all edges (one system per row of the
/// rotation matrices, weighted by each edge's mean rotation information), each projected to the
/// nearest rotation; then the translations from the linear least squares t_j - t_i = R_i t_ij with
/// those rotations, weighted by the translation information. Held poses keep their values.
template <class Poses>
void PoseGraph<Poses>::initialize_by_chordal_relaxation() {
  constexpr int d = Poses::kSpaceDim;
  using Rotation = Eigen::Matrix<double, d, d>;
  using Translation = Eigen::Matrix<double, d, 1>;
  if (poses_.empty()) return;
  hold_gauge_if_free();
  std::vector<Eigen::Index> offset(poses_.size(), -1);
  Eigen::Index dimension = 0;
  std::vector<Rotation> held_rotations(poses_.size());
  std::vector<Translation> held_translations(poses_.size());
  for (std::size_t slot = 0; slot < poses_.size(); ++slot) {
    held_rotations[slot] = Poses::rotation_of(poses_[slot]).transpose();  // rows of R as columns
    held_translations[slot] = Poses::translation_of(poses_[slot]);
    if (!vertices_[pose_vertex_[slot]].fixed) {
      offset[slot] = dimension;
      dimension += d;
    }
  }
  if (dimension == 0) return;
  if (betweens_.empty() && priors_.empty())
    throw numerical_error("chordal relaxation: no edge ties the free poses to a held one");
  auto rotation_weight = [](const EdgeInformation& information) {
    return Rotation::Identity() * (information.template bottomRightCorner<E - d, E - d>().trace() / (E - d));
  };
  // rows r_i of R_i (as columns, all d rows at once): r_j = R_ij^T r_i, i.e. R_ij^T r_i - r_j = 0
  detail::BlockLeastSquares<d, d> rotations(offset, held_rotations, dimension);
  for (const auto& edge : betweens_)
    if (!edge.rejected)
      rotations.add(edge.from, Poses::rotation_of(edge.z).transpose(), edge.to, -Rotation::Identity(), Rotation::Zero(),
                  rotation_weight(edge.information));
  for (const auto& prior : priors_)
    rotations.add_unary(prior.pose, Poses::rotation_of(prior.z).transpose(), rotation_weight(prior.information));
  const Eigen::MatrixXd rows = rotations.solve();
  std::vector<Rotation> R(poses_.size());
  for (std::size_t slot = 0; slot < poses_.size(); ++slot)
    R[slot] = offset[slot] < 0 ? Poses::rotation_of(poses_[slot])
                               : detail::nearest_rotation<d>(Rotation(rows.block(offset[slot], 0, d, d).transpose()));
  // translations: t_j - t_i = R_i t_ij, weighted by the translation information in the world frame
  detail::BlockLeastSquares<d, 1> translations(offset, held_translations, dimension);
  for (const auto& edge : betweens_) {
    if (edge.rejected) continue;
    const Rotation frame = R[edge.from] * Poses::rotation_of(edge.z);
    const Rotation W = frame * edge.information.template topLeftCorner<d, d>() * frame.transpose();
    translations.add(edge.from, -Rotation::Identity(), edge.to, Rotation::Identity(),
                     R[edge.from] * Translation(Poses::translation_of(edge.z)), W);
  }
  for (const auto& prior : priors_) {
    const Rotation frame = Poses::rotation_of(prior.z);
    translations.add_unary(prior.pose, Poses::translation_of(prior.z),
                           frame * prior.information.template topLeftCorner<d, d>() * frame.transpose());
  }
  const Eigen::MatrixXd t = translations.solve();
  for (std::size_t slot = 0; slot < poses_.size(); ++slot)
    if (offset[slot] >= 0) poses_[slot] = Poses::make(R[slot], Translation(t.block(offset[slot], 0, d, 1)));
  initialize_points_from_first_observations();
}

}  // namespace sextant
