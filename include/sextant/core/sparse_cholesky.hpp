#pragma once
/// \file Sparse Cholesky solves of an SPD system that keep the symbolic analysis while the sparsity
/// pattern stays the same (Gauss-Newton iterations, repeated optimizations of an unchanged graph).
/// SuiteSparse CHOLMOD (supernodal) when SEXTANT_HAS_CHOLMOD is defined, else Eigen's SimplicialLLT.

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>
#ifdef SEXTANT_HAS_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "sextant/core/error.hpp"

namespace sextant {

class SparseCholesky {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;

  SparseCholesky() = default;
  /// Copies start without a cached analysis (the factorization objects cannot be shared).
  SparseCholesky(const SparseCholesky&) {}
  SparseCholesky& operator=(const SparseCholesky&) {
    impl_.reset();
    return *this;
  }

  /// Factorizes A (symmetric, both triangles or the lower one stored, compressed); analyses the
  /// pattern only when it differs from the last one. Throws numerical_error if A is not PD.
  void factorize(const SparseMatrix& A) {
    if (!impl_ || !same_pattern(A)) {
      impl_ = std::make_unique<Impl>();
      impl_->solver.analyzePattern(A);
      outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
      inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
      ++analyses_;
    }
    impl_->solver.factorize(A);
    if (impl_->solver.info() != Eigen::Success) {
      impl_.reset();
      throw numerical_error("information matrix is not positive definite (sparse Cholesky failed)");
    }
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const { return impl_->solver.solve(b); }
  /// Several right-hand sides at once (e.g. the columns of a marginal covariance).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const { return impl_->solver.solve(B); }

  /// How many symbolic analyses this object has done.
  int analyses() const { return analyses_; }
  static constexpr const char* backend() {
#ifdef SEXTANT_HAS_CHOLMOD
    return "CHOLMOD supernodal";
#else
    return "Eigen SimplicialLLT";
#endif
  }

 private:
  struct Impl {
#ifdef SEXTANT_HAS_CHOLMOD
    Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> solver;
#else
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> solver;
#endif
  };

  bool same_pattern(const SparseMatrix& A) const {
    return A.outerSize() + 1 == static_cast<Eigen::Index>(outer_.size()) &&
           A.nonZeros() == static_cast<Eigen::Index>(inner_.size()) &&
           std::equal(outer_.begin(), outer_.end(), A.outerIndexPtr()) &&
           std::equal(inner_.begin(), inner_.end(), A.innerIndexPtr());
  }

  std::unique_ptr<Impl> impl_;
  std::vector<int> outer_, inner_;
  int analyses_ = 0;
};

}  // namespace sextant
