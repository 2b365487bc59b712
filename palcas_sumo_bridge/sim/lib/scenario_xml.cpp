#include "scenario_xml.h"

#include <cctype>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace palcas::sim::xml {
namespace {

bool isNameChar(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
         c == ':';
}

void skipSpace(const std::string& text, std::size_t& i) {
  while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
}

/// Parses the attributes of the tag starting at `open` (the '<'); `i` ends past the '>'.
Tag parseTag(const std::string& text, std::size_t open, const std::string& name) {
  Tag tag{name, {}, open};
  std::size_t i = open + 1 + name.size();
  while (true) {
    skipSpace(text, i);
    if (i >= text.size())
      throw std::runtime_error("XML: unterminated <" + name + "> tag at offset " +
                               std::to_string(open));
    if (text[i] == '>' || text[i] == '/') return tag;
    const std::size_t key_begin = i;
    while (i < text.size() && isNameChar(text[i])) ++i;
    const std::string key = text.substr(key_begin, i - key_begin);
    skipSpace(text, i);
    if (key.empty() || i + 1 >= text.size() || text[i] != '=')
      throw std::runtime_error("XML: malformed attribute in <" + name + "> at offset " +
                               std::to_string(key_begin));
    ++i;
    skipSpace(text, i);
    const char quote = i < text.size() ? text[i] : '\0';
    if (quote != '"' && quote != '\'')
      throw std::runtime_error("XML: unquoted value of '" + key + "' in <" + name + ">");
    const std::size_t close = text.find(quote, i + 1);
    if (close == std::string::npos)
      throw std::runtime_error("XML: unterminated value of '" + key + "' in <" + name + ">");
    tag.attributes.emplace_back(key, text.substr(i + 1, close - i - 1));
    i = close + 1;
  }
}

}  // namespace

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read file '" + path + "'");
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::string stripComments(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  std::size_t i = 0;
  while (i < text.size()) {
    const std::size_t begin = text.find("<!--", i);
    if (begin == std::string::npos) break;
    out.append(text, i, begin - i);
    const std::size_t end = text.find("-->", begin + 4);
    if (end == std::string::npos) return out;  // unterminated comment: drop the rest
    i = end + 3;
  }
  if (i < text.size()) out.append(text, i, std::string::npos);
  return out;
}

std::vector<Tag> findTags(const std::string& text, const std::string& name) {
  std::vector<Tag> tags;
  const std::string open = "<" + name;
  for (std::size_t at = text.find(open); at != std::string::npos; at = text.find(open, at + 1)) {
    const std::size_t after = at + open.size();
    // "<edge" must not match "<edges" or "<edge-files".
    if (after < text.size() && !std::isspace(static_cast<unsigned char>(text[after])) &&
        text[after] != '>' && text[after] != '/')
      continue;
    tags.push_back(parseTag(text, at, name));
  }
  return tags;
}

std::string attribute(const Tag& tag, const std::string& key, const std::string& fallback) {
  for (const auto& [k, v] : tag.attributes)
    if (k == key) return v;
  return fallback;
}

bool hasAttribute(const Tag& tag, const std::string& key) {
  for (const auto& kv : tag.attributes)
    if (kv.first == key) return true;
  return false;
}

std::string escape(const std::string& value) {
  std::string out;
  for (char c : value) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace palcas::sim::xml
