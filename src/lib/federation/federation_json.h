#pragma once
// JSON for the federation server's state file and status line (private to the core's
// federation folder; nlohmann-json is header-only, so nothing of it reaches the installed
// headers). nlohmann reads and escapes; these helpers add what the server's refusals need:
// every failure names the file and the key, and reading a value never changes anything held.

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace palcas::json {

using Value = nlohmann::json;

/// Parses one JSON document (surrounding whitespace allowed). Throws std::runtime_error
/// "<what>: not valid JSON at byte N: ..." on any syntax error or a number no double holds.
Value parse(const std::string& text, const std::string& what);

/// Member `key` of `object`; throws std::runtime_error "<what>: missing key 'key'" (or
/// "<what>: not a JSON object").
const Value& at(const Value& object, const std::string& key, const std::string& what);
/// `value` as an unsigned integer (a JSON number without sign, fraction or exponent that fits
/// in 64 bits), or throws std::runtime_error "<what> must be an unsigned integer, got ...".
uint64_t asUint(const Value& value, const std::string& what);
/// `value` as a finite double (any JSON number), or throws std::runtime_error naming `what`.
double asDouble(const Value& value, const std::string& what);
/// `value` as a string, or throws std::runtime_error naming `what`.
const std::string& asString(const Value& value, const std::string& what);
/// `value` for an error message: a scalar as its JSON text, an array or object by its type
/// (a hostile file's deep nesting is never printed).
std::string shown(const Value& value);

/// `text` as a quoted JSON string: ", \ and control characters escaped, bytes that are not
/// UTF-8 replaced by U+FFFD (an RSU id comes from the network).
std::string quote(const std::string& text);

/// A double in JSON: %.17g (round-trips exactly; the files written so far use it);
/// non-finite -> null.
std::string number(double value);

}  // namespace palcas::json
