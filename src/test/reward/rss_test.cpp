#include "palcas_core/reward/rss.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <stdexcept>

using palcas::RssParams;

TEST(Rss, LongitudinalSafeDistanceMatchesHandComputation) {
  // v = 20, v_lead = 18, paper constants:
  // delta = 20*0.2 + 0.5*2.6*0.04 + (20+0.52)^2/9 - 18^2/9
  //       = 4 + 0.052 + 421.0704/9 - 324/9 = 4 + 0.052 + 46.7856 - 36 = 14.8376
  EXPECT_NEAR(palcas::rssLongitudinalSafeDistance(20.0, 18.0, RssParams()), 14.8376, 1e-9);
}

TEST(Rss, LongitudinalSafeDistanceClampsAtZero) {
  // v = 0, v_lead = 10: 0 + 0.052 + 0.52^2/9 - 100/9 = 0.052 + 0.030044 - 11.111 < 0 -> 0
  EXPECT_EQ(palcas::rssLongitudinalSafeDistance(0.0, 10.0, RssParams()), 0.0);
}

TEST(Rss, LongitudinalSafeDistanceIsNotSymmetric) {
  // Follow pair: the rear (follower) at 22 m/s, the ego in front at 20 m/s:
  // 22*0.2 + 0.052 + 22.52^2/9 - 20^2/9 = 4.4 + 0.052 + 507.1504/9 - 400/9
  //   = 4.4 + 0.052 + 56.350044 - 44.444444 = 16.3576
  EXPECT_NEAR(palcas::rssLongitudinalSafeDistance(22.0, 20.0, RssParams()), 16.3576, 1e-9);
  // Swapped: 20 rear, 22 front: 4 + 0.052 + 46.7856 - 484/9 (53.777778) < 0 -> 0
  EXPECT_EQ(palcas::rssLongitudinalSafeDistance(20.0, 22.0, RssParams()), 0.0);
}

TEST(Rss, LateralSafeDistanceAtRest) {
  // v_i = v_m = 0: v_i,rho = v_m,rho = 0.2
  // ego = (0+0.2)/2*0.2 + 0.04/2 = 0.02 + 0.02 = 0.04; other = 0.02 - 0.02 = 0
  // delta = 0.1 + [0.04 - 0]_+ = 0.14
  EXPECT_NEAR(palcas::rssLateralSafeDistance(0.0, 0.0, RssParams()), 0.14, 1e-12);
}

TEST(Rss, LateralSafeDistanceWhenClosing) {
  // v_i = 1 (toward the other), v_m = -0.5 (toward the ego): v_i,rho = 1.2, v_m,rho = -0.3
  // ego = (1+1.2)/2*0.2 + 1.44/2 = 0.22 + 0.72 = 0.94
  // other = (-0.5-0.3)/2*0.2 - 0.09/2 = -0.08 - 0.045 = -0.125
  // delta = 0.1 + (0.94 + 0.125) = 1.165
  EXPECT_NEAR(palcas::rssLateralSafeDistance(1.0, -0.5, RssParams()), 1.165, 1e-12);
}

TEST(Rss, LateralSafeDistanceClampsToMu) {
  // v_i = -0.2 (away): v_i,rho = 0; ego = (-0.2+0)/2*0.2 + 0 = -0.02; other (v_m = 0) = 0
  // [ -0.02 ]_+ = 0 -> delta = mu = 0.1
  EXPECT_NEAR(palcas::rssLateralSafeDistance(-0.2, 0.0, RssParams()), 0.1, 1e-12);
}

TEST(Rss, SafetyTermBranches) {
  // d < delta: (10 - 14.8376) / 14.8376 = -4.8376 / 14.8376 = -0.326037
  EXPECT_NEAR(palcas::rssSafetyTerm(10.0, 14.8376), -0.3260366, 1e-6);
  // d >= delta: min(positive, 0) = 0
  EXPECT_EQ(palcas::rssSafetyTerm(20.0, 14.8376), 0.0);
  // overlap: (-2 - 14.8376) / 14.8376 = -1.134793
  EXPECT_NEAR(palcas::rssSafetyTerm(-2.0, 14.8376), -1.1347927, 1e-6);
  // delta = 0: satisfied for d >= 0, -1 for an overlap (documented choice)
  EXPECT_EQ(palcas::rssSafetyTerm(0.0, 0.0), 0.0);
  EXPECT_EQ(palcas::rssSafetyTerm(3.0, 0.0), 0.0);
  EXPECT_EQ(palcas::rssSafetyTerm(-0.5, 0.0), -1.0);
}

TEST(Rss, ValidationNamesTheBadParameter) {
  RssParams p;
  p.a_b_min_mps2 = 0.0;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { palcas::validateRssParams(p); },
                                                        "a_b_min");
  p = RssParams();
  p.rho_s = std::nan("");
  EXPECT_THROW(palcas::validateRssParams(p), std::invalid_argument);
  EXPECT_NO_THROW(palcas::validateRssParams(RssParams()));
}
