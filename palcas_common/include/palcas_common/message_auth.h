#pragma once
// Signing and checking ROS messages that carry an `auth_tag` field (AdvisoryArray,
// ModelWeights). The tag is palcas::auth's HMAC-SHA256 over the message's ROS serialisation
// with auth_tag empty (and header.seq 0: rospy rewrites it on publish), so any field changed after signing (rsu_id, step, an advisory, a
// weight) breaks it. The serialisation is ROS's wire format: rospy computes the same bytes
// (test/nodes/forged_messages_test.py signs from Python).

#include <palcas_core/common/message_auth.h>
#include <ros/serialization.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace palcas::common {

namespace detail {
// header.seq is not covered: rospy overwrites it on publish (after the sender signed).
template <class Message>
auto clearTransportFields(Message& msg, int) -> decltype(msg.header.seq = 0, void()) {
  msg.header.seq = 0;
}
template <class Message>
void clearTransportFields(Message&, long) {}
}  // namespace detail

/// The bytes a tag covers: msg serialised with auth_tag cleared and, for messages with a
/// header, header.seq zeroed (msg is a copy).
template <class Message>
std::vector<std::uint8_t> bytesToSign(Message msg) {
  msg.auth_tag.clear();
  detail::clearTransportFields(msg, 0);
  const std::uint32_t size = ros::serialization::serializationLength(msg);
  std::vector<std::uint8_t> bytes(size);
  ros::serialization::OStream stream(bytes.data(), size);
  ros::serialization::serialize(stream, msg);
  return bytes;
}

/// Sets msg.auth_tag; without a key (authentication off) leaves it empty.
template <class Message>
void signMessage(Message& msg, const auth::MessageKey* key) {
  msg.auth_tag.clear();
  if (key == nullptr) return;
  const std::vector<std::uint8_t> bytes = bytesToSign(msg);
  const auth::Tag tag = key->sign(bytes.data(), bytes.size());
  msg.auth_tag.assign(tag.begin(), tag.end());
}

/// kAuthentic when no key is set (authentication off) or the tag matches.
template <class Message>
auth::Verdict verifyMessage(const Message& msg, const auth::MessageKey* key) {
  if (key == nullptr) return auth::Verdict::kAuthentic;
  if (msg.auth_tag.empty()) return auth::Verdict::kMissing;  // no need to serialise
  const std::vector<std::uint8_t> bytes = bytesToSign(msg);
  return key->verify(bytes.data(), bytes.size(), msg.auth_tag.data(), msg.auth_tag.size());
}

/// The key named by a node's ~auth_key_file parameter: null for "" (authentication off).
/// Throws std::runtime_error naming the file if it cannot be used (MessageKey::fromFile).
inline std::unique_ptr<auth::MessageKey> loadMessageKey(const std::string& path) {
  if (path.empty()) return nullptr;
  return std::make_unique<auth::MessageKey>(auth::MessageKey::fromFile(path));
}

}  // namespace palcas::common
