#include "palcas_core/learning/nn/adamw.h"

#include <gtest/gtest.h>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/batch_norm.h"
#include "palcas_core/learning/nn/linear.h"
#include "palcas_core/learning/nn/serialization.h"

using namespace palcas;
using namespace palcas::nn;

namespace {

// y = w x + b with w = 1, b = 0; forward x = 2, backward g = 1 gives dw = 2, db = 1.
Network scalarNet(Rng& rng) {
  Network net;
  net.addLayer(std::make_unique<Linear>(1, 1, rng));
  net.layer(0).parameters() << 1, 0;
  return net;
}

void computeGradients(Network& net) {
  net.forward(Matrix::Constant(1, 1, 2));
  net.backward(Matrix::Ones(1, 1), {true, 1});
}

}  // namespace

TEST(AdamW, TwoStepsMatchHandComputedValues) {
  Rng rng(61);
  Network net = scalarNet(rng);
  AdamW adamw({0.1f, 0.9f, 0.999f, 1e-8f, 0.01f});
  computeGradients(net);
  adamw.step(net);
  // Step 1, w: decay 1*(1 - 0.1*0.01) = 0.999; m = 0.1*2 = 0.2; v = 0.001*4 = 0.004;
  // step = 0.1/(1 - 0.9) = 1; denom = sqrt(0.004)/sqrt(1 - 0.999) + 1e-8 = 2
  // w = 0.999 - 1 * 0.2/2 = 0.899.   b: 0 - 1 * 0.1/(sqrt(0.001)/sqrt(0.001)) = -0.1
  EXPECT_NEAR(net.layer(0).parameters()[0], 0.899f, 1e-6f);
  EXPECT_NEAR(net.layer(0).parameters()[1], -0.1f, 1e-6f);
  computeGradients(net);  // dw = 2 again (it does not depend on w)
  adamw.step(net);
  // Step 2, w: 0.899*0.999 = 0.898101; m = 0.9*0.2 + 0.1*2 = 0.38; v = 0.999*0.004 +
  // 0.001*4 = 0.007996; m/(1-0.81) = 2; v/(1-0.998001) = 4 -> update 0.1*2/2 = 0.1
  // w = 0.798101
  EXPECT_NEAR(net.layer(0).parameters()[0], 0.798101f, 1e-6f);
  EXPECT_EQ(adamw.stepCount(), 2u);
}

TEST(AdamW, DecaysWeightsDecoupledFromTheGradient) {
  Rng rng(62);
  Network net = scalarNet(rng);
  net.forward(Matrix::Zero(1, 1));  // x = 0 -> dw = 0
  net.backward(Matrix::Zero(1, 1), {true, 1});
  AdamW adamw({0.1f, 0.9f, 0.999f, 1e-8f, 0.5f});
  adamw.step(net);
  // Zero gradient: Adam term m/(sqrt v + eps) = 0; only w *= 1 - 0.1*0.5 = 0.95 remains.
  EXPECT_FLOAT_EQ(net.layer(0).parameters()[0], 0.95f);
}

TEST(AdamW, LeavesBatchNormRunningStatisticsAlone) {
  Rng rng(63);
  Network net;
  net.addLayer(std::make_unique<Linear>(2, 2, rng));
  net.addLayer(std::make_unique<BatchNorm1d>(2));
  net.forward(test::randomMatrix(2, 4, rng));
  net.backward(test::randomMatrix(2, 4, rng), {true, 2});
  const Vector buffers = net.layer(1).buffers();
  const Vector params = net.getParameters();
  AdamW adamw;
  adamw.step(net);
  EXPECT_EQ(net.layer(1).buffers(), buffers);
  EXPECT_NE(net.getParameters(), params);
}

TEST(AdamW, SavedStateContinuesIdentically) {
  Rng rng(64);
  Network a = scalarNet(rng), b = scalarNet(rng);
  AdamW opt_a, opt_b;
  computeGradients(a);
  opt_a.step(a);
  ByteWriter w;
  opt_a.write(w);
  ByteReader r(w.bytes(), "test");
  opt_b.read(r);
  b.setState(a.getState());
  computeGradients(a);
  computeGradients(b);
  opt_a.step(a);
  opt_b.step(b);
  EXPECT_EQ(a.getState(), b.getState());
  EXPECT_EQ(opt_b.stepCount(), 2u);
}

TEST(AdamW, RejectsBadConfigAndForeignNetworks) {
  EXPECT_THROW(AdamW({-1e-3f}), std::invalid_argument);
  EXPECT_THROW(AdamW({1e-3f, 1.0f}), std::invalid_argument);
  EXPECT_THROW(AdamW({1e-3f, 0.9f, 0.999f, 0.0f}), std::invalid_argument);
  EXPECT_THROW(AdamW({1e-3f, 0.9f, 0.999f, 1e-8f, -1.0f}), std::invalid_argument);
  Rng rng(65);
  Network small = scalarNet(rng);
  Network big;
  big.addLayer(std::make_unique<Linear>(3, 3, rng));
  AdamW adamw;
  computeGradients(small);
  adamw.step(small);
  const Vector before = big.getParameters();
  EXPECT_THROW(adamw.step(big), std::invalid_argument);
  EXPECT_EQ(big.getParameters(), before);
}
