#include "palcas_core/learning/nn/network.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/activation.h"
#include "palcas_core/learning/nn/batch_norm.h"
#include "palcas_core/learning/nn/linear.h"

using namespace palcas;
using namespace palcas::nn;

namespace {
MlpSpec paperParamNet() {
  MlpSpec spec;
  spec.input_size = 45;
  spec.hidden_sizes = {256, 512, 256};
  spec.output_size = 1;
  spec.output_activation = OutputActivation::kTanh;
  return spec;
}
}  // namespace

TEST(Network, MlpLayoutFollowsTheBlockOrder) {
  Rng rng(71);
  MlpSpec spec;
  spec.input_size = 3;
  spec.hidden_sizes = {4};
  spec.output_size = 2;
  const Network net = makeMlp(spec, rng);
  EXPECT_EQ(net.layout(), "Linear(3,4);BatchNorm1d(4);ReLU(4);Dropout(4,0.1);Linear(4,2)");
  spec.batch_norm = false;
  spec.dropout = 0;
  EXPECT_EQ(makeMlp(spec, rng).layout(), "Linear(3,4);ReLU(4);Linear(4,2)");
  EXPECT_NE(net.layoutChecksum(), makeMlp(spec, rng).layoutChecksum());
}

TEST(Network, PaperParameterNetworkCounts) {
  Rng rng(72);
  const Network net = makeMlp(paperParamNet(), rng);
  // Linear(45,256) 45*256+256 = 11776; BN(256) 2*256 = 512; Linear(256,512) 131584;
  // BN(512) 1024; Linear(512,256) 131328; BN(256) 512; Linear(256,1) 257 -> 276993.
  EXPECT_EQ(net.parameterCount(), 276993);
  // Running mean + var: 2*(256 + 512 + 256) = 2048.
  EXPECT_EQ(net.bufferCount(), 2048);
}

TEST(Network, GradientCheckThroughStackedBatchNorm) {
  // Two Linear -> BN blocks chained; Tanh instead of ReLU because with batch-normalised
  // pre-activations many sit within h of ReLU's kink, where finite differences are
  // meaningless (each layer's own check covers ReLU away from the kink).
  Rng rng(73);
  Network net;
  net.addLayer(std::make_unique<Linear>(3, 5, rng));
  net.addLayer(std::make_unique<BatchNorm1d>(5));
  net.addLayer(std::make_unique<Tanh>(5));
  net.addLayer(std::make_unique<Linear>(5, 4, rng));
  net.addLayer(std::make_unique<BatchNorm1d>(4));
  net.addLayer(std::make_unique<Tanh>(4));
  net.addLayer(std::make_unique<Linear>(4, 2, rng));
  const Matrix x = test::randomMatrix(3, 6, rng);
  const Matrix w = test::randomMatrix(2, 6, rng);
  net.forward(x);
  const Matrix dx = net.backward(w, {true, 0});
  Vector grads(net.parameterCount());
  Index offset = 0;
  for (size_t i = 0; i < net.layerCount(); ++i) {
    grads.segment(offset, net.layer(i).gradients().size()) = net.layer(i).gradients();
    offset += net.layer(i).gradients().size();
  }
  auto loss = [&](const Matrix& input) {
    return (net.forward(input).cast<double>().array() * w.cast<double>().array()).sum();
  };
  const Vector params = net.getParameters();
  for (Index i = 0; i < params.size(); ++i) {
    Vector p = params;
    p[i] += 1e-2f;
    net.setParameters(p);
    const double plus = loss(x);
    p[i] -= 2e-2f;
    net.setParameters(p);
    const double minus = loss(x);
    EXPECT_LT(test::relativeError((plus - minus) / 2e-2, grads[i]), 1e-2) << "parameter " << i;
  }
  net.setParameters(params);
  for (Index i = 0; i < x.size(); ++i) {
    Matrix xp = x;
    xp.data()[i] += 1e-2f;
    const double plus = loss(xp);
    xp.data()[i] -= 2e-2f;
    const double minus = loss(xp);
    EXPECT_LT(test::relativeError((plus - minus) / 2e-2, dx.data()[i]), 1e-2) << "input " << i;
  }
}

TEST(Network, StateRoundTripAndDeepCopy) {
  Rng rng(74);
  MlpSpec spec;
  spec.input_size = 2;
  spec.hidden_sizes = {3};
  spec.output_size = 1;
  Network a = makeMlp(spec, rng);
  Network b = makeMlp(spec, rng);
  ASSERT_NE(a.getState(), b.getState());
  b.setState(a.getState());
  EXPECT_EQ(a.getState(), b.getState());
  Network copy = a;
  copy.layer(0).parameters()[0] += 1.0f;
  EXPECT_NE(copy.getState(), a.getState());  // the copy owns its own layers
  EXPECT_EQ(copy.layout(), a.layout());
}

TEST(Network, StateSpansFromALayerCoverItsParametersThenItsBuffers) {
  Rng rng(75);
  MlpSpec spec;
  spec.input_size = 3;
  spec.hidden_sizes = {4};
  spec.output_size = 2;
  // Linear(3,4) 16 params; BatchNorm1d(4) 8 params + 8 buffers; ReLU; Dropout; Linear(4,2) 10.
  const Network net = makeMlp(spec, rng);
  ASSERT_EQ(net.parameterCount(), 34);
  ASSERT_EQ(net.bufferCount(), 8);
  auto spans = net.stateSpansFrom(4);  // the output Linear: parameters only
  ASSERT_EQ(spans.size(), 1u);
  EXPECT_EQ(spans[0].begin, 24);
  EXPECT_EQ(spans[0].count, 10);
  spans = net.stateSpansFrom(1);  // batch norm on: its parameters and the rest, then its buffers
  ASSERT_EQ(spans.size(), 2u);
  EXPECT_EQ(spans[0].begin, 16);
  EXPECT_EQ(spans[0].count, 18);
  EXPECT_EQ(spans[1].begin, 34);
  EXPECT_EQ(spans[1].count, 8);
  EXPECT_TRUE(net.stateSpansFrom(5).empty());
  EXPECT_EQ(net.stateSpansFrom(0).size(), 2u);
  EXPECT_THROW(net.stateSpansFrom(6), std::out_of_range);
}

TEST(Network, RejectsBadStateAndShapesLeavingItUnchanged) {
  Rng rng(75);
  MlpSpec spec;
  spec.input_size = 2;
  spec.hidden_sizes = {3};
  spec.output_size = 1;
  Network net = makeMlp(spec, rng);
  const Vector before = net.getState();
  Vector bad = before;
  bad[3] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(net.setState(bad), std::invalid_argument);
  EXPECT_THROW(net.setState(Vector::Zero(before.size() - 1)), std::invalid_argument);
  EXPECT_THROW(net.setParameters(Vector::Zero(2)), std::invalid_argument);
  EXPECT_EQ(net.getState(), before);
  EXPECT_THROW(net.forward(Matrix::Zero(3, 2)), std::invalid_argument);
  EXPECT_THROW(net.addLayer(std::make_unique<Linear>(7, 2, rng)), std::invalid_argument);
  EXPECT_THROW(net.addLayer(nullptr), std::invalid_argument);
  Network empty;
  EXPECT_THROW(empty.forward(Matrix::Zero(1, 1)), std::logic_error);
}

TEST(Network, EvalModeIsDeterministicTrainModeIsNot) {
  Rng rng(76);
  MlpSpec spec;
  spec.input_size = 4;
  spec.hidden_sizes = {16};
  spec.output_size = 2;
  spec.dropout = 0.5f;
  Network net = makeMlp(spec, rng);
  net.setRng(&rng);
  const Matrix x = test::randomMatrix(4, 8, rng);
  net.eval();
  const Matrix e1 = net.forward(x);
  EXPECT_EQ(e1, net.forward(x));  // no dropout, running stats
  net.train();
  const Matrix t1 = net.forward(x);
  EXPECT_NE(t1, net.forward(x));  // fresh dropout masks
}
