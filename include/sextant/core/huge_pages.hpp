#pragma once
/// \file Memory that Linux is asked to back with transparent huge pages (2 MB) when it is at least
/// that large: madvise(MADV_HUGEPAGE) on a 2 MB-aligned block, advice the kernel may ignore
/// (elsewhere, and below 2 MB, an ordinary 64-byte-aligned block). What it buys: one page fault and
/// one TLB entry per 2 MB instead of per 4 KB. In a virtual machine, where a TLB miss walks two
/// page tables, SEIF at the thesis's globe scale spent a third of its run in page faults and TLB
/// misses on its link maps and its dense workspaces (docs/benchmarks.md, round seven).

#include <cstddef>
#include <cstdlib>
#include <new>
#include <utility>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace sextant {

/// `bytes` rounded up to a multiple of `to`.
constexpr std::size_t round_up_to(std::size_t bytes, std::size_t to) { return (bytes + to - 1) / to * to; }

class HugePageMemory {
 public:
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;

  HugePageMemory() = default;
  /// At least `bytes` bytes (rounded up to 64, or to 2 MB from 2 MB on); contents uninitialized.
  explicit HugePageMemory(std::size_t bytes) {
    const std::size_t alignment = bytes >= kHugePage ? kHugePage : 64;
    size_ = round_up_to(bytes, alignment);
    data_ = static_cast<std::byte*>(std::aligned_alloc(alignment, size_));
    if (data_ == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    if (alignment == kHugePage) madvise(data_, size_, MADV_HUGEPAGE);  // advice: without it, ordinary pages
#endif
  }
  HugePageMemory(const HugePageMemory&) = delete;
  HugePageMemory& operator=(const HugePageMemory&) = delete;
  HugePageMemory(HugePageMemory&& other) noexcept
      : data_(std::exchange(other.data_, nullptr)), size_(std::exchange(other.size_, 0)) {}
  HugePageMemory& operator=(HugePageMemory&& other) noexcept {
    std::swap(data_, other.data_);
    std::swap(size_, other.size_);
    return *this;
  }
  ~HugePageMemory() { std::free(data_); }

  std::byte* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  std::byte* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace sextant
