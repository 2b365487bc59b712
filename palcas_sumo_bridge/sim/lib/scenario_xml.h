#pragma once
// A minimal reader for the flat, machine-written XML of SUMO networks and of our scenario
// sources: start tags and their attributes only (no entities, no CDATA). Private to palcas_sim.

#include <string>
#include <utility>
#include <vector>

namespace palcas::sim::xml {

/// One start tag: its name, attributes in file order, and its offset in the text.
struct Tag {
  std::string name;
  std::vector<std::pair<std::string, std::string>> attributes;
  std::size_t offset = 0;
};

/// Whole file as a string. @throws std::runtime_error naming the path when unreadable.
std::string readFile(const std::string& path);

/// The text with every <!-- ... --> comment removed (so commented-out tags are not seen).
std::string stripComments(const std::string& text);

/// Every start tag named `name` in the text, in order.
/// @throws std::runtime_error on an unterminated tag or a malformed attribute.
std::vector<Tag> findTags(const std::string& text, const std::string& name);

/// The attribute's value, or `fallback` when the tag does not have it.
std::string attribute(const Tag& tag, const std::string& key, const std::string& fallback = "");

/// True when the tag has the attribute.
bool hasAttribute(const Tag& tag, const std::string& key);

/// Value escaped for use inside a double-quoted XML attribute.
std::string escape(const std::string& value);

}  // namespace palcas::sim::xml
