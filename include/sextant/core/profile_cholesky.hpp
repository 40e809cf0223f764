#pragma once
/// \file An incremental Cholesky factorization S = L L^T of a symmetric positive definite matrix of
/// B x B blocks in profile (envelope) storage: block row i keeps its blocks from its first non-zero
/// column first_i to the diagonal. The factor's fill stays inside the envelope of S (George and
/// Liu, "Computer Solution of Large Sparse Positive Definite Systems", 1981, ch. 4), and rows before
/// the first changed one keep their factor: if S changes only in rows and columns >= e, then
/// L[:e, :] and L[e:, :e] are unchanged and
///     L[e:, e:] = chol(S[e:, e:] - L[e:, :e] L[e:, :e]^T).
/// Rows in chronological order (the poses of an online smoother) make e the oldest pose a new
/// factor reaches: the work of a step depends on how far back it reaches, not on how many rows
/// precede (docs/derivations/incremental_graph_slam.md). The trailing block is factorized densely
/// (Eigen's blocked LLT), in place in a MatrixWorkspace kept from one call to the next.
///
/// Where rows reach far back (a robot that loops through the same places: each row's envelope then
/// spans the loops between), the trailing block is most of the matrix and mostly zero blocks, and
/// a sparse factorization of the whole matrix in a fill-reducing order (core/sparse_cholesky.hpp,
/// CHOLMOD) costs a fraction of it. factorize() weighs the two by their flops once the dense one
/// passes kSparseCheckFlops and takes the sparse one where it is far cheaper. A sparse step leaves
/// no profile factor: the next steps weigh a dense refactorization from row 0 against a sparse one,
/// so once the envelope has grown wide they stay sparse (a whole factorization a step, in the order
/// that keeps its fill small).
///
/// Changes are a transaction: add() and append_row() stage copies of the rows they touch,
/// factorize() computes the staged matrix's factor (solve() and last_inverse_block() then use it),
/// commit() keeps both, discard() drops them (matrix and factor exactly as before). factorize()
/// throws numerical_error and discards when the staged matrix is not positive definite.

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sextant/core/error.hpp"
#include "sextant/core/matrix_workspace.hpp"
#include "sextant/core/sparse_cholesky.hpp"

namespace sextant {

template <int B>
class ProfileCholesky {
 public:
  using Block = Eigen::Matrix<double, B, B>;
  using Vector = Eigen::VectorXd;

  ProfileCholesky() = default;
  /// A copy has its own sparse factors, factorized again from its matrix (CHOLMOD's cannot be copied).
  ProfileCholesky(const ProfileCholesky& other)
      : matrix_(other.matrix_),
        factor_(other.factor_),
        staged_index_(other.staged_index_),
        staged_rows_(other.staged_rows_),
        staged_ids_(other.staged_ids_),
        staged_factor_(other.staged_factor_),
        refactorized_from_(other.refactorized_from_),
        next_sparse_check_(other.next_sparse_check_),
        staged_sparse_check_(other.staged_sparse_check_),
        factorized_(other.factorized_),
        staged_count_(other.staged_count_),
        first_changed_(other.first_changed_) {
    if (other.committed_sparse_) committed_sparse_ = sparse_factor_of(lower_triangle(matrix_.size(), false));
    if (other.staged_sparse_) staged_sparse_ = sparse_factor_of(lower_triangle(staged_count_, true));
  }
  ProfileCholesky& operator=(const ProfileCholesky& other) {
    if (this != &other) *this = ProfileCholesky(other);
    return *this;
  }
  ProfileCholesky(ProfileCholesky&&) noexcept = default;
  ProfileCholesky& operator=(ProfileCholesky&&) noexcept = default;
  ~ProfileCholesky() = default;

  /// Block rows of the committed matrix.
  std::size_t rows() const { return matrix_.size(); }
  /// Block rows including the staged ones.
  std::size_t staged_rows() const { return staged_count_; }
  /// The first block row the staged changes touch (rows() when nothing is staged).
  std::size_t first_changed() const { return first_changed_; }
  /// Whether the last factorize() took the sparse factorization of the whole matrix.
  bool factorized_sparse() const { return factorized_ ? staged_sparse_ != nullptr : committed_sparse_ != nullptr; }

  /// Past this many flops of the trailing dense factorization (a few milliseconds), factorize()
  /// asks a sparse one what it would cost, and takes it where it is kSparseAdvantage times cheaper:
  /// CHOLMOD's kernels, the assembly and the analysis cost more a flop than the dense blocked LLT
  /// in place (on the thesis-scale globe, whose coupling is dense, a sparse factorization predicted
  /// 5-15% cheaper took 20% longer). A check that finds no such saving is not made again until the
  /// dense cost has doubled, so that a dense problem pays for a few analyses, not one a frame.
  static constexpr double kSparseCheckFlops = 2e7;
  static constexpr double kSparseAdvantage = 10.0;

  /// Stages a new block row (zero; it must get a positive definite diagonal before factorize()).
  void append_row() {
    staged_index_.push_back(static_cast<long>(staged_rows_.size()));
    staged_rows_.push_back(Row{staged_count_, Eigen::Matrix<double, B, Eigen::Dynamic>::Zero(B, B)});
    staged_ids_.push_back(staged_count_);
    first_changed_ = std::min(first_changed_, staged_count_);
    ++staged_count_;
  }

  /// Stages S_ij += block for i >= j (the diagonal block i == j is added whole and must be symmetric).
  void add(std::size_t i, std::size_t j, const Block& block) {
    if (j > i || i >= staged_count_) throw invalid_input_error("ProfileCholesky::add: block (" + std::to_string(i) + ", " + std::to_string(j) + ") is not in the lower triangle of the matrix");
    Row& row = staged_row(i);
    if (j < row.first) extend_left(row, j);
    row.blocks.template middleCols<B>(B * static_cast<Eigen::Index>(j - row.first)) += block;
    first_changed_ = std::min(first_changed_, j);
  }

  /// Factorizes the staged matrix from its first changed row (the factor stays staged); throws
  /// numerical_error, and discards, if it is not positive definite.
  void factorize() {
    try {
      refactorized_from_ = first_refactorized_row();
      const std::size_t reach = trailing_reach(refactorized_from_);
      const double dense = trailing_flops(refactorized_from_, reach);
      if (!(dense > next_sparse_check_) || !factorize_sparse_if_cheaper(dense))
        staged_factor_ = factorized_trailing_rows(reach);
      factorized_ = true;
    } catch (...) {
      discard();
      throw;
    }
  }

  /// Keeps the staged matrix and its factor (factorize() first).
  void commit() {
    if (!factorized_) throw std::logic_error("ProfileCholesky::commit before factorize");
    matrix_.resize(staged_count_);
    for (std::size_t k = 0; k < staged_ids_.size(); ++k) matrix_[staged_ids_[k]] = std::move(staged_rows_[k]);
    if (staged_sparse_) {
      factor_.clear();  // a later dense step refactorizes from row 0 (first_refactorized_row)
    } else {
      factor_.resize(refactorized_from_);
      for (auto& row : staged_factor_) factor_.push_back(std::move(row));
    }
    committed_sparse_ = std::move(staged_sparse_);
    next_sparse_check_ = staged_sparse_check_;
    discard();
  }

  /// Drops the staged changes.
  void discard() {
    for (std::size_t i : staged_ids_)
      if (i < staged_index_.size()) staged_index_[i] = -1;
    staged_index_.resize(matrix_.size(), -1);
    staged_rows_.clear();
    staged_ids_.clear();
    staged_factor_.clear();
    staged_sparse_.reset();
    staged_sparse_check_ = next_sparse_check_;
    factorized_ = false;
    staged_count_ = matrix_.size();
    first_changed_ = matrix_.size();
  }

  /// x with S x = b (the staged factor after factorize(), else the committed one), by one forward
  /// and one backward substitution.
  Vector solve(const Vector& b) const {
    if (const SparseCholesky* sparse = sparse_factor()) return sparse->solve(b);
    const std::size_t n = factor_rows();
    Vector y(b.size());
    for (std::size_t i = 0; i < n; ++i) {
      const Row& row = factor_row(i);
      const Eigen::Index first = B * static_cast<Eigen::Index>(row.first), width = B * static_cast<Eigen::Index>(i) - first;
      Eigen::Matrix<double, B, 1> r = b.template segment<B>(B * static_cast<Eigen::Index>(i));
      r.noalias() -= row.blocks.leftCols(width) * y.segment(first, width);
      y.template segment<B>(B * static_cast<Eigen::Index>(i)) = diagonal(row).template triangularView<Eigen::Lower>().solve(r);
    }
    Vector x = y;  // accumulates y - L^T x as the rows below are solved
    for (std::size_t i = n; i-- > 0;) {
      const Row& row = factor_row(i);
      const Eigen::Index first = B * static_cast<Eigen::Index>(row.first), width = B * static_cast<Eigen::Index>(i) - first;
      auto xi = x.template segment<B>(B * static_cast<Eigen::Index>(i));
      xi = diagonal(row).transpose().template triangularView<Eigen::Upper>().solve(Eigen::Matrix<double, B, 1>(xi));
      x.segment(first, width).noalias() -= row.blocks.leftCols(width).transpose() * xi;
    }
    return x;
  }

  /// The block of S^-1 at the last row (the factor solve() uses): (L_nn L_nn^T)^-1, since L^-1 is lower triangular.
  Block last_inverse_block() const {
    if (const SparseCholesky* sparse = sparse_factor()) {
      Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(B * static_cast<Eigen::Index>(factor_rows()), B);
      unit.bottomRows(B).setIdentity();
      return sparse->solve(unit).bottomRows(B);
    }
    const Block L = diagonal(factor_row(factor_rows() - 1));
    const Block L_inv = L.template triangularView<Eigen::Lower>().solve(Block::Identity());
    return L_inv.transpose() * L_inv;
  }

  /// The committed diagonal block S_ii.
  Block diagonal_block(std::size_t i) const { return diagonal(matrix_.at(i)); }

  /// The committed matrix as a dense symmetric matrix (tests, small problems).
  Eigen::MatrixXd dense() const {
    const Eigen::Index n = B * static_cast<Eigen::Index>(matrix_.size());
    Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t i = 0; i < matrix_.size(); ++i) {
      const Row& row = matrix_[i];
      out.block(B * static_cast<Eigen::Index>(i), B * static_cast<Eigen::Index>(row.first), B, row.blocks.cols()) = row.blocks;
    }
    return out.selfadjointView<Eigen::Lower>();
  }

 private:
  struct Row {
    std::size_t first;  ///< first non-zero block column
    Eigen::Matrix<double, B, Eigen::Dynamic> blocks;  ///< columns first .. i
  };

  static Block diagonal(const Row& row) { return row.blocks.template rightCols<B>(); }

  std::size_t factor_rows() const {
    return factorized_ ? staged_count_ : committed_sparse_ ? matrix_.size() : factor_.size();
  }
  const Row& factor_row(std::size_t i) const {
    return factorized_ && i >= refactorized_from_ ? staged_factor_[i - refactorized_from_] : factor_[i];
  }
  /// The sparse factor solve() uses: the staged one after a sparse factorize(), else the committed
  /// one when the last committed step was sparse; null when it is the profile factor.
  const SparseCholesky* sparse_factor() const {
    return factorized_ ? staged_sparse_.get() : committed_sparse_.get();
  }

  /// Where the dense refactorization starts: the first changed row, or row 0 after a sparse step
  /// (which leaves no profile factor).
  std::size_t first_refactorized_row() const { return committed_sparse_ ? 0 : first_changed_; }

  /// The oldest column a trailing row (e and after) reaches: the kept factor's columns reach .. e - 1
  /// update the trailing block.
  std::size_t trailing_reach(std::size_t e) const {
    std::size_t reach = e;
    for (std::size_t i = e; i < staged_count_; ++i) reach = std::min(reach, matrix_row(i).first);
    return reach;
  }

  /// The flops of factorized_trailing_rows() from row e: m^3 / 3 for the trailing block of m
  /// columns, m^2 w for its update with the w columns of the kept factor from `reach` to e.
  double trailing_flops(std::size_t e, std::size_t reach) const {
    const double m = B * static_cast<double>(staged_count_ - e), w = B * static_cast<double>(e - reach);
    return m * m * m / 3.0 + m * m * w;
  }

  /// The staged matrix factorized as one sparse matrix (CHOLMOD's fill-reducing order) when its
  /// analysis predicts a tenth of `dense`'s flops or less (kSparseAdvantage); false, and nothing
  /// factorized, otherwise (and always without CHOLMOD, whose analysis alone predicts them).
  bool factorize_sparse_if_cheaper(double dense) {
    const Eigen::SparseMatrix<double> S = lower_triangle(staged_count_, true);
    auto sparse = std::make_unique<SparseCholesky>(SparseCholesky::Factorization::by_fill);
    if (!(kSparseAdvantage * sparse->predicted_flops(S) < dense)) {
      staged_sparse_check_ = 2.0 * dense;  // kept by commit(), as the factor is
      return false;
    }
    sparse->factorize(S);  // on the analysis predicted_flops made
    staged_sparse_ = std::move(sparse);
    return true;
  }

  /// A copy's sparse factor (the copy constructor's).
  static std::unique_ptr<SparseCholesky> sparse_factor_of(const Eigen::SparseMatrix<double>& S) {
    auto sparse = std::make_unique<SparseCholesky>(SparseCholesky::Factorization::by_fill);
    sparse->factorize(S);
    return sparse;
  }

  /// The lower triangle of the first `rows` block rows (of the staged matrix, or of the committed
  /// one), its blocks that are not zero.
  Eigen::SparseMatrix<double> lower_triangle(std::size_t rows, bool staged) const {
    std::vector<Eigen::Triplet<double>> entries;
    for (std::size_t i = 0; i < rows; ++i) {
      const Row& row = staged ? matrix_row(i) : matrix_[i];
      for (std::size_t j = row.first; j <= i; ++j) {
        const auto block = row.blocks.template middleCols<B>(B * static_cast<Eigen::Index>(j - row.first));
        if (j < i && block.isZero(0.0)) continue;
        for (int c = 0; c < B; ++c)
          for (int r = j < i ? 0 : c; r < B; ++r)
            entries.emplace_back(B * static_cast<int>(i) + r, B * static_cast<int>(j) + c, block(r, c));
      }
    }
    const Eigen::Index n = B * static_cast<Eigen::Index>(rows);
    Eigen::SparseMatrix<double> S(n, n);
    S.setFromTriplets(entries.begin(), entries.end());
    return S;
  }

  Row& staged_row(std::size_t i) {
    if (staged_index_[i] < 0) {
      staged_index_[i] = static_cast<long>(staged_rows_.size());
      staged_rows_.push_back(matrix_[i]);
      staged_ids_.push_back(i);
    }
    return staged_rows_[static_cast<std::size_t>(staged_index_[i])];
  }

  static void extend_left(Row& row, std::size_t first) {
    const Eigen::Index extra = B * static_cast<Eigen::Index>(row.first - first);
    Eigen::Matrix<double, B, Eigen::Dynamic> wider = Eigen::Matrix<double, B, Eigen::Dynamic>::Zero(B, extra + row.blocks.cols());
    wider.rightCols(row.blocks.cols()) = row.blocks;
    row.blocks = std::move(wider);
    row.first = first;
  }

  const Row& matrix_row(std::size_t i) const {
    return staged_index_[i] < 0 ? matrix_[i] : staged_rows_[static_cast<std::size_t>(staged_index_[i])];
  }

  /// The factor's rows e .. n - 1 of the staged matrix: chol(S[e:, e:] - L[e:, :e] L[e:, :e]^T),
  /// factorized in place in memory kept from one call to the next (a dense block allocated, zeroed
  /// and copied afresh each frame cost more than its factorization on a host slow to hand out pages).
  /// `reach`: trailing_reach(e), which factorize() has computed for the cost already.
  std::vector<Row> factorized_trailing_rows(std::size_t reach) {
    const std::size_t e = refactorized_from_, n = staged_count_;
    const Eigen::Index m = B * static_cast<Eigen::Index>(n - e), below = B * static_cast<Eigen::Index>(e - reach);
    auto T = trailing_.view(m);
    auto kept = kept_.view(m, below);
    for (std::size_t i = e; i < n; ++i) write_trailing_row(i, T, kept);
    if (below > 0) T.template selfadjointView<Eigen::Lower>().rankUpdate(kept, -1.0);
    for (Eigen::Index at = 0; at < m; at += B)  // the lower triangle, the part written and factorized
      if (!T.block(at, 0, B, at + B).allFinite()) throw numerical_error("information matrix has NaN or Inf entries (incremental Cholesky)");
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(T);
    if (llt.info() != Eigen::Success)
      throw numerical_error("information matrix is not positive definite (incremental Cholesky from block row " + std::to_string(e) + ")");
    std::vector<Row> out;
    out.reserve(n - e);
    for (std::size_t i = e; i < n; ++i) out.push_back(factor_row_from(i, T));
    return out;
  }

  /// Block row i of the trailing block T's lower triangle (S_i from column e on, zero left of its
  /// envelope) and of `kept` (the committed factor's last kept.cols() columns before e, unchanged).
  void write_trailing_row(std::size_t i, Eigen::Ref<Eigen::MatrixXd> T, Eigen::Ref<Eigen::MatrixXd> kept) const {
    const std::size_t e = refactorized_from_;
    const Row& row = matrix_row(i);
    const Eigen::Index at = B * static_cast<Eigen::Index>(i - e);
    const std::size_t from = std::max(row.first, e);
    T.block(at, 0, B, B * static_cast<Eigen::Index>(from - e)).setZero();
    T.block(at, B * static_cast<Eigen::Index>(from - e), B, B * static_cast<Eigen::Index>(i + 1 - from)) =
        row.blocks.rightCols(B * static_cast<Eigen::Index>(i + 1 - from));
    if (kept.cols() == 0) return;
    const Eigen::Index width = row.first < e ? B * static_cast<Eigen::Index>(e - row.first) : 0;
    kept.block(at, 0, B, kept.cols() - width).setZero();
    if (width > 0) kept.block(at, kept.cols() - width, B, width) = factor_[i].blocks.leftCols(width);
  }

  /// Factor row i (i >= e): the unchanged columns before e, then row i - e of the trailing factor
  /// (lower triangle of T, the diagonal block's upper part zero).
  Row factor_row_from(std::size_t i, const Eigen::Ref<const Eigen::MatrixXd>& T) const {
    const std::size_t e = refactorized_from_;
    const Row& row = matrix_row(i);
    Row r{row.first, Eigen::Matrix<double, B, Eigen::Dynamic>(B, row.blocks.cols())};
    const std::size_t from = std::max(row.first, e);
    const Eigen::Index at = B * static_cast<Eigen::Index>(i - e), tail = B * static_cast<Eigen::Index>(i + 1 - from);
    r.blocks.rightCols(tail) = T.block(at, B * static_cast<Eigen::Index>(from - e), B, tail);
    r.blocks.template rightCols<B>().template triangularView<Eigen::StrictlyUpper>().setZero();
    if (row.first < e) r.blocks.leftCols(r.blocks.cols() - tail) = factor_[i].blocks.leftCols(r.blocks.cols() - tail);
    return r;
  }

  std::vector<Row> matrix_;  ///< S, committed
  std::vector<Row> factor_;  ///< L of the committed S
  std::vector<long> staged_index_;  ///< per row: its position in staged_rows_, -1 if not staged
  std::vector<Row> staged_rows_;    ///< copies of the rows the staged changes touch, and new rows
  std::vector<std::size_t> staged_ids_;  ///< the row of each staged copy
  std::vector<Row> staged_factor_;  ///< rows refactorized_from_ .. of the staged matrix's factor
  std::unique_ptr<SparseCholesky> staged_sparse_;     ///< the staged matrix's factor when factorize() went sparse
  std::unique_ptr<SparseCholesky> committed_sparse_;  ///< the committed matrix's, when its step went sparse
  MatrixWorkspace trailing_, kept_;  ///< factorize()'s dense blocks, kept between calls (scratch)
  std::size_t refactorized_from_ = 0;  ///< the first row of staged_factor_ (first_refactorized_row())
  double next_sparse_check_ = kSparseCheckFlops;  ///< dense flops past which factorize() weighs a sparse step
  double staged_sparse_check_ = kSparseCheckFlops;  ///< the staged step's, kept by commit()
  bool factorized_ = false;
  std::size_t staged_count_ = 0;
  std::size_t first_changed_ = 0;
};

}  // namespace sextant
