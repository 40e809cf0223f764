#pragma once
// Include in exactly one source of a binary that links MRPT, instead of bounded_new.hpp: adds to
// its bounds MRPT's own aligned allocator. MRPT's vectors and matrices (CVectorFloat, CMatrixD…)
// allocate through mrpt::aligned_malloc, which calls aligned_alloc and returns null on failure
// (its std::allocator then hands null to the vector); our definitions, found before
// libmrpt-core's by the dynamic linker like any symbol of the executable, throw std::bad_alloc
// past the same bounds as new. Fuzz finding 6 (CI 2026-11-23): a corrupt length of
// CActionRobotMovement3D::velocities asked aligned_alloc for 15.9 GB.
#include <mrpt/core/aligned_allocator.h>

#include <cstring>

#include "bounded_new.hpp"

namespace mrpt {
void* aligned_malloc(std::size_t size, std::size_t alignment) {
  return sextant::fuzz::bounded_allocate(size, alignment);
}
void* aligned_calloc(std::size_t bytes, std::size_t alignment) {
  void* p = aligned_malloc(bytes, alignment);
  std::memset(p, 0, bytes);
  return p;
}
void aligned_free(void* p) { sextant::fuzz::bounded_free(p); }
}  // namespace mrpt
