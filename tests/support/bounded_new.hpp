#pragma once
// Include in exactly one fuzz target's source: replaces the global operator new/delete so that a
// request above kBoundedNewLimit throws std::bad_alloc, as it does outside the fuzzer on a machine
// without that much memory. ASan's own operator new reports such a request as a crash instead
// (its allocator_may_return_null does not cover a throwing new), which would make every corrupt
// length field MRPT's deserializer trusts a "finding" although our reader turns the
// std::bad_alloc into a parse_error (tests/mrpt/rawlog_test.cpp). Below the limit, memory comes
// from malloc, which ASan still checks.
#include <cstddef>
#include <cstdlib>
#include <new>

namespace sextant::fuzz {
inline constexpr std::size_t kBoundedNewLimit = std::size_t{1} << 30;  // 1 GiB
inline void* bounded_allocate(std::size_t size, std::size_t alignment) {
  if (size > kBoundedNewLimit) throw std::bad_alloc();
  if (size == 0) size = 1;
  void* p = alignment <= alignof(std::max_align_t) ? std::malloc(size)
                                                    : std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  if (!p) throw std::bad_alloc();
  return p;
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
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
