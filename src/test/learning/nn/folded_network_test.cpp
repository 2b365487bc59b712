#include "palcas_core/learning/nn/folded_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "nn_test_util.h"
#include "palcas_core/learning/nn/activation.h"
#include "palcas_core/learning/nn/adamw.h"
#include "palcas_core/learning/nn/batch_norm.h"
#include "palcas_core/learning/nn/dropout.h"
#include "palcas_core/learning/nn/linear.h"
#include "palcas_core/learning/nn/network.h"

using namespace palcas;
using namespace palcas::nn;

namespace {

// Linear(2,2) -> BN(2, eps 0.25) -> ReLU -> Dropout -> Linear(2,1) -> Tanh, values below.
Network handNetwork() {
  Rng rng(1);
  Network net;
  net.addLayer(std::make_unique<Linear>(2, 2, rng));
  net.addLayer(std::make_unique<BatchNorm1d>(2, 0.1f, 0.25f));
  net.addLayer(std::make_unique<ReLU>(2));
  net.addLayer(std::make_unique<Dropout>(2, 0.5f));
  net.addLayer(std::make_unique<Linear>(2, 1, rng));
  net.addLayer(std::make_unique<Tanh>(1));
  // W = [1 2; 3 -1] column-major, b = [0.5, -1].
  net.layer(0).parameters() << 1, 3, 2, -1, 0.5f, -1;
  // gamma = [2, 0.5], beta = [1, -1]; running mean [1, 0], running var [3.75, 0.75], so
  // sqrt(var + eps) = [2, 1] exactly.
  net.layer(1).parameters() << 2, 0.5f, 1, -1;
  net.layer(1).buffers() << 1, 0, 3.75f, 0.75f;
  net.layer(4).parameters() << 0.5f, 4, 0.25f;  // W = [0.5 4], b = 0.25
  return net;
}

// An MLP (default: the paper's hidden sizes) whose batch norms hold non-trivial running
// statistics.
Network trainedMlp(Index in, Index out, OutputActivation activation, uint64_t seed,
                   std::vector<Index> hidden = {256, 512, 256}) {
  Rng rng(seed);
  MlpSpec spec{in, hidden, out, true, 0.1f, activation};
  Network net = makeMlp(spec, rng);
  net.setRng(&rng);
  net.train();
  for (int i = 0; i < 5; ++i) net.forward(test::randomMatrix(in, 64, rng, -2, 3));
  net.eval();
  net.setRng(nullptr);
  return net;
}

void expectClose(const Matrix& folded, const Matrix& reference) {
  ASSERT_EQ(folded.rows(), reference.rows());
  ASSERT_EQ(folded.cols(), reference.cols());
  // Float rounding of a re-associated sum over 512 products: relative to the output scale.
  const float scale = std::max(1.0f, reference.cwiseAbs().maxCoeff());
  EXPECT_LE((folded - reference).cwiseAbs().maxCoeff(), 1e-4f * scale);
}

}  // namespace

TEST(FoldedNetwork, MatchesHandComputedValues) {
  Network net = handNetwork();
  FoldedNetwork folded(net);
  Matrix x(2, 3);
  x << 1, 0, 2,  //
      1, -1, 0;
  const Matrix& y = folded.forward(x);
  ASSERT_EQ(y.rows(), 1);
  ASSERT_EQ(y.cols(), 3);
  // x = [1, 1]:  z = W x + b = [3.5, 1]; BN: [2 (3.5 - 1)/2 + 1, 0.5 (1 - 0)/1 - 1] = [3.5, -0.5]
  //   ReLU [3.5, 0]; 0.5*3.5 + 4*0 + 0.25 = 2.0; tanh(2) = 0.9640276
  EXPECT_NEAR(y(0, 0), 0.9640276f, 1e-6f);
  // x = [0, -1]: z = [-1.5, 0]; BN: [2 (-2.5)/2 + 1, -1] = [-1.5, -1]; ReLU [0, 0];
  //   0.25; tanh(0.25) = 0.2449187
  EXPECT_NEAR(y(0, 1), 0.2449187f, 1e-6f);
  // x = [2, 0]:  z = [2.5, 5]; BN: [2*1.5/2 + 1, 0.5*5 - 1] = [2.5, 1.5]; ReLU keeps both;
  //   0.5*2.5 + 4*1.5 + 0.25 = 7.5; tanh(7.5) = 0.9999994
  EXPECT_NEAR(y(0, 2), 0.9999994f, 1e-6f);
  net.eval();
  expectClose(y, net.forward(x));
}

TEST(FoldedNetwork, AgreesWithTheEvalNetworkOnThePaperShapes) {
  Rng rng(5);
  for (int shape = 0; shape < 3; ++shape) {
    // mu and Q of the paper; then widths that leave partial panels and a 20-wide head.
    Network net = shape == 0   ? trainedMlp(45, 1, OutputActivation::kTanh, 12)
                  : shape == 1 ? trainedMlp(46, 4, OutputActivation::kNone, 11)
                               : trainedMlp(45, 20, OutputActivation::kNone, 14, {70, 33});
    FoldedNetwork folded(net);
    EXPECT_EQ(folded.inputSize(), net.inputSize());
    EXPECT_EQ(folded.outputSize(), net.outputSize());
    // 1, 7 and 100 columns exercise the kernel's full and single-column blocks.
    for (Index n : {1, 7, 100}) {
      const Matrix x = test::randomMatrix(net.inputSize(), n, rng, -2, 2);
      const Matrix expected = net.forward(x);
      expectClose(folded.forward(x), expected);
    }
  }
}

TEST(FoldedNetwork, ColumnResultDoesNotDependOnTheBatch) {
  Network net = trainedMlp(45, 1, OutputActivation::kTanh, 13);
  FoldedNetwork folded(net);
  Rng rng(6);
  const Matrix x = test::randomMatrix(45, 29, rng, -2, 2);
  const Matrix batch = folded.forward(x);
  for (Index j = 0; j < x.cols(); ++j) {
    const Matrix alone = folded.forward(x.col(j));
    EXPECT_EQ(alone(0, 0), batch(0, j)) << "column " << j;  // bit for bit
  }
}

TEST(FoldedNetwork, FollowsEveryStateChange) {
  Network net = handNetwork();
  FoldedNetwork folded(net);
  EXPECT_TRUE(folded.isCurrentFor(net));
  EXPECT_FALSE(folded.refresh(net));  // nothing changed
  Matrix x(2, 1);
  x << 2, 0;
  net.eval();
  net.forward(x);  // eval forward changes nothing
  EXPECT_TRUE(folded.isCurrentFor(net));

  Network copy = net;  // same values, but another network
  EXPECT_FALSE(folded.isCurrentFor(copy));

  Vector params = net.getParameters();
  params[params.size() - 1] = 1.25f;  // output bias 0.25 -> 1.25
  net.setParameters(params);
  EXPECT_FALSE(folded.isCurrentFor(net));
  EXPECT_TRUE(folded.refresh(net));
  // Same path as x = [2, 0] above with bias 1.25: tanh(8.5) = 0.99999992
  EXPECT_NEAR(folded.forward(x)(0, 0), std::tanh(8.5f), 1e-6f);

  net.setState(net.getState());
  EXPECT_FALSE(folded.isCurrentFor(net));
  folded.refresh(net);

  Rng rng(7);
  net.setRng(&rng);
  net.train();
  Matrix batch(2, 2);
  batch << 1, 2, 0, -1;
  net.forward(batch);  // training forward moves the running statistics
  EXPECT_FALSE(folded.isCurrentFor(net));
  net.backward(Matrix::Ones(1, 2), {true, net.inputSize()});
  folded.refresh(net);
  AdamW adam;
  adam.step(net);  // the optimiser writes parameters
  EXPECT_FALSE(folded.isCurrentFor(net));
  folded.refresh(net);
  net.eval();
  expectClose(folded.forward(batch), net.forward(batch));
}

TEST(FoldedNetwork, RejectsUnfoldableNetworksAndBadInput) {
  EXPECT_THROW(FoldedNetwork{Network{}}, std::invalid_argument);
  Rng rng(8);
  Network bn_first;
  bn_first.addLayer(std::make_unique<BatchNorm1d>(3));
  try {
    FoldedNetwork folded(bn_first);
    ADD_FAILURE() << "folded a batch norm without a Linear";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("layer 0 (BatchNorm1d(3))"), std::string::npos)
        << e.what();
  }
  Network bn_after_relu;
  bn_after_relu.addLayer(std::make_unique<Linear>(3, 3, rng));
  bn_after_relu.addLayer(std::make_unique<ReLU>(3));
  bn_after_relu.addLayer(std::make_unique<BatchNorm1d>(3));
  EXPECT_THROW(FoldedNetwork{bn_after_relu}, std::invalid_argument);

  FoldedNetwork empty;
  EXPECT_THROW(empty.forward(Matrix::Zero(2, 1)), std::logic_error);

  Network net = handNetwork();
  FoldedNetwork folded(net);
  EXPECT_THROW(folded.forward(Matrix::Zero(3, 1)), std::invalid_argument);  // 3 rows, not 2
  EXPECT_THROW(folded.forward(Matrix::Zero(2, 0)), std::invalid_argument);  // no column
  // A failed refresh keeps the previous fold.
  EXPECT_THROW(folded.refresh(bn_after_relu), std::invalid_argument);
  EXPECT_TRUE(folded.isCurrentFor(net));
  Matrix x(2, 1);
  x << 1, 1;
  EXPECT_NEAR(folded.forward(x)(0, 0), 0.9640276f, 1e-6f);
}
