#include "palcas_core/learning/fedavg.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cfloat>
#include <limits>

#include "palcas_core/learning/nn/serialization.h"
#include "palcas_core/learning/pdqn_agent.h"

using namespace palcas;

namespace {

ModelBlob blob(std::vector<float> values, const std::string& layout = "L") {
  return ModelBlob{layout, nn::fnv1a64(layout), std::move(values)};
}

// Expects fedAverage to throw std::invalid_argument mentioning `needle`.
void expectRejected(const std::vector<ModelBlob>& models, const std::vector<uint64_t>& n,
                    const std::string& needle, uint64_t max = FEDAVG_MAX_SAMPLES_DEFAULT) {
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { fedAverage(models, n, max); },
                                                            needle);
}

}  // namespace

TEST(FedAvg, IdenticalModelsGiveThatModelExactly) {
  const ModelBlob m = blob({0.1f, -3.7f, 12345.678f, 1e-30f, 0.0f});
  const ModelBlob avg = fedAverage({m, m, m}, {1, 7, 1000});
  EXPECT_EQ(avg.values, m.values);
  EXPECT_EQ(avg.layout_id, m.layout_id);
  EXPECT_EQ(avg.layout_checksum, m.layout_checksum);
}

TEST(FedAvg, WeightsFollowTheSampleCounts) {
  // n = (1, 3): weights 1/4 and 3/4.
  // [0.25*4 + 0.75*8, 0.25*(-2) + 0.75*2, 0.25*1 + 0.75*0] = [7, 1, 0.25]
  const ModelBlob avg = fedAverage({blob({4, -2, 1}), blob({8, 2, 0})}, {1, 3});
  EXPECT_EQ(avg.values, (std::vector<float>{7.0f, 1.0f, 0.25f}));
  // Three models n = (2, 1, 1): 0.5*10 + 0.25*20 + 0.25*(-40) = 0
  EXPECT_EQ(fedAverage({blob({10}), blob({20}), blob({-40})}, {2, 1, 1}).values[0], 0.0f);
}

TEST(FedAvg, ResultStaysFiniteAtTheFloatLimits) {
  // Double accumulation: 0.5*FLT_MAX + 0.5*FLT_MAX does not overflow.
  const ModelBlob avg = fedAverage({blob({FLT_MAX, -FLT_MAX}), blob({FLT_MAX, -FLT_MAX})}, {1, 1});
  EXPECT_EQ(avg.values, (std::vector<float>{FLT_MAX, -FLT_MAX}));
}

TEST(FedAvg, RejectsBadInputNamingIt) {
  const ModelBlob a = blob({1, 2}), b = blob({3, 4});
  expectRejected({}, {}, "no models");
  expectRejected({a, b}, {1}, "2 models but 1 sample counts");
  expectRejected({a, blob({1, 2}, "other")}, {1, 1}, "model 1: layout 'other' differs from model 0's");
  ModelBlob bad_checksum = b;
  bad_checksum.layout_checksum ^= 1;
  expectRejected({a, bad_checksum}, {1, 1}, "model 1: layout checksum");
  expectRejected({a, blob({1, 2, 3})}, {1, 1}, "model 1: 3 values, model 0 has 2");
  expectRejected({a, blob({1, std::numeric_limits<float>::quiet_NaN()})}, {1, 1},
                 "model 1: value 1 is not finite (nan)");
  expectRejected({blob({std::numeric_limits<float>::infinity(), 0}), b}, {1, 1},
                 "model 0: value 0 is not finite (inf)");
  expectRejected({a, b}, {1, 0}, "model 1 has sample count 0");
  expectRejected({a, b}, {2000000000ULL, 1}, "model 0 has sample count 2000000000");
  expectRejected({a, b}, {11, 1}, "plausible maximum 10", 10);
}

TEST(RobustAggregation, MedianAndTrimmedMeanByHand) {
  const auto m = [](std::vector<float> v) { return ModelBlob{"L", nn::fnv1a64("L"), std::move(v)}; };
  // Odd count: the middle value per coordinate; even: the mean of the two middle ones.
  EXPECT_EQ(coordinateMedian({m({1, 9}), m({5, 3}), m({2, 4})}).values, (std::vector<float>{2, 4}));
  EXPECT_EQ(coordinateMedian({m({1, 9}), m({5, 3}), m({2, 4}), m({8, 0})}).values,
            (std::vector<float>{3.5f, 3.5f}));
  // 5 models, trim 0.2: drop the largest and the smallest, average the middle three.
  const std::vector<ModelBlob> five{m({1}), m({2}), m({3}), m({4}), m({100})};
  EXPECT_EQ(trimmedMean(five, 0.2).values, (std::vector<float>{3}));
  EXPECT_EQ(trimmedMean(five, 0.0).values, (std::vector<float>{22}));  // the plain mean
  EXPECT_THROW(trimmedMean(five, 0.5), std::invalid_argument);
  EXPECT_THROW(coordinateMedian({m({1, 2}), m({1})}), std::invalid_argument);
  EXPECT_THROW(coordinateMedian({}), std::invalid_argument);
}

TEST(FedAvg, AveragesWholeAgentModelsIncludingBatchNormStatistics) {
  PdqnConfig c;
  c.state_size = 4;
  c.hidden_sizes = {6};
  c.batch_size = 8;
  c.replay_capacity = 16;
  std::vector<PdqnAgent> agents;
  for (uint64_t seed : {1, 2}) {
    c.seed = seed;
    agents.emplace_back(c);
    Rng data(seed + 10);
    for (int i = 0; i < 8; ++i) {
      nn::Vector s(4), s2(4);
      for (int f = 0; f < 4; ++f) {
        s[f] = data.uniform(0, 3);
        s2[f] = data.uniform(0, 3);
      }
      agents.back().remember(s, Decision{Action::kKeep, 0.0f}, 1.0f, s2, ALL_ACTIONS, false);
    }
    agents.back().update();  // training forward passes move the BN running statistics
  }
  const ModelBlob ma = agents[0].exportModel(), mb = agents[1].exportModel();
  const ModelBlob avg = fedAverage({ma, mb}, {1, 3});
  for (size_t i = 0; i < avg.values.size(); ++i)
    ASSERT_FLOAT_EQ(avg.values[i], 0.25f * ma.values[i] + 0.75f * mb.values[i]) << i;
  agents[1].importModel(avg);  // the average is a valid model of the same layout
  // mu's running variance (its state's last 6 values) moved off 1 and is averaged too.
  const nn::Vector var_a = agents[0].paramNetwork().getState().tail(6);
  const nn::Vector var_avg = agents[1].paramNetwork().getState().tail(6);
  ASSERT_NE(var_a, nn::Vector::Ones(6));
  for (int i = 0; i < 6; ++i)
    EXPECT_FLOAT_EQ(var_avg[i], avg.values[static_cast<size_t>(
                                    agents[0].paramNetwork().stateCount() - 6 + i)]);
}
