#include "palcas_core/common/action.h"

#include <gtest/gtest.h>

TEST(Action, CodesFollowThePaperOrder) {
  EXPECT_EQ(static_cast<int>(palcas::Action::kLaneLeft), 0);
  EXPECT_EQ(static_cast<int>(palcas::Action::kLaneRight), 1);
  EXPECT_EQ(static_cast<int>(palcas::Action::kAccelerate), 2);
  EXPECT_EQ(static_cast<int>(palcas::Action::kKeep), 3);
  EXPECT_EQ(palcas::ACTION_COUNT, 4);
}

TEST(Action, NamesAndValidity) {
  EXPECT_EQ(palcas::actionName(palcas::Action::kAccelerate), "accelerate");
  EXPECT_EQ(palcas::actionName(palcas::Action::kLaneLeft), "lane_left");
  EXPECT_TRUE(palcas::isValidActionCode(3));
  EXPECT_FALSE(palcas::isValidActionCode(4));
  EXPECT_FALSE(palcas::isValidActionCode(-1));
}

TEST(Action, MasksHoldOneBitPerActionCode) {
  EXPECT_EQ(palcas::actionBit(palcas::Action::kLaneLeft), 1);
  EXPECT_EQ(palcas::actionBit(palcas::Action::kLaneRight), 2);
  EXPECT_EQ(palcas::actionBit(palcas::Action::kKeep), 8);
  EXPECT_EQ(palcas::ALL_ACTIONS, 15);
  EXPECT_TRUE(palcas::isValidActionMask(palcas::ALL_ACTIONS));
  EXPECT_TRUE(palcas::isValidActionMask(palcas::actionBit(palcas::Action::kKeep)));
  EXPECT_FALSE(palcas::isValidActionMask(0));  // no action left to take
  EXPECT_FALSE(palcas::isValidActionMask(16));
}
