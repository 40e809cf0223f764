#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sextant {

/// A set of slots (indices 0, 1, ...) with O(1) insertion, membership and clear, without hashing:
/// a slot is a member while it holds the set's current mark, and clear() takes a new mark. For the
/// per-step scratch sets of a back-end, which would otherwise clear a per-slot flag vector each step.
class SlotSet {
 public:
  /// Empties the set (the marks stay: the new mark makes them stale).
  void clear() {
    ++mark_;
    members_.clear();
  }
  /// Adds `slot`; false when it was a member already.
  bool insert(std::size_t slot) {
    if (slot >= marks_.size()) marks_.resize(slot + 1, 0);
    if (marks_[slot] == mark_) return false;
    marks_[slot] = mark_;
    members_.push_back(slot);
    return true;
  }
  bool contains(std::size_t slot) const { return slot < marks_.size() && marks_[slot] == mark_; }
  /// The members in the order they were inserted.
  const std::vector<std::size_t>& members() const { return members_; }

 private:
  std::vector<std::uint64_t> marks_;
  std::uint64_t mark_ = 1;  ///< marks_ start at 0: no slot is a member
  std::vector<std::size_t> members_;
};

}  // namespace sextant
