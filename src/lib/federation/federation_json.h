#pragma once
// Minimal JSON for the federation server's state file and status line (private to the
// core: no JSON dependency for one small flat file). Reads standard JSON; numbers keep
// their text so 64-bit counters round-trip exactly.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace palcas::json {

struct Value {
  enum class Type { kNull, kBool, kNumber, kString, kArray, kObject };
  Type type = Type::kNull;
  bool boolean = false;
  std::string text;                                     ///< number text or string value
  std::vector<Value> items;                             ///< array elements
  std::vector<std::pair<std::string, Value>> members;   ///< object members, in file order

  /// Member `key` of an object; throws std::runtime_error "<what>: missing key 'key'"
  /// (or "not an object").
  const Value& at(const std::string& key, const std::string& what) const;
  /// This number as an unsigned integer (digits only, fits in 64 bits), or throws
  /// std::runtime_error naming `what`.
  uint64_t asUint(const std::string& what) const;
  /// This number as a finite double, or throws std::runtime_error naming `what`.
  double asDouble(const std::string& what) const;
  /// This string, or throws std::runtime_error naming `what`.
  const std::string& asString(const std::string& what) const;
};

/// Parses one JSON document (trailing whitespace allowed). Throws std::runtime_error
/// "<what>: not valid JSON at byte N: ..." on any syntax error.
Value parse(const std::string& text, const std::string& what);

/// `text` as a quoted JSON string, with ", \ and control characters escaped.
std::string quote(const std::string& text);

/// A double in JSON: shortest round-tripping form (%.17g); non-finite -> null.
std::string number(double value);

}  // namespace palcas::json
