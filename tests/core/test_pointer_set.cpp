// PointerSet: the same answers as std::unordered_set for a random stream of pointers with
// repeats, across growth and clears; null is never a member.
#include <random>
#include <unordered_set>
#include <vector>

#include <gtest/gtest.h>

#include "plslam/core/pointer_set.h"

namespace plslam::core {
namespace {

TEST(PointerSet, AgreesWithUnorderedSetThroughGrowthAndClears) {
  std::vector<int> objects(5000);
  std::mt19937 rng(11);
  PointerSet set;
  for (const std::size_t expected : {std::size_t{0}, std::size_t{100}, std::size_t{20000}}) {
    set.clear(expected);
    std::unordered_set<const void*> reference;
    // Indices drawn from a range smaller than the draws, so about half repeat.
    std::uniform_int_distribution<std::size_t> pick(0, objects.size() - 1);
    for (int k = 0; k < 8000; ++k) {
      const int* p = &objects[pick(rng)];
      ASSERT_EQ(set.insert(p), reference.insert(p).second) << k;
      ASSERT_TRUE(set.contains(p));
    }
    EXPECT_EQ(set.size(), reference.size());
    EXPECT_GT(reference.size(), 3000u);
    EXPECT_LT(reference.size(), 5000u);
    std::size_t found = 0;
    for (const int& o : objects) found += set.contains(&o) ? 1 : 0;
    EXPECT_EQ(found, reference.size());
  }
  set.clear();
  EXPECT_EQ(set.size(), 0u);
  EXPECT_FALSE(set.contains(&objects[0]));
  EXPECT_FALSE(set.insert(nullptr));
  EXPECT_FALSE(set.contains(nullptr));
  EXPECT_EQ(set.size(), 0u);
  // Neighbouring addresses (a vector's elements) land in distinct slots often enough that a
  // full run of them stays cheap: insert every element, then each is found.
  for (const int& o : objects) EXPECT_TRUE(set.insert(&o));
  EXPECT_EQ(set.size(), objects.size());
  EXPECT_FALSE(set.insert(&objects[1234]));
}

TEST(PointerSet, AssignKeepsTheNonNullItems) {
  int a = 0, b = 0;
  const std::vector<const int*> items = {&a, nullptr, &b, &a};
  PointerSet set;
  set.assign(items, 100);
  EXPECT_EQ(set.size(), 2u);
  EXPECT_TRUE(set.contains(&a));
  EXPECT_TRUE(set.contains(&b));
  EXPECT_FALSE(set.insert(&b));
}

TEST(PointerSet, ContainsOnAnEmptySetIsFalse) {
  const PointerSet empty;
  int x = 0;
  EXPECT_FALSE(empty.contains(&x));
  EXPECT_EQ(empty.size(), 0u);
}

}  // namespace
}  // namespace plslam::core
