#pragma once
/// \file One row of links per landmark slot (SparseInformation's landmark-landmark maps), every
/// row's memory in one HugePageArena that the rows own together: a copy gets an arena of its own,
/// a move takes the arena along, and the rows give their memory back before the arena goes.
/// Row must be constructible from a std::pmr::memory_resource* and from (const Row&, resource*).

#include <cstddef>
#include <memory>
#include <memory_resource>
#include <vector>

#include "sextant/core/huge_page_arena.hpp"

namespace sextant {

template <class Row>
class LinkRows {
 public:
  LinkRows() = default;
  LinkRows(const LinkRows& other) {
    rows_.reserve(other.rows_.size());
    for (const Row& row : other.rows_) rows_.emplace_back(row, arena_.get());
  }
  LinkRows(LinkRows&&) noexcept = default;
  LinkRows& operator=(const LinkRows& other) { return *this = LinkRows(other); }
  /// Members in declaration order: the old rows are freed into the old arena, then it goes.
  LinkRows& operator=(LinkRows&&) noexcept = default;
  ~LinkRows() { rows_.clear(); }

  std::size_t size() const { return rows_.size(); }
  Row& operator[](std::size_t slot) { return rows_[slot]; }
  const Row& operator[](std::size_t slot) const { return rows_[slot]; }

  /// Appends an empty row (a moved-from LinkRows gets a new arena first).
  void append() {
    if (!arena_) arena_ = std::make_unique<HugePageArena>();
    rows_.emplace_back(arena_.get());
  }
  void pop_back() { rows_.pop_back(); }
  /// Drops the rows from `count` on.
  void truncate(std::size_t count) {
    while (rows_.size() > count) rows_.pop_back();
  }

  /// Heap bytes held: the row headers and every block carved from the arena (in use or waiting).
  std::size_t memory_bytes() const {
    return rows_.capacity() * sizeof(Row) + (arena_ ? arena_->bytes_carved() : 0);
  }

 private:
  std::vector<Row> rows_;
  std::unique_ptr<HugePageArena> arena_ = std::make_unique<HugePageArena>();
};

}  // namespace sextant
