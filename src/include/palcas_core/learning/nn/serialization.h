#pragma once
// The versioned binary file format of PALCAS models and agent checkpoints (ours only),
// and the byte-level writer/reader it is built from. Byte layout: src/doc/learning.md.
//
//   "PALCASNN" | u32 version | u32 kind | u64 n + layout bytes | u64 layout checksum |
//   u64 count + f32 values | u64 n + extra bytes | u64 FNV-1a 64 of everything before
//
// Little-endian (the only byte order this code is built for; a static_assert checks).

#include <cstdint>
#include <string>
#include <vector>

#include "palcas_core/learning/nn/types.h"

namespace palcas::nn {

class Network;

constexpr char FILE_MAGIC[8] = {'P', 'A', 'L', 'C', 'A', 'S', 'N', 'N'};
constexpr uint32_t FILE_FORMAT_VERSION = 1;

/// FNV-1a 64-bit hash of bytes (offset basis 14695981039346656037, prime 1099511628211).
uint64_t fnv1a64(const void* data, size_t size, uint64_t hash = 14695981039346656037ULL);
inline uint64_t fnv1a64(const std::string& text) { return fnv1a64(text.data(), text.size()); }

/// Appends little-endian values to a byte string.
class ByteWriter {
 public:
  void u32(uint32_t value) { raw(&value, sizeof value); }
  void u64(uint64_t value) { raw(&value, sizeof value); }
  void f64(double value) { raw(&value, sizeof value); }
  /// Length-prefixed (u64) bytes.
  void str(const std::string& text);
  /// Count-prefixed (u64) float32 array.
  void floats(const Scalar* values, size_t count);
  void raw(const void* data, size_t size);
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

/// Reads what ByteWriter wrote; every read checks the remaining size first and throws
/// std::runtime_error "<what> is truncated ..." instead of reading past the end.
class ByteReader {
 public:
  /// `what` names the source in error messages (e.g. the file path).
  ByteReader(const std::string& bytes, std::string what);
  uint32_t u32();
  uint64_t u64();
  double f64();
  std::string str();
  std::vector<Scalar> floats();
  void raw(void* out, size_t size);
  size_t offset() const { return offset_; }
  size_t remaining() const { return bytes_.size() - offset_; }

 private:
  void need(size_t size, const char* item) const;
  const std::string& bytes_;
  std::string what_;
  size_t offset_ = 0;
};

/// What a file holds: a model (network or ModelBlob) or a whole agent checkpoint.
enum class FileKind : uint32_t { kModel = 1, kAgentCheckpoint = 2 };

struct FileContents {
  FileKind kind = FileKind::kModel;
  std::string layout;            ///< layout description string
  uint64_t layout_checksum = 0;  ///< fnv1a64(layout)
  std::vector<Scalar> values;    ///< model values (parameters + state)
  std::string extra;             ///< kind-specific extra bytes (checkpoint state)
};

/// Writes atomically: to "<path>.tmp" then rename(2), so readers never see half a file.
/// Throws std::runtime_error naming the path if writing or renaming fails.
void writeModelFile(const std::string& path, const FileContents& contents);
/// Reads and fully verifies a file: magic ("not a PALCAS model file"), version, kind,
/// truncation, layout checksum vs layout string, trailing FNV-1a checksum. Throws
/// std::runtime_error saying which check failed.
FileContents readModelFile(const std::string& path, FileKind expected_kind);

/// Saves a network's layout and getState() values.
void saveNetwork(const Network& network, const std::string& path);
/// Loads into `network`; throws std::runtime_error (network untouched) if the file fails
/// a check or its layout differs (both layouts named in the message).
void loadNetwork(Network& network, const std::string& path);

}  // namespace palcas::nn
