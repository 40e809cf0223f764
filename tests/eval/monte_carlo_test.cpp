#include "sextant/eval/monte_carlo.hpp"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace sextant::eval {
namespace {

double experiment(std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  return std::normal_distribution<double>(0.0, 1.0)(rng);
}

TEST(MonteCarlo, ResultsComeInSeedOrderWhateverTheThreadCount) {
  const auto one = monte_carlo(37, 100, experiment, 1);
  const auto many = monte_carlo(37, 100, experiment, 4);
  ASSERT_EQ(one.size(), 37u);
  EXPECT_EQ(one, many);
  EXPECT_EQ(one[5], experiment(105));
}

TEST(MonteCarlo, RethrowsAFailure) {
  EXPECT_THROW(monte_carlo(10, 0, [](std::uint64_t seed) -> int {
                 if (seed == 6) throw std::runtime_error("run 6 failed");
                 return 0;
               }),
               std::runtime_error);
}

}  // namespace
}  // namespace sextant::eval
