// Signing ROS messages: a tag covers every field, survives the wire format, and a message
// without a key's tag is told apart from a forged one.
#include "palcas_common/message_auth.h"

#include <gtest/gtest.h>
#include <palcas_msgs/AdvisoryArray.h>
#include <palcas_msgs/ModelWeights.h>

#include <vector>

namespace palcas::common {
namespace {

using auth::MessageKey;
using auth::Verdict;

palcas_msgs::AdvisoryArray someAdvisories() {
  palcas_msgs::AdvisoryArray a;
  a.step = 42;
  a.rsu_id = "rsu_0";
  a.decision_ms = 1.25f;
  palcas_msgs::Advisory adv;
  adv.vehicle_id = "cav_7";
  adv.action = palcas_msgs::Advisory::LANE_LEFT;
  adv.accel_mps2 = 0.0;
  a.advisories.push_back(adv);
  return a;
}

const MessageKey kKey = MessageKey::fromBytes(std::vector<std::uint8_t>(32, 0x5a));
const MessageKey kOtherKey = MessageKey::fromBytes(std::vector<std::uint8_t>(32, 0xa5));

TEST(MessageSigning, SignedArrayVerifiesAndSurvivesTheWire) {
  palcas_msgs::AdvisoryArray a = someAdvisories();
  signMessage(a, &kKey);
  ASSERT_EQ(a.auth_tag.size(), auth::TAG_BYTES);
  EXPECT_EQ(verifyMessage(a, &kKey), Verdict::kAuthentic);
  // Through ROS serialisation and back, as a subscriber receives it.
  const std::uint32_t size = ros::serialization::serializationLength(a);
  std::vector<std::uint8_t> wire(size);
  ros::serialization::OStream out(wire.data(), size);
  ros::serialization::serialize(out, a);
  palcas_msgs::AdvisoryArray received;
  ros::serialization::IStream in(wire.data(), size);
  ros::serialization::deserialize(in, received);
  EXPECT_EQ(verifyMessage(received, &kKey), Verdict::kAuthentic);
  EXPECT_EQ(verifyMessage(received, &kOtherKey), Verdict::kForged);
}

TEST(MessageSigning, EveryFieldIsCovered) {
  palcas_msgs::AdvisoryArray signed_array = someAdvisories();
  signMessage(signed_array, &kKey);
  auto tampered = [&](auto change) {
    palcas_msgs::AdvisoryArray a = signed_array;
    change(a);
    return verifyMessage(a, &kKey);
  };
  EXPECT_EQ(tampered([](auto& a) { a.rsu_id = "rsu_1"; }), Verdict::kForged);
  EXPECT_EQ(tampered([](auto& a) { a.step = 43; }), Verdict::kForged);
  EXPECT_EQ(tampered([](auto& a) { a.advisories[0].action = palcas_msgs::Advisory::LANE_RIGHT; }),
            Verdict::kForged);
  EXPECT_EQ(tampered([](auto& a) { a.advisories[0].vehicle_id = "cav_8"; }), Verdict::kForged);
  EXPECT_EQ(tampered([](auto& a) { a.advisories.push_back(a.advisories[0]); }), Verdict::kForged);
  EXPECT_EQ(tampered([](auto& a) { a.header.stamp.sec = 9; }), Verdict::kForged);
  // header.seq is left out: rospy rewrites it when it publishes a signed message.
  EXPECT_EQ(tampered([](auto& a) { a.header.seq = 17; }), Verdict::kAuthentic);
  EXPECT_EQ(tampered([](auto& a) { a.auth_tag.clear(); }), Verdict::kMissing);
  EXPECT_EQ(tampered([](auto& a) { a.auth_tag.resize(8); }), Verdict::kBadLength);
}

TEST(MessageSigning, WithoutAKeyNothingIsSignedOrChecked) {
  palcas_msgs::AdvisoryArray a = someAdvisories();
  signMessage(a, nullptr);
  EXPECT_TRUE(a.auth_tag.empty());
  EXPECT_EQ(verifyMessage(a, nullptr), Verdict::kAuthentic);
  EXPECT_EQ(verifyMessage(a, &kKey), Verdict::kMissing);
  EXPECT_EQ(loadMessageKey(""), nullptr);
  EXPECT_THROW(loadMessageKey("/nonexistent/palcas.key"), std::runtime_error);
}

TEST(MessageSigning, ModelWeightsAreSignedOverTheirValues) {
  palcas_msgs::ModelWeights w;
  w.rsu_id = "rsu_2";
  w.round = 3;
  w.sample_count = 600;
  w.values = {0.5f, -0.25f, 1e-3f};
  signMessage(w, &kKey);
  EXPECT_EQ(verifyMessage(w, &kKey), Verdict::kAuthentic);
  w.values[1] = 1e30f;  // a poisoned weight after signing
  EXPECT_EQ(verifyMessage(w, &kKey), Verdict::kForged);
}

}  // namespace
}  // namespace palcas::common
