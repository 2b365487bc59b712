#include "palcas_core/learning/nn/serialization.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "palcas_core/common/atomic_file.h"
#include "palcas_core/learning/nn/network.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the model format is little-endian");

namespace palcas::nn {

uint64_t fnv1a64(const void* data, size_t size, uint64_t hash) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  // h = (h XOR byte) * 1099511628211, per byte (FNV-1a).
  for (size_t i = 0; i < size; ++i) hash = (hash ^ bytes[i]) * 1099511628211ULL;
  return hash;
}

void ByteWriter::raw(const void* data, size_t size) {
  bytes_.append(static_cast<const char*>(data), size);
}

void ByteWriter::str(const std::string& text) {
  u64(text.size());
  raw(text.data(), text.size());
}

void ByteWriter::floats(const Scalar* values, size_t count) {
  u64(count);
  raw(values, count * sizeof(Scalar));
}

ByteReader::ByteReader(const std::string& bytes, std::string what)
    : bytes_(bytes), what_(std::move(what)) {}

void ByteReader::need(size_t size, const char* item) const {
  if (size > remaining())
    throw std::runtime_error(what_ + " is truncated: " + item + " needs " + std::to_string(size) +
                             " bytes at offset " + std::to_string(offset_) + ", only " +
                             std::to_string(remaining()) + " left");
}

void ByteReader::raw(void* out, size_t size) {
  need(size, "a field");
  std::memcpy(out, bytes_.data() + offset_, size);
  offset_ += size;
}

uint32_t ByteReader::u32() {
  uint32_t v;
  raw(&v, sizeof v);
  return v;
}

uint64_t ByteReader::u64() {
  uint64_t v;
  raw(&v, sizeof v);
  return v;
}

double ByteReader::f64() {
  double v;
  raw(&v, sizeof v);
  return v;
}

std::string ByteReader::str() {
  const uint64_t size = u64();
  need(size, "a string");
  std::string text = bytes_.substr(offset_, size);
  offset_ += size;
  return text;
}

std::vector<Scalar> ByteReader::floats() {
  const uint64_t count = u64();
  if (count > remaining() / sizeof(Scalar))
    throw std::runtime_error(what_ + " is truncated: a float array of " + std::to_string(count) +
                             " values at offset " + std::to_string(offset_) + ", only " +
                             std::to_string(remaining()) + " bytes left");
  std::vector<Scalar> values(count);
  raw(values.data(), count * sizeof(Scalar));
  return values;
}

void writeModelFile(const std::string& path, const FileContents& contents) {
  ByteWriter w;
  w.raw(FILE_MAGIC, sizeof FILE_MAGIC);
  w.u32(FILE_FORMAT_VERSION);
  w.u32(static_cast<uint32_t>(contents.kind));
  w.str(contents.layout);
  w.u64(contents.layout_checksum);
  w.floats(contents.values.data(), contents.values.size());
  w.str(contents.extra);
  w.u64(fnv1a64(w.bytes().data(), w.bytes().size()));
  writeFileAtomically(path, w.bytes());
}

FileContents readModelFile(const std::string& path, FileKind expected_kind) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open model file " + path);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < sizeof FILE_MAGIC || std::memcmp(bytes.data(), FILE_MAGIC, 8) != 0)
    throw std::runtime_error(path + " is not a PALCAS model file (bad magic bytes)");
  ByteReader r(bytes, path);
  char magic[8];
  r.raw(magic, sizeof magic);
  const uint32_t version = r.u32();
  if (version != FILE_FORMAT_VERSION)
    throw std::runtime_error(path + " has format version " + std::to_string(version) +
                             ", this build reads version " + std::to_string(FILE_FORMAT_VERSION));
  FileContents c;
  const uint32_t kind = r.u32();
  if (kind != static_cast<uint32_t>(expected_kind))
    throw std::runtime_error(path + " holds file kind " + std::to_string(kind) + ", expected " +
                             std::to_string(static_cast<uint32_t>(expected_kind)) +
                             " (1 = model, 2 = agent checkpoint)");
  c.kind = expected_kind;
  c.layout = r.str();
  c.layout_checksum = r.u64();
  c.values = r.floats();
  c.extra = r.str();
  const size_t body = r.offset();
  const uint64_t stored = r.u64();
  if (r.remaining() != 0)
    throw std::runtime_error(path + " has " + std::to_string(r.remaining()) +
                             " unexpected bytes after the checksum");
  if (stored != fnv1a64(bytes.data(), body))
    throw std::runtime_error(path + " has a bad checksum (file corrupted)");
  if (c.layout_checksum != fnv1a64(c.layout))
    throw std::runtime_error(path + ": layout checksum does not match its layout string");
  return c;
}

void saveNetwork(const Network& network, const std::string& path) {
  FileContents c;
  c.layout = network.layout();
  c.layout_checksum = network.layoutChecksum();
  const Vector state = network.getState();
  c.values.assign(state.data(), state.data() + state.size());
  writeModelFile(path, c);
}

void loadNetwork(Network& network, const std::string& path) {
  const FileContents c = readModelFile(path, FileKind::kModel);
  if (c.layout != network.layout())
    throw std::runtime_error(path + " holds layout '" + c.layout + "', the network is '" +
                             network.layout() + "'");
  try {
    network.setState(c.values.data(), static_cast<Index>(c.values.size()));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace palcas::nn
