#pragma once
// Message authentication between the suite's nodes: only the RSUs speak for the RSUs.
// Advisory arrays and model submissions carry an HMAC-SHA256 tag over the message's bytes,
// computed with a per-deployment key that every node of one deployment reads from the same
// file. A message without the right tag is refused by its receiver and counted; a forged
// array can then never displace a genuine one. ROS-free: callers pass the bytes to sign
// (the node shells serialise the ROS message with its tag field empty).
//
// Key file: hexadecimal text, at least 32 hex digits (16 bytes; 64 recommended), surrounding
// whitespace ignored, readable by its owner only (like an ssh key). `./palcas run|train`
// make one per run folder; `openssl rand -hex 32 > key && chmod 600 key` makes one by hand.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace palcas::auth {

constexpr std::size_t TAG_BYTES = 32;        ///< HMAC-SHA256 output
constexpr std::size_t MIN_KEY_BYTES = 16;    ///< shorter keys are refused
constexpr std::size_t MAX_KEY_BYTES = 1024;  ///< a longer file is not a key of ours
using Tag = std::array<std::uint8_t, TAG_BYTES>;

/// Outcome of checking one message's tag.
enum class Verdict {
  kAuthentic,  ///< the tag is the HMAC of the bytes under this key
  kMissing,    ///< the message carries no tag (an unauthenticated sender)
  kBadLength,  ///< a tag of another length than TAG_BYTES
  kForged,     ///< a tag of the right length that does not match
};
/// "authentic", "missing_tag", "bad_tag_length", "forged_tag".
const char* verdictName(Verdict v);

/// One deployment's shared secret.
class MessageKey {
 public:
  /// Reads a key file (format above). Throws std::runtime_error naming the path and what is
  /// wrong: missing or unreadable, readable or writable by group or others, not hexadecimal,
  /// an odd digit count, shorter than MIN_KEY_BYTES or longer than MAX_KEY_BYTES.
  static MessageKey fromFile(const std::string& path);
  /// From raw bytes; throws std::invalid_argument if fewer than MIN_KEY_BYTES or more than
  /// MAX_KEY_BYTES.
  static MessageKey fromBytes(std::vector<std::uint8_t> bytes);

  /// HMAC-SHA256 of the bytes under this key.
  Tag sign(const std::uint8_t* data, std::size_t size) const;
  /// Compares in constant time (no early exit on the first differing byte).
  Verdict verify(const std::uint8_t* data, std::size_t size, const std::uint8_t* tag,
                 std::size_t tag_size) const;
  /// First 8 hex digits of SHA-256 of the key: names the key in logs without revealing it,
  /// so an operator can see that two nodes hold the same one.
  std::string fingerprint() const;

 private:
  explicit MessageKey(std::vector<std::uint8_t> bytes) : bytes_(std::move(bytes)) {}
  std::vector<std::uint8_t> bytes_;
};

/// Lower-case hex of bytes (for logs and tests).
std::string toHex(const std::uint8_t* data, std::size_t size);

}  // namespace palcas::auth
