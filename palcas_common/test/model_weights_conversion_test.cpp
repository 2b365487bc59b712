// ModelBlob <-> palcas_msgs/ModelWeights: a round trip keeps every field bit for bit.
#include "palcas_common/model_weights.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using palcas::ModelBlob;
using palcas::common::toModelBlob;
using palcas::common::toWeightsMsg;

TEST(ModelWeightsConversion, ModelRoundTripKeepsEveryField) {
  const ModelBlob blob{"pdqn v1 mu[45-8-4] q[49-8-4]", 0xFEDCBA9876543210ULL,
                       {0.0f, -1.5f, 3.4e38f, 1e-45f, -0.0f}};
  const palcas_msgs::ModelWeights msg = toWeightsMsg(blob, "server", 7, 6, 123456789012ULL);
  EXPECT_EQ(msg.rsu_id, "server");
  EXPECT_EQ(msg.round, 7u);
  EXPECT_EQ(msg.model_version, 6u);
  EXPECT_EQ(msg.sample_count, 123456789012ULL);  // > 2^32: the uint64 field is not narrowed
  EXPECT_EQ(msg.layout_id, blob.layout_id);
  EXPECT_EQ(msg.layout_checksum, blob.layout_checksum);
  const ModelBlob back = toModelBlob(msg);
  EXPECT_EQ(back.layout_id, blob.layout_id);
  EXPECT_EQ(back.layout_checksum, blob.layout_checksum);
  EXPECT_EQ(back.values, blob.values);
  EXPECT_TRUE(std::signbit(back.values[4]));  // -0.0 stays negative zero
}

TEST(ModelWeightsConversion, NonFiniteValuesPassThroughForTheServerToRefuse) {
  // Conversion does not judge: the FederationServer names the bad index in its reason.
  palcas_msgs::ModelWeights msg;
  msg.values = {1.0f, std::numeric_limits<float>::quiet_NaN()};
  const ModelBlob blob = toModelBlob(msg);
  ASSERT_EQ(blob.values.size(), 2u);
  EXPECT_TRUE(std::isnan(blob.values[1]));
}
