#pragma once
/// \file A hash map from slot numbers to values whose entries sit contiguously in one vector (an
/// open-addressing index with linear probing points into it). SEIF's landmark-landmark links are
/// such maps: mean recovery walks every link of every active landmark, and a node-based map turns
/// that walk into a cache miss per link (at the globe's thesis scale, 80% of mean recovery's time
/// was spent loading hash nodes). Iteration visits entries in vector order; erasing moves the last
/// entry into the hole, so the order is not the insertion order and no algorithm may depend on it.
/// The entries grow by half when full (from 8 on): at the thesis's globe scale the maps' capacity was
/// 1.47x their entries with doubling, and the memory a run first touches is what SEIF's
/// sparsification waits for on a virtual machine (docs/benchmarks.md, round seven).

#include <cstddef>
#include <cstdint>
#include <memory_resource>
#include <utility>
#include <vector>

namespace sextant {

template <class Value>
class DenseSlotMap {
 public:
  using Entry = std::pair<std::size_t, Value>;
  using iterator = typename std::pmr::vector<Entry>::iterator;
  using const_iterator = typename std::pmr::vector<Entry>::const_iterator;

  /// The entries and the index live in `memory` (a copy lives in the default resource, as any
  /// std::pmr container's; the copy below chooses).
  explicit DenseSlotMap(std::pmr::memory_resource* memory = std::pmr::get_default_resource())
      : entries_(memory), index_(memory) {}
  DenseSlotMap(const DenseSlotMap& other, std::pmr::memory_resource* memory)
      : entries_(other.entries_, memory), index_(other.index_, memory), shift_(other.shift_) {}

  std::size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  iterator begin() { return entries_.begin(); }
  iterator end() { return entries_.end(); }
  const_iterator begin() const { return entries_.begin(); }
  const_iterator end() const { return entries_.end(); }

  iterator find(std::size_t key) {
    const std::size_t at = position_of(key);
    return at == kNone ? entries_.end() : entries_.begin() + static_cast<std::ptrdiff_t>(index_[at] - 1);
  }
  const_iterator find(std::size_t key) const {
    const std::size_t at = position_of(key);
    return at == kNone ? entries_.end() : entries_.begin() + static_cast<std::ptrdiff_t>(index_[at] - 1);
  }
  bool contains(std::size_t key) const { return position_of(key) != kNone; }

  /// Inserts (key, value) unless key is present; returns the entry and whether it was inserted.
  std::pair<iterator, bool> try_emplace(std::size_t key, const Value& value) {
    if (const auto it = find(key); it != end()) return {it, false};
    if (2 * (entries_.size() + 1) > index_.size()) grow();
    if (entries_.size() == entries_.capacity() && entries_.size() >= 8)  // grow by half, not double
      entries_.reserve(entries_.size() + entries_.size() / 2);
    entries_.emplace_back(key, value);
    index_[free_position_for(key)] = static_cast<std::uint32_t>(entries_.size());
    return {entries_.end() - 1, true};
  }
  void insert_or_assign(std::size_t key, const Value& value) {
    auto [it, inserted] = try_emplace(key, value);
    if (!inserted) it->second = value;
  }

  /// Hints for a caller that will look up many keys of one map in a known order (memory-level
  /// parallelism: the look-ups of a large map miss the cache, and a miss found early overlaps the
  /// work on the keys before it). prefetch_position(key) loads the index position where key's probe
  /// starts; prefetch_entry(key) then loads the entry that position points to. Neither changes anything.
  void prefetch_position(std::size_t key) const {
    if (!index_.empty()) __builtin_prefetch(&index_[home_of(key)]);
  }
  void prefetch_entry(std::size_t key) const {
    if (index_.empty()) return;
    const std::uint32_t entry = index_[home_of(key)];
    if (entry != 0) __builtin_prefetch(&entries_[entry - 1]);
  }

  /// Removes key if present; returns how many entries were removed (0 or 1).
  std::size_t erase(std::size_t key) {
    const std::size_t at = position_of(key);
    if (at == kNone) return 0;
    const std::size_t entry = index_[at] - 1;
    remove_position(at);
    if (entry + 1 != entries_.size()) {  // the last entry fills the hole
      index_[position_of(entries_.back().first)] = static_cast<std::uint32_t>(entry + 1);
      entries_[entry] = std::move(entries_.back());
    }
    entries_.pop_back();
    return 1;
  }
  /// Gives the entry under `from` the key `to` (which must be absent).
  void rekey(std::size_t from, std::size_t to) {
    const auto it = find(from);
    if (it == end()) return;
    const Value value = it->second;
    erase(from);
    try_emplace(to, value);
  }
  void clear() {
    entries_.clear();
    index_.clear();
  }

  /// Heap bytes held.
  std::size_t memory_bytes() const {
    return entries_.capacity() * sizeof(Entry) + index_.capacity() * sizeof(std::uint32_t);
  }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  /// Fibonacci hashing: consecutive slots spread over the table.
  std::size_t home_of(std::size_t key) const {
    return static_cast<std::size_t>((static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  std::size_t mask() const { return index_.size() - 1; }
  std::size_t position_of(std::size_t key) const {
    if (index_.empty()) return kNone;
    for (std::size_t at = home_of(key);; at = (at + 1) & mask()) {
      if (index_[at] == 0) return kNone;
      if (entries_[index_[at] - 1].first == key) return at;
    }
  }
  std::size_t free_position_for(std::size_t key) const {
    std::size_t at = home_of(key);
    while (index_[at] != 0) at = (at + 1) & mask();
    return at;
  }
  /// Empties a position and shifts later members of its probe run back (no tombstones).
  void remove_position(std::size_t hole) {
    index_[hole] = 0;
    for (std::size_t at = (hole + 1) & mask(); index_[at] != 0; at = (at + 1) & mask()) {
      const std::size_t home = home_of(entries_[index_[at] - 1].first);
      const bool reachable_from_hole = ((at - home) & mask()) >= ((at - hole) & mask());
      if (reachable_from_hole) {
        index_[hole] = index_[at];
        index_[at] = 0;
        hole = at;
      }
    }
  }
  void grow() {
    const std::size_t capacity = index_.empty() ? 8 : 2 * index_.size();
    shift_ = 64;
    for (std::size_t c = capacity; c > 1; c >>= 1) --shift_;
    index_.assign(capacity, 0);
    for (std::size_t e = 0; e < entries_.size(); ++e)
      index_[free_position_for(entries_[e].first)] = static_cast<std::uint32_t>(e + 1);
  }

  std::pmr::vector<Entry> entries_;
  std::pmr::vector<std::uint32_t> index_;  ///< 0 = empty, else entry number + 1
  int shift_ = 64;
};

}  // namespace sextant
