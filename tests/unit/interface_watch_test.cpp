// The fluid side's watch on unsolved implicit interface steps
// (fluid/side/interface_watch.hpp): the rule that turns them into a notice,
// at the counts measured on the KGD CI scenes and on the inclined well.
#include "interface_watch.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace hfmpm::fluid {
namespace {

using ::testing::HasSubstr;

TEST(InterfaceWatch, QuietForTheFewUnsolvedStepsOfAVerifiedRun) {
  InterfaceWatch watch;
  // kgd-two-wing-ci's 3 in 2 x 9,000 solver steps; kgd-paper-field-ci's 1 in 5,552.
  EXPECT_FALSE(watch.check(3, 18000, 5.0));
  EXPECT_FALSE(watch.check(1, 5552, 300.0));
  // Ten but below 1% of the steps: still quiet.
  EXPECT_FALSE(watch.check(10, 1000, 1.0));
}

TEST(InterfaceWatch, WarnsOnceWhenUnsolvedStepsAreCommon) {
  InterfaceWatch watch;
  EXPECT_FALSE(watch.check(9, 100, 0.5));  // under ten: too few to call
  // The 30-degree inclined well at 1.5 s: 556 of 11,264 solver steps (two wings).
  const auto message = watch.check(556, 11264, 1.5);
  ASSERT_TRUE(message);
  EXPECT_THAT(*message, HasSubstr("556 of 11264 implicit fluid steps (4.9%)"));
  EXPECT_THAT(*message, HasSubstr("best iterate"));
  EXPECT_FALSE(watch.check(600, 11300, 1.6));  // raised once
}

}  // namespace
}  // namespace hfmpm::fluid
