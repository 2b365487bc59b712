#include "palcas_core/common/message_auth.h"

#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <openssl/sha.h>
#include <sys/stat.h>

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace palcas::auth {
namespace {

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

const char* verdictName(Verdict v) {
  switch (v) {
    case Verdict::kAuthentic: return "authentic";
    case Verdict::kMissing: return "missing_tag";
    case Verdict::kBadLength: return "bad_tag_length";
    case Verdict::kForged: return "forged_tag";
  }
  return "unknown";
}

std::string toHex(const std::uint8_t* data, std::size_t size) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  out.reserve(2 * size);
  for (std::size_t i = 0; i < size; ++i) {
    out.push_back(digits[data[i] >> 4]);
    out.push_back(digits[data[i] & 0xf]);
  }
  return out;
}

MessageKey MessageKey::fromBytes(std::vector<std::uint8_t> bytes) {
  if (bytes.size() < MIN_KEY_BYTES || bytes.size() > MAX_KEY_BYTES)
    throw std::invalid_argument("message key of " + std::to_string(bytes.size()) +
                                " bytes: expected " + std::to_string(MIN_KEY_BYTES) + " to " +
                                std::to_string(MAX_KEY_BYTES));
  return MessageKey(std::move(bytes));
}

MessageKey MessageKey::fromFile(const std::string& path) {
  auto fail = [&path](const std::string& what) {
    return std::runtime_error("message key file '" + path + "': " + what);
  };
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw fail("does not exist or cannot be read");
  if (!S_ISREG(st.st_mode)) throw fail("is not a regular file");
  // A key others can read is no secret; one others can write is no one's key.
  if (st.st_mode & (S_IRWXG | S_IRWXO)) {
    std::ostringstream mode;
    mode << std::oct << (st.st_mode & 0777);
    throw fail("mode " + mode.str() + " lets group or others access it (chmod 600 it)");
  }
  if (st.st_size > static_cast<off_t>(4 * MAX_KEY_BYTES)) throw fail("too large to be a key");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw fail("cannot be opened");
  std::stringstream text;
  text << in.rdbuf();
  std::string hex = text.str();
  const auto first = hex.find_first_not_of(" \t\r\n");
  const auto last = hex.find_last_not_of(" \t\r\n");
  hex = first == std::string::npos ? std::string() : hex.substr(first, last - first + 1);
  if (hex.empty()) throw fail("is empty");
  for (std::size_t i = 0; i < hex.size(); ++i)
    if (hexDigit(hex[i]) < 0)
      throw fail("character " + std::to_string(i + 1) + " is not a hexadecimal digit: not a key file of ours");
  if (hex.size() % 2 != 0)
    throw fail("holds " + std::to_string(hex.size()) + " hex digits, an odd count");
  std::vector<std::uint8_t> bytes(hex.size() / 2);
  for (std::size_t i = 0; i < bytes.size(); ++i)
    bytes[i] = static_cast<std::uint8_t>(16 * hexDigit(hex[2 * i]) + hexDigit(hex[2 * i + 1]));
  if (bytes.size() < MIN_KEY_BYTES || bytes.size() > MAX_KEY_BYTES)
    throw fail("holds a key of " + std::to_string(bytes.size()) + " bytes; expected " +
               std::to_string(MIN_KEY_BYTES) + " to " + std::to_string(MAX_KEY_BYTES) +
               " (at least " + std::to_string(2 * MIN_KEY_BYTES) + " hex digits)");
  return MessageKey(std::move(bytes));
}

Tag MessageKey::sign(const std::uint8_t* data, std::size_t size) const {
  Tag tag{};
  unsigned int length = 0;
  static const std::uint8_t kEmpty = 0;  // HMAC() wants a valid pointer for empty input
  if (HMAC(EVP_sha256(), bytes_.data(), static_cast<int>(bytes_.size()),
           size == 0 ? &kEmpty : data, size, tag.data(), &length) == nullptr ||
      length != TAG_BYTES)
    throw std::runtime_error("HMAC-SHA256 failed in OpenSSL");
  return tag;
}

Verdict MessageKey::verify(const std::uint8_t* data, std::size_t size, const std::uint8_t* tag,
                           std::size_t tag_size) const {
  if (tag_size == 0) return Verdict::kMissing;
  if (tag_size != TAG_BYTES) return Verdict::kBadLength;
  const Tag expected = sign(data, size);
  std::uint8_t difference = 0;
  for (std::size_t i = 0; i < TAG_BYTES; ++i) difference |= expected[i] ^ tag[i];
  return difference == 0 ? Verdict::kAuthentic : Verdict::kForged;
}

std::string MessageKey::fingerprint() const {
  std::uint8_t digest[SHA256_DIGEST_LENGTH];
  SHA256(bytes_.data(), bytes_.size(), digest);
  return toHex(digest, 4);
}

}  // namespace palcas::auth
