#include "palcas_core/learning/nn/activation.h"

#include <gtest/gtest.h>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/linear.h"

using namespace palcas;
using namespace palcas::nn;

TEST(ReLU, ForwardAndBackwardMatchHandComputedValues) {
  ReLU relu(3);
  Matrix x(3, 1);
  x << -2, 0, 3;
  // max(0, x) = [0, 0, 3]
  const Matrix y = relu.forward(x, true);
  EXPECT_EQ(y, (Matrix(3, 1) << 0, 0, 3).finished());
  // dy/dx = [0, 0 (PyTorch's choice at x = 0), 1]; times g = [5, 6, 7] -> [0, 0, 7]
  const Matrix dx = relu.backward((Matrix(3, 1) << 5, 6, 7).finished(), {});
  EXPECT_EQ(dx, (Matrix(3, 1) << 0, 0, 7).finished());
}

TEST(ReLU, GradientCheck) {
  Rng rng(11);
  ReLU relu(4);
  // Keep |x| >= 0.1 > h so no finite difference straddles the kink at 0.
  Matrix x = test::randomMatrix(4, 3, rng);
  for (Index i = 0; i < x.size(); ++i)
    x.data()[i] = x.data()[i] >= 0 ? x.data()[i] + 0.1f : x.data()[i] - 0.1f;
  test::expectInputGradient(relu, x, test::randomMatrix(4, 3, rng), true);
}

TEST(ReLU, SaveLoadRoundTrip) {
  Rng rng_a(12), rng_b(13);
  Network a, b;
  a.addLayer(std::make_unique<Linear>(2, 3, rng_a));
  a.addLayer(std::make_unique<ReLU>(3));
  b.addLayer(std::make_unique<Linear>(2, 3, rng_b));
  b.addLayer(std::make_unique<ReLU>(3));
  test::expectSaveLoadRoundTrip(a, b, test::randomMatrix(2, 5, rng_a));
}

TEST(ReLU, RejectsBadShapes) {
  EXPECT_THROW(ReLU(0), std::invalid_argument);
  ReLU relu(2);
  EXPECT_THROW(relu.backward(Matrix::Zero(2, 1), {}), std::logic_error);
  EXPECT_THROW(relu.forward(Matrix::Zero(3, 1), true), std::invalid_argument);
  relu.forward(Matrix::Zero(2, 1), true);
  EXPECT_THROW(relu.backward(Matrix::Zero(2, 2), {}), std::invalid_argument);
}
