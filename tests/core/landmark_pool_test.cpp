#include "sextant/core/landmark_pool.hpp"

#include <gtest/gtest.h>

namespace sextant {
namespace {

TEST(LandmarkPool, AddAssignsDenseSlots) {
  LandmarkPool pool;
  EXPECT_EQ(pool.add(7), 0u);
  EXPECT_EQ(pool.add(3), 1u);
  EXPECT_EQ(pool.slot(3), 1u);
  EXPECT_TRUE(pool.contains(7));
  EXPECT_THROW(pool.add(7), duplicate_landmark_error);
  EXPECT_THROW(pool.slot(8), unknown_landmark_error);
}

TEST(LandmarkPool, RemoveMovesTheLastSlotIntoTheFreedOne) {
  LandmarkPool pool;
  for (LandmarkId id : {10, 11, 12, 13}) pool.add(id);
  const auto removal = pool.remove(11);
  EXPECT_EQ(removal.freed_slot, 1u);
  EXPECT_EQ(removal.last_slot, 3u);
  EXPECT_EQ(pool.slot(13), 1u);
  EXPECT_EQ(pool.ids(), (std::vector<LandmarkId>{10, 13, 12}));
  const auto last = pool.remove(12);
  EXPECT_EQ(last.freed_slot, last.last_slot);
  EXPECT_EQ(pool.size(), 2u);
  EXPECT_THROW(pool.remove(11), unknown_landmark_error);
}

}  // namespace
}  // namespace sextant
