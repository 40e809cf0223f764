#pragma once
/// \file A Monte Carlo study's seeds split into K shards that any batch system (or MPI's ranks) can
/// run apart: shard i of K holds a contiguous block of the seeds, the blocks differ in size by at most
/// one run, and together they hold every seed once.

#include <charconv>
#include <cstdint>
#include <string>

#include "sextant/core/error.hpp"

namespace sextant::eval {

/// Shard `index` (0-based) of `count`.
struct Shard {
  int index = 0, count = 1;
  friend bool operator==(const Shard&, const Shard&) = default;
};

/// The most shards a study may have (a million: far beyond any cluster's job array).
inline constexpr int kMaxShards = 1000000;

/// "i/K" as a shard; invalid_input_error names what is wrong (1 ≤ K ≤ kMaxShards, 0 ≤ i < K).
inline Shard parse_shard(const std::string& text) {
  const auto slash = text.find('/');
  Shard s{-1, 0};
  const auto whole = [](const char* first, const char* last, int& value) {
    const auto [end, ec] = std::from_chars(first, last, value);
    return ec == std::errc{} && end == last && first != last;
  };
  if (slash == std::string::npos || !whole(text.data(), text.data() + slash, s.index) ||
      !whole(text.data() + slash + 1, text.data() + text.size(), s.count))
    throw invalid_input_error("shard '" + text + "': expected i/K, e.g. 0/4 for the first of 4 shards");
  if (s.count < 1 || s.count > kMaxShards || s.index < 0 || s.index >= s.count)
    throw invalid_input_error("shard '" + text + "': needs 1 <= K <= " + std::to_string(kMaxShards) +
                              " and 0 <= i < K (shards count from 0)");
  return s;
}

inline std::string to_string(const Shard& s) { return std::to_string(s.index) + "/" + std::to_string(s.count); }

/// A block of consecutive seeds.
struct SeedRange {
  std::uint64_t first = 0;
  int count = 0;
  std::uint64_t last() const { return first + static_cast<std::uint64_t>(count) - 1; }
  bool contains(std::uint64_t seed) const { return seed >= first && seed - first < static_cast<std::uint64_t>(count); }
};

/// The seeds of `shard` in a study of `runs` runs from `first_seed`: runs i*N/K .. (i+1)*N/K - 1
/// (integer division), so K shards hold seeds first_seed .. first_seed + N - 1 once each. A shard may
/// be empty when K > N.
inline SeedRange seeds_of(const Shard& shard, int runs, std::uint64_t first_seed) {
  const auto begin = static_cast<long long>(shard.index) * runs / shard.count;
  const auto end = static_cast<long long>(shard.index + 1) * runs / shard.count;
  return {first_seed + static_cast<std::uint64_t>(begin), static_cast<int>(end - begin)};
}

/// "a..b", "a" or "none".
inline std::string to_string(const SeedRange& r) {
  if (r.count <= 0) return "none";
  if (r.count == 1) return std::to_string(r.first);
  return std::to_string(r.first) + ".." + std::to_string(r.last());
}

}  // namespace sextant::eval
