#include "sextant/core/dense_cholesky.hpp"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cstdlib>
#include <limits>
#include <random>

#include "sextant/core/error.hpp"
#include "sextant/core/gaussian.hpp"
#include "sextant/core/symmetric_rank_update.hpp"

#ifdef SEXTANT_HAS_LAPACK
extern "C" int openblas_get_num_threads();
#endif

namespace sextant {
namespace {

/// A random symmetric positive definite n x n matrix with condition number about 1e4: Q diag Q^T.
Eigen::MatrixXd random_spd(Eigen::Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd g(n, n);
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i) g(i, j) = normal(rng);
  const Eigen::MatrixXd q = Eigen::HouseholderQR<Eigen::MatrixXd>(g).householderQ();
  const Eigen::VectorXd eigenvalues = Eigen::VectorXd::LinSpaced(n, 1e-4, 1.0);
  return q * eigenvalues.asDiagonal() * q.transpose();
}

/// Sizes on both sides of kLapackMinDimension: with sextant::lapack linked both paths run.
const Eigen::Index kSizes[] = {1, 8, kLapackMinDimension - 1, kLapackMinDimension, 200};

// Backward stability: L L^T = A + E with |E| <= c n u |A| (Higham, Thm 10.3); 100 n u is generous.
double factor_tolerance(Eigen::Index n) { return 100.0 * static_cast<double>(n) * std::numeric_limits<double>::epsilon(); }

TEST(DenseCholesky, FactorReproducesTheMatrixAndLeavesTheStrictUpperTriangleAlone) {
  for (const Eigen::Index n : kSizes) {
    const Eigen::MatrixXd a = random_spd(n, static_cast<unsigned>(n));
    Eigen::MatrixXd work = a;
    work.triangularView<Eigen::StrictlyUpper>().setConstant(7.0);  // must survive
    ASSERT_TRUE(factorize_lower_in_place(work)) << "n = " << n;
    const Eigen::MatrixXd L = work.triangularView<Eigen::Lower>();
    EXPECT_LE((L * L.transpose() - a).norm(), factor_tolerance(n) * a.norm()) << "n = " << n;
    for (Eigen::Index j = 1; j < n; ++j)
      for (Eigen::Index i = 0; i < j; ++i) ASSERT_EQ(work(i, j), 7.0) << "n = " << n;
  }
}

TEST(DenseCholesky, FactorizesAViewWithAnOuterStrideInPlace) {
  const Eigen::Index n = 2 * kLapackMinDimension;
  const Eigen::MatrixXd a = random_spd(n, 11);
  Eigen::MatrixXd big = Eigen::MatrixXd::Constant(n + 37, n + 37, -3.0);  // as MatrixWorkspace's views
  big.topLeftCorner(n, n) = a;
  ASSERT_TRUE(factorize_lower_in_place(big.topLeftCorner(n, n)));
  const Eigen::MatrixXd L = big.topLeftCorner(n, n).triangularView<Eigen::Lower>();
  EXPECT_LE((L * L.transpose() - a).norm(), factor_tolerance(n) * a.norm());
  EXPECT_TRUE((big.bottomRows(37).array() == -3.0).all());
  EXPECT_TRUE((big.rightCols(37).array() == -3.0).all());
}

TEST(DenseCholesky, ReportsAnIndefiniteMatrixOnBothPaths) {
  for (const Eigen::Index n : kSizes) {
    if (n < 2) continue;
    Eigen::MatrixXd a = random_spd(n, 5);
    a(n / 2, n / 2) = -1.0;  // a negative diagonal entry: not positive definite
    EXPECT_FALSE(factorize_lower_in_place(a)) << "n = " << n;
    a = random_spd(n, 5) - Eigen::MatrixXd::Identity(n, n);  // eigenvalues in [-1, 0)
    EXPECT_THROW(cholesky_in_place_or_throw(a, "the test block"), numerical_error) << "n = " << n;
  }
}

TEST(DenseCholesky, SolvesWithTheFactorAndGivesItsSquaredPivots) {
  for (const Eigen::Index n : kSizes) {
    const Eigen::MatrixXd a = random_spd(n, 3 + static_cast<unsigned>(n));
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(n, -1.0, 2.0);
    Eigen::MatrixXd work = a;
    const LowerCholeskyFactor factor = cholesky_in_place_or_throw(work, "the test block");
    const Eigen::VectorXd x = factor.solve(b);
    // cond(a) = 1e4: the residual of a backward-stable solve is a few u |a| |x|.
    EXPECT_LE((a * x - b).norm(), factor_tolerance(n) * a.norm() * x.norm()) << "n = " << n;
    const Eigen::LLT<Eigen::MatrixXd> reference(a);
    EXPECT_TRUE(factor.squared_pivots().isApprox(reference.matrixLLT().diagonal().array().square().matrix(), 1e-10))
        << "n = " << n;
  }
}

#ifdef SEXTANT_HAS_LAPACK
TEST(DenseCholesky, TheProjectsProgramsRunOpenBlasOnTheCallingThread) {
  if (std::getenv("OPENBLAS_NUM_THREADS") != nullptr) GTEST_SKIP() << "OPENBLAS_NUM_THREADS is set: it decides";
  EXPECT_EQ(openblas_get_num_threads(), 1) << "src/blas_on_calling_thread.cpp is not part of this program";
}
#endif

TEST(DenseCholesky, ThrowsNamingTheBlockOnNaN) {
  Eigen::MatrixXd a = random_spd(kLapackMinDimension, 9);
  a(4, 3) = std::numeric_limits<double>::quiet_NaN();  // the lower triangle: all that is read
  try {
    cholesky_in_place_or_throw(a, "the test block");
    FAIL() << "no throw";
  } catch (const numerical_error& e) {
    EXPECT_NE(std::string(e.what()).find("the test block has NaN or Inf"), std::string::npos) << e.what();
  }
}

TEST(DenseCholesky, ReadsOnlyTheLowerTriangle) {
  // The SEIF block is gathered into its lower triangle; what the strict upper triangle holds
  // (NaN here) must not matter, to the factorization nor to the conditioning test.
  for (const Eigen::Index n : kSizes) {
    if (n < 2) continue;
    const Eigen::MatrixXd a = random_spd(n, 13 + static_cast<unsigned>(n));
    Eigen::MatrixXd with_nan_above = a;
    with_nan_above.triangularView<Eigen::StrictlyUpper>().setConstant(std::numeric_limits<double>::quiet_NaN());
    Eigen::MatrixXd clean = a;
    cholesky_in_place_or_throw(clean, "the test block");
    Eigen::MatrixXd work = with_nan_above;
    EXPECT_NO_THROW(cholesky_in_place_or_throw(work, "the test block")) << "n = " << n;
    EXPECT_EQ(Eigen::MatrixXd(work.triangularView<Eigen::Lower>()), Eigen::MatrixXd(clean.triangularView<Eigen::Lower>()));
    work = with_nan_above;
    EXPECT_NO_THROW(require_well_conditioned_in_place(work, "the test block")) << "n = " << n;
    work = with_nan_above;
    work(n - 1, 0) = std::numeric_limits<double>::infinity();  // below the diagonal: read, and named
    EXPECT_THROW(require_well_conditioned_in_place(work, "the test block"), numerical_error) << "n = " << n;
  }
}

/// symmetric_rank_update<UpLo, Of> against the dense product on the `UpLo` triangle, the other strict
/// triangle untouched, at sizes on both sides of kLapackMinDimension.
template <unsigned int UpLo, RankUpdateOf Of = RankUpdateOf::rows>
void check_symmetric_rank_update() {
  constexpr unsigned int other = UpLo == Eigen::Lower ? Eigen::StrictlyUpper : Eigen::StrictlyLower;
  std::mt19937 rng(21);
  std::normal_distribution<double> normal;
  for (const Eigen::Index n : kSizes) {
    for (const Eigen::Index k : {Eigen::Index{1}, Eigen::Index{12}}) {
      const Eigen::MatrixXd A = Eigen::MatrixXd::NullaryExpr(k, n, [&] { return normal(rng); });
      const Eigen::MatrixXd C0 = Eigen::MatrixXd::NullaryExpr(n, n, [&] { return normal(rng); });
      for (const double beta : {0.0, 1.0, 0.5}) {
        Eigen::MatrixXd C = C0;
        if (beta == 0.0)  // not read: garbage must not leak through
          C.triangularView<UpLo>().setConstant(std::numeric_limits<double>::quiet_NaN());
        if constexpr (Of == RankUpdateOf::rows)
          symmetric_rank_update<UpLo>(C, A, -1.5, beta);
        else
          symmetric_rank_update<UpLo, Of>(C, Eigen::MatrixXd(A.transpose()), -1.5, beta);  // the same vectors as columns
        const Eigen::MatrixXd expected = -1.5 * A.transpose() * A + beta * C0;
        const double scale = expected.cwiseAbs().maxCoeff();
        const Eigen::MatrixXd error = (C - expected).triangularView<UpLo>();
        EXPECT_LE(error.cwiseAbs().maxCoeff(), 1e-13 * scale) << "n " << n << " k " << k << " beta " << beta;
        EXPECT_EQ(Eigen::MatrixXd(C.triangularView<other>()), Eigen::MatrixXd(C0.triangularView<other>()))
            << "the other triangle changed, n " << n;
      }
    }
  }
}

TEST(SymmetricRankUpdate, IsAlphaATransposeAPlusBetaCOnTheUpperTriangleOnBothPaths) {
  check_symmetric_rank_update<Eigen::Upper>();
}

TEST(SymmetricRankUpdate, IsAlphaATransposeAPlusBetaCOnTheLowerTriangleOnBothPaths) {
  check_symmetric_rank_update<Eigen::Lower>();
}

TEST(SymmetricRankUpdate, OfColumnsIsAlphaAATransposePlusBetaCOnBothTrianglesAndPaths) {
  check_symmetric_rank_update<Eigen::Lower, RankUpdateOf::columns>();
  check_symmetric_rank_update<Eigen::Upper, RankUpdateOf::columns>();
}

TEST(DenseCholesky, RightSolveWithTheTransposedFactorIsBTimesLInverseTransposedOnBothPaths) {
  // The EKF's W^T = C L^-T, in place: against the dense inverse, and L's strict upper triangle
  // (NaN here) never read, with b of rows on both sides of kLapackMinDimension.
  std::mt19937 rng(22);
  std::normal_distribution<double> normal;
  for (const Eigen::Index rows : kSizes)
    for (const Eigen::Index k : {Eigen::Index{1}, Eigen::Index{6}, Eigen::Index{70}}) {
      Eigen::MatrixXd factor = random_spd(k, 31 + static_cast<unsigned>(k));
      cholesky_in_place_or_throw(factor, "the test block");
      const Eigen::MatrixXd L = factor.triangularView<Eigen::Lower>();
      factor.triangularView<Eigen::StrictlyUpper>().setConstant(std::numeric_limits<double>::quiet_NaN());
      const Eigen::MatrixXd b0 = Eigen::MatrixXd::NullaryExpr(rows, k, [&] { return normal(rng); });
      Eigen::MatrixXd b = b0;
      right_solve_lower_transposed(factor, b);
      const Eigen::MatrixXd expected = b0 * L.transpose().inverse();
      EXPECT_LE((b - expected).cwiseAbs().maxCoeff(), 1e-12 * std::max(1.0, expected.cwiseAbs().maxCoeff()))
          << "rows " << rows << " k " << k;
    }
}

}  // namespace
}  // namespace sextant
