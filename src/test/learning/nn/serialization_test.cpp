#include "palcas_core/learning/nn/serialization.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cstdio>
#include <fstream>
#include <iterator>

#include "nn_test_util.h"
#include "palcas_core/learning/model_blob.h"
#include "palcas_core/learning/nn/network.h"

using namespace palcas;
using namespace palcas::nn;

namespace {

std::string tempPath(const std::string& name) { return ::testing::TempDir() + "palcas_ser_" + name; }

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

Network smallNet(uint64_t seed, Index hidden = 3) {
  Rng rng(seed);
  MlpSpec spec;
  spec.input_size = 2;
  spec.hidden_sizes = {hidden};
  spec.output_size = 1;
  return makeMlp(spec, rng);
}

// Expects loadNetwork to throw a runtime_error whose message contains `needle`, and the
// network to keep its state.
void expectRefused(const std::string& path, const std::string& needle) {
  Network target = smallNet(99);
  const Vector before = target.getState();
  palcas_test::expectThrowNaming<std::runtime_error>([&] { loadNetwork(target, path); },
                                                        needle);
  EXPECT_EQ(target.getState(), before);
}

}  // namespace

TEST(Serialization, Fnv1a64KnownVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);   // the offset basis
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);  // published FNV-1a 64 test vector
}

TEST(Serialization, HeaderLayoutIsAsDocumented) {
  const std::string path = tempPath("header.model");
  Network net = smallNet(1);
  saveNetwork(net, path);
  const std::string bytes = readBytes(path);
  const std::string layout = net.layout();
  // magic 8 + version 4 + kind 4 + (8 + layout) + checksum 8 + (8 + 4 n) + (8 + 0) + 8
  const size_t n = static_cast<size_t>(net.stateCount());
  EXPECT_EQ(bytes.size(), 8 + 4 + 4 + 8 + layout.size() + 8 + 8 + 4 * n + 8 + 8);
  EXPECT_EQ(bytes.substr(0, 8), "PALCASNN");
  EXPECT_EQ(bytes[8], 1);   // version 1, little-endian
  EXPECT_EQ(bytes[12], 1);  // kind 1 = model
  EXPECT_EQ(bytes.substr(24, layout.size()), layout);
  std::remove(path.c_str());
}

TEST(Serialization, RoundTripAndNoTemporaryLeft) {
  const std::string path = tempPath("roundtrip.model");
  Network a = smallNet(2), b = smallNet(3);
  Rng rng(4);
  test::expectSaveLoadRoundTrip(a, b, test::randomMatrix(2, 3, rng));
  saveNetwork(a, path);
  EXPECT_FALSE(std::ifstream(path + ".tmp").good());
  std::remove(path.c_str());
}

TEST(Serialization, RefusesFilesThatAreNotOurs) {
  const std::string path = tempPath("foreign.model");
  writeBytes(path, "GIF89a this is a picture, not a model");
  expectRefused(path, "not a PALCAS model file");
  expectRefused(tempPath("missing.model"), "cannot open");
  std::remove(path.c_str());
}

TEST(Serialization, RefusesAnotherVersion) {
  const std::string path = tempPath("version.model");
  saveNetwork(smallNet(5), path);
  std::string bytes = readBytes(path);
  bytes[8] = 2;  // version field
  writeBytes(path, bytes);
  expectRefused(path, "format version 2");
  std::remove(path.c_str());
}

TEST(Serialization, RefusesAnotherLayoutNamingBoth) {
  const std::string path = tempPath("layout.model");
  saveNetwork(smallNet(6, 5), path);  // hidden 5 instead of 3
  expectRefused(path, "Linear(2,5)");
  expectRefused(path, "Linear(2,3)");
  std::remove(path.c_str());
}

TEST(Serialization, RefusesTruncatedFiles) {
  const std::string path = tempPath("truncated.model");
  saveNetwork(smallNet(7), path);
  const std::string bytes = readBytes(path);
  for (size_t cut : {size_t{10}, size_t{30}, bytes.size() / 2, bytes.size() - 1}) {
    writeBytes(path, bytes.substr(0, cut));
    expectRefused(path, "truncated");
  }
  std::remove(path.c_str());
}

TEST(Serialization, RefusesABadChecksum) {
  const std::string path = tempPath("checksum.model");
  saveNetwork(smallNet(8), path);
  std::string bytes = readBytes(path);
  bytes[bytes.size() - 20] ^= 0x01;  // one bit of the float payload
  writeBytes(path, bytes);
  expectRefused(path, "bad checksum");
  std::remove(path.c_str());
}

TEST(Serialization, RefusesAnotherFileKind) {
  const std::string path = tempPath("kind.model");
  FileContents c;
  c.kind = FileKind::kAgentCheckpoint;
  c.layout = "x";
  c.layout_checksum = fnv1a64("x");
  writeModelFile(path, c);
  expectRefused(path, "file kind 2");
  std::remove(path.c_str());
}

TEST(Serialization, RefusesAWriteIntoAMissingDirectory) {
  EXPECT_THROW(saveNetwork(smallNet(9), "/nonexistent_dir_palcas/x.model"), std::runtime_error);
}

TEST(ModelBlob, SaveLoadRoundTripAndValidation) {
  const std::string path = tempPath("blob.model");
  ModelBlob blob{"layout-x", fnv1a64("layout-x"), {1.0f, -2.5f, 3.25f}};
  saveModelBlob(blob, path);
  const ModelBlob loaded = loadModelBlob(path);
  EXPECT_EQ(loaded.layout_id, blob.layout_id);
  EXPECT_EQ(loaded.layout_checksum, blob.layout_checksum);
  EXPECT_EQ(loaded.values, blob.values);
  std::remove(path.c_str());
  ModelBlob bad = blob;
  bad.layout_checksum += 1;
  EXPECT_THROW(validateModelBlob(bad), std::invalid_argument);
  bad = blob;
  bad.values[1] = std::numeric_limits<float>::infinity();
  try {
    validateModelBlob(bad);
    ADD_FAILURE() << "accepted an infinite value";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("value 1"), std::string::npos) << e.what();
  }
}
