#include "palcas_core/common/build_info.h"

#include <gtest/gtest.h>

#include <Eigen/Core>

TEST(BuildInfo, NamesTheArchAndTheInstructionSetsItsUsersCompileWith) {
  const palcas::BuildInfo info = palcas::buildInfo();
  EXPECT_EQ(info.arch, PALCAS_CORE_ARCH_EXPECTED);  // native, portable or PALCAS_MARCH's value
  // A package compiling against the core inherits its -march (palcas_core-extras.cmake): the
  // vector sets seen here and inside the library must agree, or Eigen's layouts would not.
  EXPECT_EQ(info.simd, Eigen::SimdInstructionSetsInUse());
  EXPECT_FALSE(info.simd.empty());
  EXPECT_FALSE(info.cpu.empty());
}
