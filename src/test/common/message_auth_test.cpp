// HMAC tags and key files of palcas::auth: RFC 4231 vectors, tampering, and every way a key
// file can be wrong.
#include "palcas_core/common/message_auth.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

namespace palcas::auth {
namespace {

std::vector<std::uint8_t> bytesOf(const std::string& s) { return {s.begin(), s.end()}; }

std::string hexTag(const Tag& t) { return toHex(t.data(), t.size()); }

class KeyFile : public ::testing::Test {
 protected:
  std::string path_ = ::testing::TempDir() + "palcas_key_" +
                      std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
                      ::testing::UnitTest::GetInstance()->current_test_info()->name();
  void write(const std::string& text, mode_t mode = 0600) {
    std::remove(path_.c_str());
    std::ofstream(path_, std::ios::binary) << text;
    ASSERT_EQ(::chmod(path_.c_str(), mode), 0);
  }
  void TearDown() override { std::remove(path_.c_str()); }
  std::string errorOf() {
    try {
      MessageKey::fromFile(path_);
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }
};

TEST(MessageAuth, MatchesRfc4231TestVectors) {
  // RFC 4231 test cases 1 and 3 (HMAC-SHA-256).
  const MessageKey key1 = MessageKey::fromBytes(std::vector<std::uint8_t>(20, 0x0b));
  const auto data1 = bytesOf("Hi There");
  EXPECT_EQ(hexTag(key1.sign(data1.data(), data1.size())),
            "b0344c61d8db38535ca8afceaf0bf12b881dc200c9833da726e9376c2e32cff7");
  const MessageKey key3 = MessageKey::fromBytes(std::vector<std::uint8_t>(20, 0xaa));
  const std::vector<std::uint8_t> data3(50, 0xdd);
  EXPECT_EQ(hexTag(key3.sign(data3.data(), data3.size())),
            "773ea91e36800e46854db8ebd09181a72959098b3ef8c122d9635514ced565fe");
  // Empty input (Python's hmac gives the same) and the fingerprint (SHA-256 prefix of the key).
  EXPECT_EQ(hexTag(key1.sign(nullptr, 0)),
            "999a901219f032cd497cadb5e6051e97b6a29ab297bd6ae722bd6062a2f59542");
  EXPECT_EQ(key1.fingerprint(), "6ff22768");
}

TEST(MessageAuth, VerifiesOnlyTheSignedBytesUnderTheSameKey) {
  const MessageKey key = MessageKey::fromBytes(std::vector<std::uint8_t>(32, 7));
  const MessageKey other = MessageKey::fromBytes(std::vector<std::uint8_t>(32, 8));
  auto data = bytesOf("rsu_0 step 42: LANE_LEFT veh_7");
  const Tag tag = key.sign(data.data(), data.size());
  EXPECT_EQ(key.verify(data.data(), data.size(), tag.data(), tag.size()), Verdict::kAuthentic);
  EXPECT_EQ(other.verify(data.data(), data.size(), tag.data(), tag.size()), Verdict::kForged);
  Tag flipped = tag;
  flipped[31] ^= 1;
  EXPECT_EQ(key.verify(data.data(), data.size(), flipped.data(), flipped.size()), Verdict::kForged);
  data[0] = 'R';  // the message changed after signing
  EXPECT_EQ(key.verify(data.data(), data.size(), tag.data(), tag.size()), Verdict::kForged);
  EXPECT_EQ(key.verify(data.data(), data.size(), nullptr, 0), Verdict::kMissing);
  EXPECT_EQ(key.verify(data.data(), data.size(), tag.data(), 16), Verdict::kBadLength);
  EXPECT_STREQ(verdictName(Verdict::kForged), "forged_tag");
  EXPECT_STREQ(verdictName(Verdict::kMissing), "missing_tag");
}

TEST(MessageAuth, RefusesShortAndOversizedKeys) {
  EXPECT_THROW(MessageKey::fromBytes(std::vector<std::uint8_t>(MIN_KEY_BYTES - 1, 1)),
               std::invalid_argument);
  EXPECT_THROW(MessageKey::fromBytes(std::vector<std::uint8_t>(MAX_KEY_BYTES + 1, 1)),
               std::invalid_argument);
  EXPECT_NO_THROW(MessageKey::fromBytes(std::vector<std::uint8_t>(MIN_KEY_BYTES, 1)));
}

TEST_F(KeyFile, ReadsHexWithSurroundingWhitespace) {
  write("  0b0b0b0b0b0b0b0b0b0b0b0b0b0b0b0b0b0b0b0B\n");
  const MessageKey key = MessageKey::fromFile(path_);
  EXPECT_EQ(key.fingerprint(), "6ff22768");  // the 20 bytes 0x0b of RFC 4231 case 1
}

TEST_F(KeyFile, NamesWhatIsWrongWithTheFile) {
  const std::string good(64, 'a');
  write(good, 0644);
  EXPECT_NE(errorOf().find("mode 644 lets group or others access it"), std::string::npos) << errorOf();
  write(good, 0660);
  EXPECT_NE(errorOf().find("mode 660"), std::string::npos) << errorOf();
  write("");
  EXPECT_NE(errorOf().find("is empty"), std::string::npos) << errorOf();
  write("\x89PNG\r\n\x1a\n not a key");
  EXPECT_NE(errorOf().find("character 1 is not a hexadecimal digit: not a key file of ours"),
            std::string::npos) << errorOf();
  write(std::string(33, 'a'));
  EXPECT_NE(errorOf().find("33 hex digits, an odd count"), std::string::npos) << errorOf();
  write(std::string(30, 'a'));
  EXPECT_NE(errorOf().find("a key of 15 bytes"), std::string::npos) << errorOf();
  std::remove(path_.c_str());
  EXPECT_NE(errorOf().find("does not exist"), std::string::npos) << errorOf();
  EXPECT_NE(errorOf().find(path_), std::string::npos) << "the error names the file";
}

TEST_F(KeyFile, TwoNodesReadingOneFileAgree) {
  write("00112233445566778899aabbccddeeff00112233445566778899aabbccddeeff");
  const MessageKey rsu = MessageKey::fromFile(path_);
  const MessageKey bridge = MessageKey::fromFile(path_);
  const auto data = bytesOf("advisories");
  const Tag tag = rsu.sign(data.data(), data.size());
  EXPECT_EQ(bridge.verify(data.data(), data.size(), tag.data(), tag.size()), Verdict::kAuthentic);
}

}  // namespace
}  // namespace palcas::auth
