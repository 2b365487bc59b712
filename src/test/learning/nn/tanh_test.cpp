#include "palcas_core/learning/nn/activation.h"

#include <gtest/gtest.h>

#include <cmath>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/linear.h"

using namespace palcas;
using namespace palcas::nn;

TEST(Tanh, ForwardAndBackwardMatchHandComputedValues) {
  Tanh layer(2);
  // x = ln(3)/2: e^{2x} = 3, tanh = (3 - 1)/(3 + 1) = 0.5; tanh(0) = 0.
  Matrix x(2, 1);
  x << static_cast<float>(0.5 * std::log(3.0)), 0;
  const Matrix y = layer.forward(x, true);
  EXPECT_NEAR(y(0, 0), 0.5f, 1e-6f);
  EXPECT_FLOAT_EQ(y(1, 0), 0.0f);
  // dy/dx = 1 - y^2 = [0.75, 1]; times g = [2, 3] -> [1.5, 3]
  const Matrix dx = layer.backward((Matrix(2, 1) << 2, 3).finished(), {});
  EXPECT_NEAR(dx(0, 0), 1.5f, 1e-6f);
  EXPECT_FLOAT_EQ(dx(1, 0), 3.0f);
}

TEST(Tanh, GradientCheck) {
  Rng rng(21);
  Tanh layer(3);
  test::expectInputGradient(layer, test::randomMatrix(3, 4, rng, -2, 2),
                            test::randomMatrix(3, 4, rng), true);
}

TEST(Tanh, SaveLoadRoundTrip) {
  Rng rng_a(22), rng_b(23);
  Network a, b;
  a.addLayer(std::make_unique<Linear>(2, 1, rng_a));
  a.addLayer(std::make_unique<Tanh>(1));
  b.addLayer(std::make_unique<Linear>(2, 1, rng_b));
  b.addLayer(std::make_unique<Tanh>(1));
  test::expectSaveLoadRoundTrip(a, b, test::randomMatrix(2, 3, rng_a));
}

TEST(Tanh, RejectsBadShapes) {
  EXPECT_THROW(Tanh(0), std::invalid_argument);
  Tanh layer(2);
  EXPECT_THROW(layer.forward(Matrix::Zero(1, 1), true), std::invalid_argument);
  EXPECT_THROW(layer.backward(Matrix::Zero(2, 1), {}), std::logic_error);
}
