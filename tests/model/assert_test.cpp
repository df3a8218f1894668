// FOXI_ASSERT (foxi/model/assert.hpp), forced on here by FOXI_CHECKS: the test builds are Release,
// where it is otherwise compiled out.
#define FOXI_CHECKS 1
#include "foxi/model/assert.hpp"

#include <gtest/gtest.h>

namespace {

TEST(AssertDeathTest, BrokenInvariantAbortsNamingMessageConditionAndPlace) {
  const int counted = 3, filled = 2;
  EXPECT_DEATH(
      FOXI_ASSERT(filled == counted, "row 7: " << filled << " of " << counted),
      "internal invariant broken: row 7: 2 of 3 \\(filled == counted\\) at .*assert_test\\.cpp:[0-9]+");
}

TEST(Assert, HeldInvariantIsEvaluatedOnceAndPasses) {
  int evaluated = 0;
  int messages = 0;
  FOXI_ASSERT(++evaluated == 1, "not shown " << ++messages);
  EXPECT_EQ(evaluated, 1);
  EXPECT_EQ(messages, 0);  // the message is built only when the check fails
}

}  // namespace
