#pragma once
/// \file A Gaussian over (robot, landmarks) in error-state information form: the information
/// matrix Omega, stored by blocks (robot, robot-landmark links, landmark diagonals, landmark-landmark
/// links), and the residual r = xi - Omega mu of the information vector at the current mean mu.
/// The mean that the form implies is mu + Omega^-1 r; mean recovery drives r to zero.
/// A transaction (begin_transaction / commit / rollback) records the old value of every block it
/// touches, so a filter step that fails half-way is undone in O(touched blocks), not O(map).

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "sextant/core/block_triplets.hpp"
#include "sextant/core/dense_slot_map.hpp"
#include "sextant/core/error.hpp"
#include "sextant/core/link_rows.hpp"

namespace sextant {

/// SparseInformation::add_to_links' report of the new blocks when the caller wants none.
struct IgnoreChangedLinks {
  template <class Block>
  void operator()(std::size_t, std::size_t, const Block&) const {}
};

template <int X, int M>
class SparseInformation {
 public:
  using RobotBlock = Eigen::Matrix<double, X, X>;
  using CrossBlock = Eigen::Matrix<double, X, M>;  ///< Omega_{x, m}
  using LandmarkBlock = Eigen::Matrix<double, M, M>;
  using RobotVector = Eigen::Matrix<double, X, 1>;
  using LandmarkVector = Eigen::Matrix<double, M, 1>;
  using Links = DenseSlotMap<LandmarkBlock>;  ///< neighbour slot -> Omega_{i, j}

  explicit SparseInformation(const RobotBlock& robot_information = RobotBlock::Identity())
      : robot_(robot_information), robot_residual_(RobotVector::Zero()) {}

  std::size_t num_landmarks() const { return diagonal_.size(); }
  Eigen::Index dim() const { return X + M * static_cast<Eigen::Index>(num_landmarks()); }

  RobotBlock& robot() { return robot_; }  // saved whole when a transaction begins
  const RobotBlock& robot() const { return robot_; }
  RobotVector& robot_residual() { return robot_residual_; }
  const RobotVector& robot_residual() const { return robot_residual_; }

  /// The landmarks linked to the robot (SEIF's active landmarks), with Omega_{x, m}.
  const std::unordered_map<std::size_t, CrossBlock>& robot_links() const { return robot_links_; }
  bool is_linked_to_robot(std::size_t slot) const { return robot_links_.contains(slot); }
  void add_to_robot_link(std::size_t slot, const CrossBlock& block) {
    note_robot_link(slot);
    auto [it, inserted] = robot_links_.try_emplace(slot, block);
    if (!inserted) it->second += block;
  }
  void set_robot_link(std::size_t slot, const CrossBlock& block) {
    note_robot_link(slot);
    robot_links_[slot] = block;
  }
  void remove_robot_link(std::size_t slot) {
    note_robot_link(slot);
    robot_links_.erase(slot);
  }

  LandmarkBlock& diagonal(std::size_t slot) {
    save(slot);
    return diagonal_[slot];
  }
  const LandmarkBlock& diagonal(std::size_t slot) const { return diagonal_[slot]; }
  auto landmark_residual(std::size_t slot) {
    save(slot);
    return landmark_residual_.template segment<M>(M * slot);
  }
  auto landmark_residual(std::size_t slot) const { return landmark_residual_.template segment<M>(M * slot); }

  /// Landmark-landmark links of a slot (both directions are stored).
  const Links& links(std::size_t slot) const { return links_[slot]; }
  /// Omega_{i, j} += block and Omega_{j, i} += block^T, for i != j.
  void add_to_link(std::size_t i, std::size_t j, const LandmarkBlock& block) {
    if (i > j) return add_to_link(j, i, block.transpose());
    auto [it, inserted] = links_[i].try_emplace(j, block);  // one look-up for the journal and the change
    if (open_ && i < journal_.landmarks)
      journal_.links.push_back({i, j, inserted ? std::nullopt : std::optional<LandmarkBlock>(it->second)});
    if (!inserted) it->second += block;
    add_or_insert(links_[j], i, block.transpose());
  }
  /// Omega_{s_a, s_b} += change(a, b) and Omega_{s_b, s_a} += change(a, b)^T for every pair of
  /// positions a < b of `slots` (distinct slots): add_to_link for all pairs, done one landmark's
  /// links at a time, so that each map is probed while it is in cache (pair by pair, every second
  /// write goes to a cold map). change(a, b) is called once from each side and must return the same
  /// block both times. `changed(a, b, block)`, if given, is called for every pair a > b with the new
  /// Omega_{s_a, s_b} (a caller that needs the block afterwards as a dense matrix, its lower
  /// triangle, gets it without looking the links up again).
  template <class Change, class Changed = IgnoreChangedLinks>
  void add_to_links(std::span<const std::size_t> slots, Change change, Changed changed = {}) {
    for (std::size_t a = 0; a < slots.size(); ++a) {
      const std::size_t i = slots[a];
      Links& row = links_[i];
      for (std::size_t b = 0; b < slots.size(); ++b) {
        prefetch_ahead(row, slots, b);
        if (b == a) continue;
        const std::size_t j = slots[b];
        const LandmarkBlock block = a < b ? LandmarkBlock(change(a, b)) : LandmarkBlock(change(b, a).transpose());
        auto [it, inserted] = row.try_emplace(j, block);
        if (open_ && i < j && i < journal_.landmarks)  // the pair's record, made from its first slot's side
          journal_.links.push_back({i, j, inserted ? std::nullopt : std::optional<LandmarkBlock>(it->second)});
        if (!inserted) it->second += block;
        if (b < a) changed(a, b, it->second);
      }
    }
  }
  /// out(b, Omega_{i, slots[b]}) for every b in order (the diagonal block where slots[b] == i, zero
  /// where not linked): landmark_block along one row, its look-ups prefetched ahead.
  template <class Out>
  void for_each_block_in_row(std::size_t i, std::span<const std::size_t> slots, Out out) const {
    const Links& row = links_[i];
    for (std::size_t b = 0; b < slots.size(); ++b) {
      prefetch_ahead(row, slots, b);
      const std::size_t j = slots[b];
      if (j == i) {
        out(b, diagonal_[i]);
        continue;
      }
      const auto it = row.find(j);
      out(b, it == row.end() ? LandmarkBlock::Zero().eval() : it->second);
    }
  }
  /// Omega_{i, j} for any two slots (the diagonal block when i == j, zero when not linked).
  LandmarkBlock landmark_block(std::size_t i, std::size_t j) const {
    if (i == j) return diagonal_[i];
    const auto it = links_[i].find(j);
    return it == links_[i].end() ? LandmarkBlock::Zero() : it->second;
  }
  CrossBlock robot_link(std::size_t slot) const {
    const auto it = robot_links_.find(slot);
    return it == robot_links_.end() ? CrossBlock::Zero() : it->second;
  }

  /// Appends a landmark with no information and no links; returns its slot.
  std::size_t append_landmark() {
    diagonal_.push_back(LandmarkBlock::Zero());
    links_.append();
    saved_in_.push_back(0);
    landmark_residual_.conservativeResize(landmark_residual_.size() + M);
    landmark_residual_.template tail<M>().setZero();
    return diagonal_.size() - 1;
  }

  /// Marginalizes a landmark out (thesis Appendix C): Omega' = Omega_{-j} - Omega_{-j,j} Omega_jj^-1
  /// Omega_{j,-j}, r' = r_{-j} - Omega_{-j,j} Omega_jj^-1 r_j, touching only its neighbours; then the
  /// last slot moves into the freed one. Throws numerical_error (form unchanged) if Omega_jj is not PD.
  void marginalize_landmark(std::size_t slot);
  /// Whether marginalize_landmark(slot) would add no link: its neighbours (the robot among them when
  /// linked) are already linked pair by pair, a simplicial vertex of Omega's graph. O(d^2) look-ups.
  bool marginalizing_adds_no_links(std::size_t slot) const;

  /// The full symmetric Omega as a sparse matrix, ordered (robot, slot 0, slot 1, ...).
  Eigen::SparseMatrix<double> to_sparse() const;
  /// The stacked residual (robot, slot 0, ...).
  Eigen::VectorXd residual() const {
    Eigen::VectorXd out(dim());
    out << robot_residual_, landmark_residual_;
    return out;
  }
  void set_residual(const Eigen::VectorXd& r) {
    for (std::size_t slot = 0; slot < num_landmarks(); ++slot) save(slot);
    robot_residual_ = r.template head<X>();
    landmark_residual_ = r.tail(r.size() - X);
  }

  /// Starts recording: until commit() or rollback(), every block changed through this interface
  /// keeps its old value. Landmarks may be appended; marginalize_landmark is not allowed.
  void begin_transaction() {
    if (open_) throw error("SparseInformation: a transaction is already open");
    journal_.robot = robot_;
    journal_.robot_residual = robot_residual_;
    journal_.landmarks = num_landmarks();
    open_ = true;
    ++transaction_;
  }
  /// Keeps every change since begin_transaction().
  void commit() { close_journal(); }
  /// Restores the form exactly as it was at begin_transaction().
  void rollback();
  bool in_transaction() const { return open_; }

  /// Approximate heap bytes held (blocks and hash-map nodes), for memory reports.
  std::size_t memory_bytes() const;

 private:
  static constexpr std::size_t kPrefetchAhead = 8;  ///< look-ups between a prefetch and its use
  /// Before the look-up of slots[b] in `row`: the index position of the key 2 kPrefetchAhead
  /// look-ups ahead, and the entry of the one kPrefetchAhead ahead (whose position is loaded by now).
  static void prefetch_ahead(const Links& row, std::span<const std::size_t> slots, std::size_t b) {
    if (b + 2 * kPrefetchAhead < slots.size()) row.prefetch_position(slots[b + 2 * kPrefetchAhead]);
    if (b + kPrefetchAhead < slots.size()) row.prefetch_entry(slots[b + kPrefetchAhead]);
  }
  template <class Block, class Map>
  static void add_or_insert(Map& map, std::size_t key, const Block& block) {
    auto [it, inserted] = map.try_emplace(key, block);
    if (!inserted) it->second += block;
  }
  void move_slot(std::size_t from, std::size_t to);
  /// In a transaction, keeps the old diagonal block and residual of a slot that existed when it
  /// began (once per transaction: saved_in_ holds the transaction that last saved each slot).
  void save(std::size_t slot) {
    if (!open_ || slot >= journal_.landmarks || saved_in_[slot] == transaction_) return;
    saved_in_[slot] = transaction_;
    journal_.slots.push_back({slot, diagonal_[slot], landmark_residual_.template segment<M>(M * slot)});
  }
  /// In a transaction, records Omega_{x, slot} (or its absence) before a change.
  void note_robot_link(std::size_t slot) {
    if (!open_) return;
    const auto it = robot_links_.find(slot);
    journal_.robot_links.push_back({slot, it == robot_links_.end() ? std::nullopt : std::optional(it->second)});
  }
  /// Ends the transaction; the journal keeps its capacity for the next one.
  void close_journal() {
    open_ = false;
    journal_.slots.clear();
    journal_.robot_links.clear();
    journal_.links.clear();
  }

  struct SavedSlot {
    std::size_t slot;
    LandmarkBlock diagonal;
    LandmarkVector residual;
  };
  struct SavedRobotLink {
    std::size_t slot;
    std::optional<CrossBlock> block;  ///< nullopt: there was no link
  };
  struct SavedLink {
    std::size_t i, j;
    std::optional<LandmarkBlock> block;
  };
  struct Journal {
    RobotBlock robot;
    RobotVector robot_residual;
    std::size_t landmarks;  ///< landmarks when the transaction began
    std::vector<SavedSlot> slots;
    std::vector<SavedRobotLink> robot_links;  ///< in the order of the changes
    std::vector<SavedLink> links;
  };

  RobotBlock robot_;
  RobotVector robot_residual_;
  std::unordered_map<std::size_t, CrossBlock> robot_links_;
  std::vector<LandmarkBlock> diagonal_;
  LinkRows<Links> links_;  ///< per slot, in one arena of huge pages
  Eigen::VectorXd landmark_residual_;
  Journal journal_;  ///< the open transaction's record (open_), kept allocated between transactions
  bool open_ = false;
  std::vector<std::uint64_t> saved_in_;  ///< per slot, see save()
  std::uint64_t transaction_ = 0;
};

template <int X, int M>
void SparseInformation<X, M>::rollback() {
  if (!open_) return;
  const Journal& journal = journal_;
  robot_ = journal.robot;
  robot_residual_ = journal.robot_residual;
  for (auto it = journal.robot_links.rbegin(); it != journal.robot_links.rend(); ++it) {  // newest first
    if (it->block)
      robot_links_[it->slot] = *it->block;
    else
      robot_links_.erase(it->slot);
  }
  for (auto it = journal.links.rbegin(); it != journal.links.rend(); ++it) {  // i < j, i existed
    const bool j_existed = it->j < journal.landmarks;
    if (it->block) {
      links_[it->i].insert_or_assign(it->j, *it->block);
      links_[it->j].insert_or_assign(it->i, it->block->transpose());
    } else {
      links_[it->i].erase(it->j);
      if (j_existed) links_[it->j].erase(it->i);
    }
  }
  diagonal_.resize(journal.landmarks);
  links_.truncate(journal.landmarks);
  saved_in_.resize(journal.landmarks);
  landmark_residual_.conservativeResize(M * static_cast<Eigen::Index>(journal.landmarks));
  for (const auto& saved : journal.slots) {
    diagonal_[saved.slot] = saved.diagonal;
    landmark_residual_.template segment<M>(M * saved.slot) = saved.residual;
  }
  close_journal();
}

template <int X, int M>
void SparseInformation<X, M>::marginalize_landmark(std::size_t slot) {
  if (open_) throw error("SparseInformation: marginalize_landmark inside a transaction");
  const Eigen::LLT<LandmarkBlock> llt(diagonal_[slot]);
  if (llt.info() != Eigen::Success)
    throw numerical_error("information block of the landmark to marginalize is not positive definite");
  // Schur complement on the neighbourhood {robot, linked landmarks}: with Omega_jj = L L^T, each
  // term Omega_{a,j} Omega_jj^-1 Omega_{j,b} is G_a^T G_b for G_a = L^-1 Omega_{j,a}, one triangular
  // solve per neighbour instead of one per pair.
  const auto& L = llt.matrixL();
  const LandmarkVector g_r = L.solve(landmark_residual(slot));
  const bool robot_linked = is_linked_to_robot(slot);
  const Eigen::Matrix<double, M, X> g_x = L.solve(robot_link(slot).transpose());  // L^-1 Omega_{j, x}
  std::vector<std::size_t> neighbours;
  std::vector<LandmarkBlock> g;  // G_a of each neighbour, in `neighbours` order
  neighbours.reserve(links_[slot].size());
  g.reserve(links_[slot].size());
  for (const auto& [a, O_ja] : links_[slot]) {
    neighbours.push_back(a);
    g.push_back(L.solve(O_ja));
  }
  if (robot_linked) {
    robot_ -= g_x.transpose() * g_x;
    robot_residual_ -= g_x.transpose() * g_r;
  }
  for (std::size_t k = 0; k < neighbours.size(); ++k) {
    const std::size_t a = neighbours[k];
    landmark_residual(a) -= g[k].transpose() * g_r;
    diagonal_[a] -= g[k].transpose() * g[k];
    if (robot_linked) add_to_robot_link(a, -g_x.transpose() * g[k]);
  }
  add_to_links(std::span<const std::size_t>(neighbours),
               [&](std::size_t a, std::size_t b) -> LandmarkBlock { return -g[a].transpose() * g[b]; });
  // Unlink and drop the slot.
  remove_robot_link(slot);
  for (const std::size_t a : neighbours) links_[a].erase(slot);
  links_[slot].clear();
  const std::size_t last = num_landmarks() - 1;
  if (slot != last) move_slot(last, slot);
  diagonal_.pop_back();
  links_.pop_back();
  saved_in_.pop_back();
  landmark_residual_.conservativeResize(landmark_residual_.size() - M);
}

template <int X, int M>
bool SparseInformation<X, M>::marginalizing_adds_no_links(std::size_t slot) const {
  const Links& around = links_[slot];
  const bool robot_linked = is_linked_to_robot(slot);
  for (auto a = around.begin(); a != around.end(); ++a) {
    if (robot_linked && !is_linked_to_robot(a->first)) return false;
    const Links& of_a = links_[a->first];
    for (auto b = std::next(a); b != around.end(); ++b)
      if (!of_a.contains(b->first)) return false;
  }
  return true;
}

/// Relabels slot `from` as `to` (which must be empty), fixing every link that points at it.
template <int X, int M>
void SparseInformation<X, M>::move_slot(std::size_t from, std::size_t to) {
  diagonal_[to] = diagonal_[from];
  landmark_residual(to) = landmark_residual(from);
  links_[to] = std::move(links_[from]);
  links_[from].clear();
  for (const auto& [neighbour, block] : links_[to]) links_[neighbour].rekey(from, to);
  if (auto node = robot_links_.extract(from); !node.empty()) {
    node.key() = to;
    robot_links_.insert(std::move(node));
  }
}

template <int X, int M>
Eigen::SparseMatrix<double> SparseInformation<X, M>::to_sparse() const {
  BlockTriplets triplets;
  auto offset = [](std::size_t slot) { return X + M * static_cast<Eigen::Index>(slot); };
  triplets.add(0, 0, robot_);
  for (const auto& [slot, block] : robot_links_) triplets.add_symmetric(0, offset(slot), block);
  for (std::size_t i = 0; i < num_landmarks(); ++i) {
    triplets.add(offset(i), offset(i), diagonal_[i]);
    for (const auto& [j, block] : links_[i]) triplets.add(offset(i), offset(j), block);
  }
  return triplets.to_sparse(dim(), dim());
}

template <int X, int M>
std::size_t SparseInformation<X, M>::memory_bytes() const {
  constexpr std::size_t node_overhead = 2 * sizeof(void*) + sizeof(std::size_t);  // hash node: next, key, hash
  std::size_t bytes = sizeof(*this) + diagonal_.capacity() * sizeof(LandmarkBlock) +
                      static_cast<std::size_t>(landmark_residual_.size()) * sizeof(double) +
                      links_.memory_bytes() + robot_links_.size() * (sizeof(CrossBlock) + node_overhead) +
                      robot_links_.bucket_count() * sizeof(void*);
  bytes += journal_.slots.capacity() * sizeof(SavedSlot) + journal_.robot_links.capacity() * sizeof(SavedRobotLink) +
           journal_.links.capacity() * sizeof(SavedLink);
  return bytes;
}

}  // namespace sextant
