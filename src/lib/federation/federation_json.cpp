#include "federation_json.h"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace palcas::json {

namespace {

/// Recursive-descent reader over the whole text; depth-limited so a hostile file cannot
/// exhaust the stack.
class Parser {
 public:
  Parser(const std::string& text, const std::string& what) : s_(text), what_(what) {}

  Value document() {
    Value v = value(0);
    skipSpace();
    if (pos_ != s_.size()) fail("unexpected text after the document");
    return v;
  }

 private:
  static constexpr int MAX_DEPTH = 32;

  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(what_ + ": not valid JSON at byte " + std::to_string(pos_) + ": " + why);
  }
  void skipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool consume(char c) {
    skipSpace();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  void expect(char c) {
    if (!consume(c)) fail(std::string("expected '") + c + "'");
  }
  bool literal(const char* word) {
    const std::string w(word);
    if (s_.compare(pos_, w.size(), w) != 0) return false;
    pos_ += w.size();
    return true;
  }

  Value value(int depth) {
    if (depth > MAX_DEPTH) fail("nested too deeply");
    skipSpace();
    if (pos_ >= s_.size()) fail("unexpected end");
    Value v;
    const char c = s_[pos_];
    if (c == '{') return object(depth);
    if (c == '[') return array(depth);
    if (c == '"') {
      v.type = Value::Type::kString;
      v.text = string();
    } else if (literal("true")) {
      v.type = Value::Type::kBool;
      v.boolean = true;
    } else if (literal("false")) {
      v.type = Value::Type::kBool;
    } else if (literal("null")) {
      v.type = Value::Type::kNull;
    } else if (c == '-' || std::isdigit(static_cast<unsigned char>(c))) {
      v.type = Value::Type::kNumber;
      const size_t start = pos_;
      while (pos_ < s_.size() && std::strchr("+-.eE0123456789", s_[pos_])) ++pos_;
      v.text = s_.substr(start, pos_ - start);
    } else {
      fail(std::string("unexpected character '") + c + "'");
    }
    return v;
  }

  Value object(int depth) {
    Value v;
    v.type = Value::Type::kObject;
    expect('{');
    if (consume('}')) return v;
    do {
      skipSpace();
      if (pos_ >= s_.size() || s_[pos_] != '"') fail("expected a key string");
      std::string key = string();
      expect(':');
      v.members.emplace_back(std::move(key), value(depth + 1));
    } while (consume(','));
    expect('}');
    return v;
  }

  Value array(int depth) {
    Value v;
    v.type = Value::Type::kArray;
    expect('[');
    if (consume(']')) return v;
    do v.items.push_back(value(depth + 1));
    while (consume(','));
    expect(']');
    return v;
  }

  std::string string() {
    ++pos_;  // opening quote
    std::string out;
    while (pos_ < s_.size() && s_[pos_] != '"') {
      char c = s_[pos_++];
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (pos_ >= s_.size()) break;
      c = s_[pos_++];
      switch (c) {
        case '"': case '\\': case '/': out += c; break;
        case 'b': out += '\b'; break;
        case 'f': out += '\f'; break;
        case 'n': out += '\n'; break;
        case 'r': out += '\r'; break;
        case 't': out += '\t'; break;
        case 'u': {
          if (pos_ + 4 > s_.size()) fail("truncated \\u escape");
          const unsigned long code = std::strtoul(s_.substr(pos_, 4).c_str(), nullptr, 16);
          pos_ += 4;
          if (code >= 0x80) fail("non-ASCII \\u escape (not written by PALCAS)");
          out += static_cast<char>(code);
          break;
        }
        default: fail(std::string("unknown escape '\\") + c + "'");
      }
    }
    if (pos_ >= s_.size()) fail("unterminated string");
    ++pos_;  // closing quote
    return out;
  }

  const std::string& s_;
  const std::string& what_;
  size_t pos_ = 0;
};

}  // namespace

const Value& Value::at(const std::string& key, const std::string& what) const {
  if (type != Type::kObject) throw std::runtime_error(what + ": not a JSON object");
  for (const auto& m : members)
    if (m.first == key) return m.second;
  throw std::runtime_error(what + ": missing key '" + key + "'");
}

uint64_t Value::asUint(const std::string& what) const {
  const bool digits = type == Type::kNumber && !text.empty() &&
                      text.find_first_not_of("0123456789") == std::string::npos;
  errno = 0;
  const unsigned long long v = digits ? std::strtoull(text.c_str(), nullptr, 10) : 0;
  if (!digits || errno == ERANGE)
    throw std::runtime_error(what + " must be an unsigned integer, got '" + text + "'");
  return v;
}

double Value::asDouble(const std::string& what) const {
  char* end = nullptr;
  const double v = type == Type::kNumber ? std::strtod(text.c_str(), &end) : NAN;
  if (type != Type::kNumber || end != text.c_str() + text.size() || !std::isfinite(v))
    throw std::runtime_error(what + " must be a finite number, got '" + text + "'");
  return v;
}

const std::string& Value::asString(const std::string& what) const {
  if (type != Type::kString) throw std::runtime_error(what + " must be a string");
  return text;
}

Value parse(const std::string& text, const std::string& what) {
  return Parser(text, what).document();
}

std::string quote(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string number(double value) {
  if (!std::isfinite(value)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", value);
  return buf;
}

}  // namespace palcas::json
