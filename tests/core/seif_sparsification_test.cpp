#include "sextant/core/seif_sparsification.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "support/seif_sparsification_reference.hpp"

namespace sextant {
namespace {

/// A random symmetric positive definite matrix with condition number about `condition`.
Eigen::MatrixXd random_information(Eigen::Index n, double condition, std::mt19937& rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A(n, n);
  for (Eigen::Index i = 0; i < A.size(); ++i) A.data()[i] = normal(rng);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
  const Eigen::MatrixXd Q = qr.householderQ();
  Eigen::VectorXd eigenvalues(n);
  for (Eigen::Index i = 0; i < n; ++i) eigenvalues(i) = std::pow(condition, -static_cast<double>(i) / (n - 1));
  return Q * eigenvalues.asDiagonal() * Q.transpose();
}

TEST(SeifSparsification, EqualsTheThesisTwoSchurComplementsOnRandomBlocks) {
  // The thesis's form (eqs. 39-43) computed as written, against the rank-X form, on blocks of the
  // shapes the filters make (planar 3 + 2 m, spatial 6 + 3 m, the camera's 12 + 3 m), conditioned
  // up to 1e6. Both are backward-stable computations of the same matrix; 1e-9 relative leaves room
  // for the condition number times the rounding of either.
  std::mt19937 rng(3);
  for (const auto [X, M, kept, dropped] : std::vector<std::array<int, 4>>{{3, 2, 8, 3}, {6, 3, 10, 5}, {12, 3, 40, 30}}) {
    for (const double condition : {1e2, 1e6}) {
      const Eigen::Index n = X + M * (kept + dropped);
      const Eigen::MatrixXd D = random_information(n, condition, rng);
      const Eigen::MatrixXd expected = test::thesis_sparsification_change(D, X, M * kept);
      Eigen::MatrixXd change;
      if (X == 3) change = test::sparsification_change_as_matrix<3>(D, M * kept);
      if (X == 6) change = test::sparsification_change_as_matrix<6>(D, M * kept);
      if (X == 12) change = test::sparsification_change_as_matrix<12>(D, M * kept);
      const double scale = expected.cwiseAbs().maxCoeff();
      EXPECT_LT((change - expected).cwiseAbs().maxCoeff(), 1e-9 * scale)
          << "X " << X << ", " << kept << " kept, " << dropped << " dropped, condition " << condition;
    }
  }
}

TEST(SeifSparsification, NamesTheBlockThatIsNotPositiveDefinite) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Identity(3 + 2 * 4, 3 + 2 * 4);
  D(9, 9) = -1.0;  // a landmark to deactivate
  try {
    test::sparsification_change_as_matrix<3>(D, 4);
    FAIL() << "no error";
  } catch (const numerical_error& e) {
    EXPECT_NE(std::string(e.what()).find("landmarks to deactivate"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sextant
