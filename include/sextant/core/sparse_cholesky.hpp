#pragma once
/// \file Sparse Cholesky solves of an SPD system that keep the symbolic analysis while the sparsity
/// pattern stays the same (Gauss-Newton iterations, repeated optimizations of an unchanged graph).
/// SuiteSparse CHOLMOD (supernodal) when SEXTANT_HAS_CHOLMOD is defined, else Eigen's SimplicialLLT.
/// CHOLMOD's factorization is supernodal, or chosen by the fill (Factorization::by_fill: simplicial
/// where the factor is sparse, as in pose graphs, as Ceres lets CHOLMOD choose): on the pose-graph
/// benchmarks by_fill is 2.4x faster on intel and 2.7x on manhattan and even on city10000 and
/// sphere2500 (docs/results/pose_graphs.md).

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <limits>
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

  enum class Factorization {
    supernodal,  ///< always supernodal (dense blocks through BLAS)
    by_fill,     ///< CHOLMOD's choice between supernodal and simplicial by the factor's fill
  };

  explicit SparseCholesky(Factorization factorization = Factorization::supernodal) : factorization_(factorization) {}
  /// Copies start without a cached analysis (the factorization objects cannot be shared).
  SparseCholesky(const SparseCholesky& other) : factorization_(other.factorization_) {}
  SparseCholesky& operator=(const SparseCholesky& other) {
    impl_.reset();
    factorization_ = other.factorization_;
    return *this;
  }

  /// Factorizes A (symmetric, both triangles or the lower one stored, compressed); analyses the
  /// pattern only when it differs from the last one. Throws numerical_error if A is not PD.
  void factorize(const SparseMatrix& A) {
    analyze(A);
    if (!impl_->factorize(A)) {
      impl_.reset();
      throw numerical_error("information matrix is not positive definite (sparse Cholesky failed)");
    }
  }

  /// The flops of factorizing a matrix of A's pattern, as the symbolic analysis (made here when the
  /// pattern differs from the last one; factorize(A) then reuses it) predicts them: CHOLMOD's count
  /// for LL^T in its fill-reducing order. NaN without CHOLMOD (Eigen's simplicial LL^T does not say).
  double predicted_flops(const SparseMatrix& A) {
    analyze(A);
    return impl_->flops();
  }

  Eigen::VectorXd solve(const Eigen::VectorXd& b) const { return impl_->solve(b); }
  /// Several right-hand sides at once (e.g. the columns of a marginal covariance).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& B) const { return impl_->solve(B); }

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
  /// The solver of each kind; the pattern is analysed when the Impl is made. Without CHOLMOD both
  /// are Eigen's simplicial LL^T.
  struct Impl {
#ifdef SEXTANT_HAS_CHOLMOD
    Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> supernodal;
    Eigen::CholmodDecomposition<SparseMatrix, Eigen::Lower> by_fill;
#else
    Eigen::SimplicialLLT<SparseMatrix, Eigen::Lower, Eigen::AMDOrdering<int>> supernodal, by_fill;
#endif
    Factorization kind;

    explicit Impl(Factorization k) : kind(k) {}
    /// False when CHOLMOD reports an error (its factor would then be missing).
    bool analyze(const SparseMatrix& A) {
      if (kind == Factorization::supernodal) {
        supernodal.analyzePattern(A);
        return analysis_succeeded(supernodal);
      }
#ifdef SEXTANT_HAS_CHOLMOD
      by_fill.setMode(Eigen::CholmodAuto);  // supernodal or simplicial by the fill
      by_fill.cholmod().final_asis = 0;     // LL^T either way: a pivot <= 0 fails (not PD)
      by_fill.cholmod().final_ll = 1;
#endif
      by_fill.analyzePattern(A);
      return analysis_succeeded(by_fill);
    }
    template <class Solver>
    static bool analysis_succeeded(Solver& solver) {
#ifdef SEXTANT_HAS_CHOLMOD
      return solver.cholmod().status >= CHOLMOD_OK;
#else
      return solver.info() == Eigen::Success;
#endif
    }
    bool factorize(const SparseMatrix& A) {
      if (kind == Factorization::supernodal) {
        supernodal.factorize(A);
        return supernodal.info() == Eigen::Success;
      }
      by_fill.factorize(A);
      return by_fill.info() == Eigen::Success;
    }
    double flops() {
#ifdef SEXTANT_HAS_CHOLMOD
      return kind == Factorization::supernodal ? supernodal.cholmod().fl : by_fill.cholmod().fl;
#else
      return std::numeric_limits<double>::quiet_NaN();
#endif
    }
    template <class Rhs>
    Rhs solve(const Rhs& b) const {
      return kind == Factorization::supernodal ? Rhs(supernodal.solve(b)) : Rhs(by_fill.solve(b));
    }
  };

  /// The symbolic analysis of A's pattern, unless the last one was of the same pattern.
  void analyze(const SparseMatrix& A) {
    if (A.rows() == 0 || A.nonZeros() == 0)  // CHOLMOD cannot analyse a matrix without entries
      throw numerical_error("information matrix is empty or zero (not positive definite)");
    if (impl_ && same_pattern(A)) return;
    impl_ = std::make_unique<Impl>(factorization_);
    if (!impl_->analyze(A)) {
      impl_.reset();
      throw numerical_error("the sparse Cholesky analysis of the information matrix failed");
    }
    outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    ++analyses_;
  }

  bool same_pattern(const SparseMatrix& A) const {
    return A.outerSize() + 1 == static_cast<Eigen::Index>(outer_.size()) &&
           A.nonZeros() == static_cast<Eigen::Index>(inner_.size()) &&
           std::equal(outer_.begin(), outer_.end(), A.outerIndexPtr()) &&
           std::equal(inner_.begin(), inner_.end(), A.innerIndexPtr());
  }

  Factorization factorization_ = Factorization::supernodal;
  std::unique_ptr<Impl> impl_;
  std::vector<int> outer_, inner_;
  int analyses_ = 0;
};

}  // namespace sextant
