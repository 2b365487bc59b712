#include "palcas_core/learning/nn/linear.h"

#include <gtest/gtest.h>

#include <cmath>

#include "nn_test_util.h"

using namespace palcas;
using namespace palcas::nn;

namespace {

// W = [[1, 2], [3, -1]], b = [0.5, -1]; params are W column-major, then b.
Linear handLayer(Rng& rng) {
  Linear layer(2, 2, rng);
  layer.parameters() << 1, 3, 2, -1, 0.5f, -1;
  return layer;
}

}  // namespace

TEST(Linear, ForwardMatchesHandComputedValues) {
  Rng rng(1);
  Linear layer = handLayer(rng);
  Matrix x(2, 2);
  x << 1, 0,
       2, -1;  // two samples: (1, 2) and (0, -1)
  const Matrix& y = layer.forward(x, true);
  // sample 0: [1*1 + 2*2 + 0.5, 3*1 - 1*2 - 1] = [5.5, 0]
  // sample 1: [1*0 + 2*(-1) + 0.5, 3*0 - 1*(-1) - 1] = [-1.5, 0]
  EXPECT_FLOAT_EQ(y(0, 0), 5.5f);
  EXPECT_FLOAT_EQ(y(1, 0), 0.0f);
  EXPECT_FLOAT_EQ(y(0, 1), -1.5f);
  EXPECT_FLOAT_EQ(y(1, 1), 0.0f);
}

TEST(Linear, BackwardMatchesHandComputedValues) {
  Rng rng(1);
  Linear layer = handLayer(rng);
  Matrix x(2, 2);
  x << 1, 0,
       2, -1;
  layer.forward(x, true);
  const Matrix g = Matrix::Identity(2, 2);
  const Matrix dx = layer.backward(g, {true, 0});
  // dW = G X^T = X^T = [[1, 2], [0, -1]] -> column-major [1, 0, 2, -1]; db = G 1 = [1, 1]
  Vector expected_grads(6);
  expected_grads << 1, 0, 2, -1, 1, 1;
  EXPECT_EQ(layer.gradients(), expected_grads);
  // dX = W^T G = W^T = [[1, 3], [2, -1]]
  Matrix expected_dx(2, 2);
  expected_dx << 1, 3,
                 2, -1;
  EXPECT_EQ(dx, expected_dx);
}

TEST(Linear, InputGradientOnlyForRequestedRows) {
  Rng rng(1);
  Linear layer = handLayer(rng);
  Matrix x(2, 2);
  x << 1, 0,
       2, -1;
  layer.forward(x, true);
  // Row 1 of W^T G with G = I is W^T's row 1 = [2, -1]; from = 2 means no input gradient.
  const Matrix tail = layer.backward(Matrix::Identity(2, 2), {false, 1});
  ASSERT_EQ(tail.rows(), 1);
  EXPECT_FLOAT_EQ(tail(0, 0), 2.0f);
  EXPECT_FLOAT_EQ(tail(0, 1), -1.0f);
  EXPECT_EQ(layer.backward(Matrix::Identity(2, 2), {false, 2}).rows(), 0);
}

TEST(Linear, GradientCheck) {
  Rng rng(3);
  Linear layer(5, 4, rng);
  const Matrix x = test::randomMatrix(5, 3, rng);
  const Matrix w = test::randomMatrix(4, 3, rng);
  test::expectInputGradient(layer, x, w, true);
  test::expectParameterGradient(layer, x, w, true);
}

TEST(Linear, HeUniformInitialisation) {
  Rng rng(4);
  Linear layer(256, 512, rng);
  const auto weights = layer.weight();
  const float bound = std::sqrt(6.0f / 256.0f);  // sqrt(6/in) = 0.153
  EXPECT_LE(weights.cwiseAbs().maxCoeff(), bound);
  EXPECT_EQ(layer.bias(), Vector::Zero(512));
  // Var(U(-b, b)) = b^2 / 3 = 2 / in = 0.0078125; 131072 samples estimate it within ~1%.
  const double var = weights.cast<double>().array().square().mean();
  EXPECT_NEAR(var, 2.0 / 256.0, 0.05 * 2.0 / 256.0);
}

TEST(Linear, SaveLoadRoundTrip) {
  Rng rng_a(5), rng_b(6);
  Network a, b;
  a.addLayer(std::make_unique<Linear>(3, 2, rng_a));
  b.addLayer(std::make_unique<Linear>(3, 2, rng_b));
  ASSERT_NE(a.getState(), b.getState());
  test::expectSaveLoadRoundTrip(a, b, test::randomMatrix(3, 4, rng_a));
}

TEST(Linear, RejectsBadShapesAndKeepsParameters) {
  Rng rng(7);
  EXPECT_THROW(Linear(0, 3, rng), std::invalid_argument);
  Linear layer(3, 2, rng);
  const Vector before = layer.parameters();
  EXPECT_THROW(layer.forward(Matrix::Zero(4, 2), true), std::invalid_argument);
  EXPECT_THROW(layer.forward(Matrix::Zero(3, 0), true), std::invalid_argument);
  EXPECT_THROW(layer.backward(Matrix::Zero(2, 2), {}), std::logic_error);  // no forward yet
  const Matrix x = Matrix::Zero(3, 2);  // the layer keeps a pointer to its input
  layer.forward(x, true);
  EXPECT_THROW(layer.backward(Matrix::Zero(2, 5), {}), std::invalid_argument);
  EXPECT_EQ(layer.parameters(), before);
}
