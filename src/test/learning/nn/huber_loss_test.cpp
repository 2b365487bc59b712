#include "palcas_core/learning/nn/huber_loss.h"

#include <gtest/gtest.h>

#include "nn_test_util.h"

using namespace palcas;
using namespace palcas::nn;

TEST(HuberLoss, ValueAndGradientMatchHandComputedValues) {
  HuberLoss huber(1.0f);
  Matrix pred(1, 2), target(1, 2);
  pred << 0, 3;
  target << 0.5f, 0;
  // d = [-0.5, 3]: l = [0.5*0.25, 1*(3 - 0.5)] = [0.125, 2.5]; mean = 1.3125
  EXPECT_FLOAT_EQ(huber.compute(pred, target), 1.3125f);
  // dL/dpred = clamp(d, -1, 1) / 2 = [-0.25, 0.5]
  EXPECT_FLOAT_EQ(huber.gradient()(0, 0), -0.25f);
  EXPECT_FLOAT_EQ(huber.gradient()(0, 1), 0.5f);
}

TEST(HuberLoss, DeltaScalesTheLinearPart) {
  HuberLoss huber(2.0f);
  Matrix pred(1, 1), target(1, 1);
  pred << 5;
  target << 0;
  // |d| = 5 > 2: l = 2 (5 - 1) = 8; gradient = clamp(5, -2, 2) = 2
  EXPECT_FLOAT_EQ(huber.compute(pred, target), 8.0f);
  EXPECT_FLOAT_EQ(huber.gradient()(0, 0), 2.0f);
}

TEST(HuberLoss, GradientCheck) {
  Rng rng(51);
  HuberLoss huber(1.0f);
  Matrix pred = test::randomMatrix(2, 5, rng, -3, 3);
  const Matrix target = test::randomMatrix(2, 5, rng, -3, 3);
  huber.compute(pred, target);
  const Matrix analytic = huber.gradient();
  for (Index i = 0; i < pred.size(); ++i) {
    const float original = pred.data()[i];
    pred.data()[i] = original + 1e-2f;
    const double plus = huber.compute(pred, target);
    pred.data()[i] = original - 1e-2f;
    const double minus = huber.compute(pred, target);
    pred.data()[i] = original;
    EXPECT_LT(test::relativeError((plus - minus) / 2e-2, analytic.data()[i]), 1e-2) << i;
  }
}

TEST(HuberLoss, RejectsBadInput) {
  EXPECT_THROW(HuberLoss(0.0f), std::invalid_argument);
  HuberLoss huber;
  EXPECT_THROW(huber.compute(Matrix::Zero(1, 2), Matrix::Zero(1, 3)), std::invalid_argument);
  EXPECT_THROW(huber.compute(Matrix::Zero(0, 0), Matrix::Zero(0, 0)), std::invalid_argument);
}
