#include "federation_json.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace palcas::json {

namespace {

// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
std::string reason(const nlohmann::json::exception& e) {
  const std::string text = e.what();
  const auto end = text.rfind("] ", text.find(' '));
  return text.front() == '[' && end != std::string::npos ? text.substr(end + 2) : text;
}

}  // namespace

Value parse(const std::string& text, const std::string& what) {
  try {
    return Value::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw std::runtime_error(what + ": not valid JSON at byte " + std::to_string(e.byte) + ": " +
                             reason(e));
  } catch (const nlohmann::json::exception& e) {  // out_of_range.406: a number beyond a double
    throw std::runtime_error(what + ": not valid JSON: " + reason(e));
  }
}

const Value& at(const Value& object, const std::string& key, const std::string& what) {
  if (!object.is_object())
    throw std::runtime_error(what + ": not a JSON object, got " + shown(object));
  const auto it = object.find(key);
  if (it == object.end()) throw std::runtime_error(what + ": missing key '" + key + "'");
  return *it;
}

uint64_t asUint(const Value& value, const std::string& what) {
  // nlohmann reads digits without sign, fraction or exponent that fit in 64 bits as unsigned;
  // anything else (negative, 3.0, 1e3, beyond 2^64, a string) is another type.
  if (!value.is_number_unsigned())
    throw std::runtime_error(what + " must be an unsigned integer, got " + shown(value));
  return value.get<uint64_t>();
}

double asDouble(const Value& value, const std::string& what) {
  const double v = value.is_number() ? value.get<double>() : NAN;
  if (!std::isfinite(v))
    throw std::runtime_error(what + " must be a finite number, got " + shown(value));
  return v;
}

const std::string& asString(const Value& value, const std::string& what) {
  if (!value.is_string()) throw std::runtime_error(what + " must be a string, got " + shown(value));
  return value.get_ref<const std::string&>();
}

std::string shown(const Value& value) {
  if (value.is_primitive())
    return "'" + value.dump(-1, ' ', false, Value::error_handler_t::replace) + "'";
  return std::string("a JSON ") + value.type_name();
}

std::string quote(const std::string& text) {
  return Value(text).dump(-1, ' ', false, Value::error_handler_t::replace);
}

std::string number(double value) {
  if (!std::isfinite(value)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

}  // namespace palcas::json
