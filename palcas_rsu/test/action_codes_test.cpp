// The advisory message constants must mirror palcas_core's action enum, since the RSU
// converts one into the other by value.
#include <gtest/gtest.h>
#include <palcas_core/common/action.h>
#include <palcas_msgs/Advisory.h>

TEST(ActionCodes, MessageConstantsMirrorCoreEnum) {
  using palcas::Action;
  using palcas_msgs::Advisory;
  EXPECT_EQ(Advisory::LANE_LEFT, static_cast<int>(Action::kLaneLeft));
  EXPECT_EQ(Advisory::LANE_RIGHT, static_cast<int>(Action::kLaneRight));
  EXPECT_EQ(Advisory::ACCELERATE, static_cast<int>(Action::kAccelerate));
  EXPECT_EQ(Advisory::KEEP, static_cast<int>(Action::kKeep));
}
