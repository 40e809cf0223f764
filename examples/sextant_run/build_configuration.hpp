#pragma once
// The configuration macros that sextant's headers test, as constants of the unit that first
// included this header. In the runner's precompiled header (docs/build_times.md) that unit is the
// header's own build, so program_main.cpp can check that a program's units were compiled with the
// macros the header was built with: clang refuses a unit that lacks one of them, but silently takes
// one that adds one, which would give the program two definitions of, e.g., the sparse factor.

namespace sextant::runner::build {
#ifdef SEXTANT_HAS_CHOLMOD
inline constexpr bool has_cholmod = true;
#else
inline constexpr bool has_cholmod = false;
#endif
#ifdef SEXTANT_HAS_LAPACK
inline constexpr bool has_lapack = true;
#else
inline constexpr bool has_lapack = false;
#endif
#ifdef SEXTANT_COMPILED_INSTANCES
inline constexpr bool compiled_instances = true;
#else
inline constexpr bool compiled_instances = false;
#endif
}  // namespace sextant::runner::build
