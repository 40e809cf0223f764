#pragma once
/// \file A memory resource for many buffers that grow by one rule and live as long as one owner:
/// blocks are carved from chunks that double in size up to 64 MB, from 2 MB on backed by huge
/// pages (core/huge_pages.hpp), and a freed block waits for the next request of its size (a buffer
/// that grows by the rule frees exactly the sizes the buffers behind it will ask for).
/// SEIF's landmark links are such buffers: at the thesis's globe scale ~3,800 link maps grow to ~900
/// entries each, ~450 MB first touched over the run, and with 4 KB pages each first touch was a page
/// fault (a fifth of SEIF's run on a virtual machine) and each look-up in a cold map a TLB miss.
/// Not thread-safe: one owner (a SparseInformation) uses it. Memory goes back when it is destroyed.

#include <algorithm>
#include <cstddef>
#include <memory_resource>
#include <unordered_map>
#include <vector>

#include "sextant/core/huge_pages.hpp"

namespace sextant {

class HugePageArena final : public std::pmr::memory_resource {
 public:
  HugePageArena() = default;
  HugePageArena(const HugePageArena&) = delete;
  HugePageArena& operator=(const HugePageArena&) = delete;
  ~HugePageArena() override = default;

  /// Bytes carved from the chunks so far (blocks in use and blocks waiting for reuse).
  std::size_t bytes_carved() const { return carved_; }

 private:
  static constexpr std::size_t kGranule = alignof(std::max_align_t);
  static constexpr std::size_t kFirstChunk = std::size_t{64} << 10;  ///< a small map costs no huge page
  static constexpr std::size_t kLargestChunk = std::size_t{64} << 20;

  /// The block a request of `bytes` gets (its free list's key).
  static std::size_t block_size(std::size_t bytes) { return round_up_to(std::max<std::size_t>(bytes, 1), kGranule); }

  void* do_allocate(std::size_t bytes, std::size_t alignment) override {
    if (alignment > kGranule) return std::pmr::new_delete_resource()->allocate(bytes, alignment);
    const std::size_t size = block_size(bytes);
    if (void*& waiting = free_[size]; waiting != nullptr) {  // the key exists from here on
      void* block = waiting;
      waiting = *static_cast<void**>(block);
      return block;
    }
    if (left_ < size) add_chunk(size);
    void* block = next_;
    next_ += size;
    left_ -= size;
    carved_ += size;
    return block;
  }
  void do_deallocate(void* block, std::size_t bytes, std::size_t alignment) override {
    if (alignment > kGranule) return std::pmr::new_delete_resource()->deallocate(block, bytes, alignment);
    void*& waiting = free_.find(block_size(bytes))->second;  // allocate made the key
    *static_cast<void**>(block) = waiting;
    waiting = block;
  }
  bool do_is_equal(const std::pmr::memory_resource& other) const noexcept override { return this == &other; }

  /// A new chunk of at least `size` bytes, each twice the last up to kLargestChunk; what is left of
  /// the old one is not used.
  void add_chunk(std::size_t size) {
    chunks_.reserve(chunks_.size() + 1);
    HugePageMemory& chunk = chunks_.emplace_back(std::max(size, next_chunk_));
    next_chunk_ = std::min(2 * next_chunk_, kLargestChunk);
    next_ = chunk.data();
    left_ = chunk.size();
  }

  std::vector<HugePageMemory> chunks_;
  /// Block size -> the last freed block of that size, each freed block holding the one freed before
  /// it (no allocation when a block is freed).
  std::unordered_map<std::size_t, void*> free_;
  std::byte* next_ = nullptr;
  std::size_t left_ = 0;
  std::size_t next_chunk_ = kFirstChunk;
  std::size_t carved_ = 0;
};

}  // namespace sextant
