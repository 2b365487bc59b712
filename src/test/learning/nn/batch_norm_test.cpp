#include "palcas_core/learning/nn/batch_norm.h"

#include <gtest/gtest.h>

#include <cmath>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/linear.h"

using namespace palcas;
using namespace palcas::nn;

TEST(BatchNorm1d, TrainingForwardMatchesHandComputedValues) {
  BatchNorm1d bn(1);
  bn.parameters() << 2, 1;  // gamma = 2, beta = 1
  Matrix x(1, 2);
  x << 1, 3;
  const Matrix y = bn.forward(x, true);
  // mean = 2, biased var = ((1-2)^2 + (3-2)^2)/2 = 1, xhat = -+1/sqrt(1 + 1e-5)
  // y = 2 xhat + 1 = [1 - 2/sqrt(1.00001), 1 + 2/sqrt(1.00001)] = [-0.99999, 2.99999]
  const float s = 2.0f / std::sqrt(1.00001f);
  EXPECT_NEAR(y(0, 0), 1.0f - s, 1e-6f);
  EXPECT_NEAR(y(0, 1), 1.0f + s, 1e-6f);
  // running mean = 0.9*0 + 0.1*2 = 0.2; running var = 0.9*1 + 0.1*(unbiased var 2) = 1.1
  EXPECT_NEAR(bn.runningMean()[0], 0.2f, 1e-7f);
  EXPECT_NEAR(bn.runningVar()[0], 1.1f, 1e-6f);
}

TEST(BatchNorm1d, EvalForwardUsesRunningStatistics) {
  BatchNorm1d bn(1);
  bn.parameters() << 2, 1;
  bn.buffers() << 0.2f, 1.1f;  // running mean, running var
  Matrix x(1, 2);
  x << 0.2f, 0.2f + std::sqrt(1.1f + 1e-5f);
  // xhat = (x - 0.2)/sqrt(1.1 + 1e-5) = [0, 1]; y = 2 xhat + 1 = [1, 3]
  const Matrix y = bn.forward(x, false);
  EXPECT_NEAR(y(0, 0), 1.0f, 1e-6f);
  EXPECT_NEAR(y(0, 1), 3.0f, 1e-6f);
  EXPECT_EQ(bn.buffers(), (Vector(2) << 0.2f, 1.1f).finished());  // eval leaves stats alone
}

TEST(BatchNorm1d, GradientCheckTrainingMode) {
  Rng rng(31);
  BatchNorm1d bn(3);
  bn.parameters() << 1.5f, 0.5f, -1.0f, 0.1f, 0.2f, 0.3f;
  const Matrix x = test::randomMatrix(3, 5, rng, -2, 2);
  const Matrix w = test::randomMatrix(3, 5, rng);
  test::expectInputGradient(bn, x, w, true);
  test::expectParameterGradient(bn, x, w, true);
}

TEST(BatchNorm1d, GradientCheckEvalMode) {
  Rng rng(32);
  BatchNorm1d bn(2);
  bn.parameters() << 1.5f, -0.5f, 0.1f, 0.2f;
  bn.buffers() << 0.3f, -0.2f, 2.0f, 0.5f;
  const Matrix x = test::randomMatrix(2, 3, rng, -2, 2);
  const Matrix w = test::randomMatrix(2, 3, rng);
  test::expectInputGradient(bn, x, w, false);
  test::expectParameterGradient(bn, x, w, false);
}

TEST(BatchNorm1d, TrainingInputGradientSumsToZeroOverBatch) {
  // Shifting every sample of a feature by the same amount leaves the output unchanged, so
  // sum_n dL/dx_n = 0 per feature for any upstream gradient.
  Rng rng(33);
  BatchNorm1d bn(4);
  bn.forward(test::randomMatrix(4, 6, rng), true);
  const Matrix dx = bn.backward(test::randomMatrix(4, 6, rng), {});
  for (Index i = 0; i < 4; ++i) EXPECT_NEAR(dx.row(i).sum(), 0.0f, 1e-5f);
}

TEST(BatchNorm1d, SaveLoadRoundTripIncludesRunningStatistics) {
  Rng rng(34);
  Network a, b;
  a.addLayer(std::make_unique<BatchNorm1d>(3));
  b.addLayer(std::make_unique<BatchNorm1d>(3));
  a.layer(0).parameters() << 1, 2, 3, 4, 5, 6;
  a.forward(test::randomMatrix(3, 8, rng, 0, 5));  // moves the running stats off 0 / 1
  ASSERT_NE(a.layer(0).buffers(), b.layer(0).buffers());
  test::expectSaveLoadRoundTrip(a, b, test::randomMatrix(3, 2, rng));
  EXPECT_EQ(a.layer(0).buffers(), b.layer(0).buffers());
}

TEST(BatchNorm1d, RejectsBadInput) {
  EXPECT_THROW(BatchNorm1d(0), std::invalid_argument);
  EXPECT_THROW(BatchNorm1d(2, 0.0f), std::invalid_argument);
  EXPECT_THROW(BatchNorm1d(2, 0.1f, 0.0f), std::invalid_argument);
  BatchNorm1d bn(2);
  const Vector buffers = bn.buffers();
  // One sample has no variance: training refuses it (as PyTorch), stats untouched.
  EXPECT_THROW(bn.forward(Matrix::Ones(2, 1), true), std::invalid_argument);
  EXPECT_THROW(bn.forward(Matrix::Ones(3, 4), true), std::invalid_argument);
  EXPECT_EQ(bn.buffers(), buffers);
  EXPECT_NO_THROW(bn.forward(Matrix::Ones(2, 1), false));  // eval: one sample is fine
}
