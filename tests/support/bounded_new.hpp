#pragma once
// Include in exactly one source of a binary: replaces the global operator new/delete so that a
// request above kBoundedNewLimit, or one that would take the memory alive through new past
// kBoundedNewTotal, throws std::bad_alloc, as it does outside the fuzzer on a machine
// without that much memory. ASan's own operator new reports such a request as a crash instead
// (its allocator_may_return_null does not cover a throwing new), which would make every corrupt
// length field MRPT's deserializer trusts a "finding" although our reader turns the
// std::bad_alloc into a parse_error (tests/mrpt/rawlog_test.cpp). Below the limit, memory comes
// from malloc, which ASan still checks.
// Why 256 MiB: fuzz inputs are at most 64 KiB (-max_len in cmake/fuzz.sh) and gzip inflates at
// most ~1032:1, so no entry of any input holds more than ~66 MB; a larger request can only come
// from a corrupt length field. With 1 GiB, two such requests alive at once (a 1 GB string MRPT
// zero-fills before reading it, CI run of 2026-11-23) passed the 2.5 GB RSS limit.
#include <malloc.h>

#include <atomic>
#include <cstddef>
#include <cstdlib>
#include <new>

/// What a library asks of malloc itself (Eigen matrices inside MRPT's classes, libzip's buffers)
/// is bounded by ASan where it runs: above 256 MiB malloc returns null, which Eigen turns into
/// std::bad_alloc and libzip into an error, instead of libFuzzer reporting the request as an
/// out-of-memory crash. Without ASan this function is never called.
extern "C" __attribute__((used)) const char* __asan_default_options() {
  return "allocator_may_return_null=1:max_allocation_size_mb=256";
}

namespace sextant::fuzz {
inline constexpr std::size_t kBoundedNewLimit = std::size_t{1} << 28;  // 256 MiB in one request
/// ... and 512 MiB alive at once: MRPT also trusts counts it feeds to containers that allocate in
/// small pieces (a CSensoryFrame's std::deque of observations resized to a corrupt count took
/// 3 million 512-byte chunks, 1.5 GB, on 2026-11-23), which no bound on one request catches.
inline constexpr std::size_t kBoundedNewTotal = std::size_t{1} << 29;
inline std::atomic<std::size_t> bounded_new_live{0};

inline void* bounded_allocate(std::size_t size, std::size_t alignment) {
  if (size > kBoundedNewLimit || bounded_new_live.load(std::memory_order_relaxed) + size > kBoundedNewTotal)
    throw std::bad_alloc();
  if (size == 0) size = 1;
  void* p = alignment <= alignof(std::max_align_t) ? std::malloc(size)
                                                    : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  if (!p) throw std::bad_alloc();
  bounded_new_live.fetch_add(malloc_usable_size(p), std::memory_order_relaxed);
  return p;
}
inline void bounded_free(void* p) noexcept {
  if (!p) return;
  bounded_new_live.fetch_sub(malloc_usable_size(p), std::memory_order_relaxed);
  std::free(p);
}
}  // namespace sextant::fuzz

void* operator new(std::size_t n) { return sextant::fuzz::bounded_allocate(n, 0); }
void* operator new[](std::size_t n) { return sextant::fuzz::bounded_allocate(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return sextant::fuzz::bounded_allocate(n, static_cast<std::size_t>(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return sextant::fuzz::bounded_allocate(n, static_cast<std::size_t>(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try { return sextant::fuzz::bounded_allocate(n, 0); } catch (...) { return nullptr; }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try { return sextant::fuzz::bounded_allocate(n, 0); } catch (...) { return nullptr; }
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try { return sextant::fuzz::bounded_allocate(n, static_cast<std::size_t>(a)); } catch (...) { return nullptr; }
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  try { return sextant::fuzz::bounded_allocate(n, static_cast<std::size_t>(a)); } catch (...) { return nullptr; }
}
void operator delete(void* p) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete[](void* p) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete(void* p, std::size_t) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete[](void* p, std::size_t) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete(void* p, std::align_val_t) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { sextant::fuzz::bounded_free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { sextant::fuzz::bounded_free(p); }
