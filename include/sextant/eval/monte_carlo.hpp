#pragma once
/// \file Runs a seeded experiment many times in parallel on all cores; results come back in
/// seed order, so a Monte Carlo study is reproducible whatever the thread count.

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace sextant::eval {

/// Calls experiment(seed) for seed = first_seed .. first_seed + runs - 1 on `threads` threads
/// (0 = all hardware threads) and returns the results in seed order. The first exception thrown
/// by any run is rethrown after all threads stop.
template <class Experiment>
auto monte_carlo(int runs, std::uint64_t first_seed, Experiment experiment, unsigned threads = 0) {
  using Result = decltype(experiment(first_seed));
  std::vector<Result> results(static_cast<std::size_t>(std::max(runs, 0)));
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = std::min<unsigned>(threads, static_cast<unsigned>(std::max(runs, 1)));
  std::atomic<int> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto worker = [&] {
    for (int i = next++; i < runs; i = next++) {
      try {
        results[i] = experiment(first_seed + static_cast<std::uint64_t>(i));
      } catch (...) {
        std::lock_guard lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  {
    std::vector<std::jthread> pool;
    for (unsigned t = 0; t < threads; ++t) pool.emplace_back(worker);
  }
  if (failure) std::rethrow_exception(failure);
  return results;
}

}  // namespace sextant::eval
