#include "palcas_core/learning/nn/dropout.h"

#include <gtest/gtest.h>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/linear.h"

using namespace palcas;
using namespace palcas::nn;

TEST(Dropout, ForwardMatchesTheDrawnMask) {
  Rng rng(41), replay(41);
  Dropout dropout(4, 0.5f);
  dropout.setRng(&rng);
  Matrix x(4, 1);
  x << 1, 2, 3, 4;
  const Matrix y = dropout.forward(x, true);
  // p = 0.5: keep element i when its 32-bit draw >= 0.5 * 2^32; kept values are scaled by
  // 1/(1 - 0.5) = 2. Two elements per 64-bit draw (low half first).
  const uint64_t d0 = replay.nextU64(), d1 = replay.nextU64();
  const uint64_t halves[4] = {d0 & 0xffffffffULL, d0 >> 32, d1 & 0xffffffffULL, d1 >> 32};
  for (int i = 0; i < 4; ++i) {
    const float expected = halves[i] >= 2147483648ULL ? 2.0f * x(i, 0) : 0.0f;
    EXPECT_EQ(y(i, 0), expected) << "element " << i;
  }
  // Backward multiplies by the same mask: g = 1 gives 0 or 2 where y was 0 or 2x.
  const Matrix dx = dropout.backward(Matrix::Ones(4, 1), {});
  for (int i = 0; i < 4; ++i) EXPECT_EQ(dx(i, 0), y(i, 0) == 0 ? 0.0f : 2.0f);
}

TEST(Dropout, KeepsAboutOneMinusPAndIsIdentityInEval) {
  Rng rng(42);
  Dropout dropout(100, 0.1f);
  dropout.setRng(&rng);
  const Matrix x = Matrix::Ones(100, 100);
  const Matrix y = dropout.forward(x, true);
  // 10000 Bernoulli(0.9) draws: kept fraction 0.9 +- 3 sigma (sigma = 0.003).
  const double kept = (y.array() != 0).cast<double>().mean();
  EXPECT_NEAR(kept, 0.9, 0.01);
  EXPECT_NEAR(y.maxCoeff(), 1.0f / 0.9f, 1e-6f);
  EXPECT_EQ(dropout.forward(x, false), x);
}

TEST(Dropout, GradientCheckWithAFixedMask) {
  Rng rng(43);
  const std::string start = rng.state();
  Dropout dropout(3, 0.3f);
  dropout.setRng(&rng);
  Rng data(44);
  test::expectInputGradient(dropout, test::randomMatrix(3, 4, data),
                            test::randomMatrix(3, 4, data), true,
                            [&] { rng.setState(start); });  // same mask every pass
}

TEST(Dropout, SaveLoadRoundTrip) {
  Rng rng_a(45), rng_b(46);
  Network a, b;
  a.addLayer(std::make_unique<Linear>(2, 3, rng_a));
  a.addLayer(std::make_unique<Dropout>(3, 0.1f));
  b.addLayer(std::make_unique<Linear>(2, 3, rng_b));
  b.addLayer(std::make_unique<Dropout>(3, 0.1f));
  EXPECT_EQ(a.layout(), "Linear(2,3);Dropout(3,0.1)");
  test::expectSaveLoadRoundTrip(a, b, test::randomMatrix(2, 4, rng_a));
}

TEST(Dropout, RejectsBadInput) {
  EXPECT_THROW(Dropout(3, 1.0f), std::invalid_argument);
  EXPECT_THROW(Dropout(3, -0.1f), std::invalid_argument);
  EXPECT_THROW(Dropout(0, 0.1f), std::invalid_argument);
  Dropout dropout(2, 0.5f);
  EXPECT_THROW(dropout.forward(Matrix::Ones(2, 2), true), std::logic_error);  // no Rng
  EXPECT_THROW(dropout.forward(Matrix::Ones(3, 2), false), std::invalid_argument);
}
