#pragma once
// ParamReader: the one way PALCAS nodes read their private parameters. Each node's options
// loader is the only code that calls it; it remembers every key it was asked for, so a key
// nobody asked for (a typo in a YAML file) is reported by rejectUnknownKeys() instead of
// being silently ignored. Errors are std::invalid_argument naming the full parameter name.
// Header-only, next to the message contract because every node depends on palcas_msgs.

#include <ros/node_handle.h>

#include <cmath>
#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace palcas::common {

class ParamReader {
 public:
  explicit ParamReader(const ros::NodeHandle& nh) : nh_(nh) {}

  bool has(const std::string& key) const { return nh_.hasParam(key); }
  std::string fullName(const std::string& key) const { return nh_.resolveName(key); }

  /// An optional key: `fallback` when absent; present with the wrong type is an error.
  template <typename T>
  T get(const std::string& key, const T& fallback) {
    known_.insert(key);
    T value = fallback;
    if (nh_.hasParam(key) && !nh_.getParam(key, value))
      throw std::invalid_argument("parameter '" + fullName(key) + "' has the wrong type");
    return value;
  }

  /// A required key: missing or of the wrong type is an error naming it.
  template <typename T>
  T require(const std::string& key) {
    if (!nh_.hasParam(key)) {
      known_.insert(key);
      throw std::invalid_argument("parameter '" + fullName(key) + "' is missing");
    }
    return get<T>(key, T{});
  }

  /// A number in [min, max] (NaN refused), optional with `fallback`.
  double number(const std::string& key, double fallback, double min, double max) {
    return checkRange(key, get<double>(key, fallback), min, max);
  }
  /// An integer in [min, max]; a fractional value is refused, not truncated.
  int integer(const std::string& key, int fallback, int min, int max) {
    const double value = checkRange(key, get<double>(key, fallback), min, max);
    if (value != std::floor(value))
      throw std::invalid_argument("parameter '" + fullName(key) + "' = " + std::to_string(value) +
                                  " is not a whole number");
    return static_cast<int>(value);
  }
  /// A count that may exceed int32 (XmlRpc integers are 32-bit; YAML writes larger ones as
  /// doubles): a whole number in [min, 2^53]. Read as a double, which holds both exactly
  /// (roscpp would silently truncate 10.5 read as an int).
  std::uint64_t count(const std::string& key, std::uint64_t fallback, std::uint64_t min) {
    const double value = get<double>(key, static_cast<double>(fallback));
    checkRange(key, value, static_cast<double>(min), 9007199254740992.0);
    if (value != std::floor(value))
      throw std::invalid_argument("parameter '" + fullName(key) + "' = " + std::to_string(value) +
                                  " is not a whole number");
    return static_cast<std::uint64_t>(value);
  }

  /// Marks a key as known without reading it (read elsewhere, e.g. by a sub-loader).
  void accept(const std::string& key) { known_.insert(key); }

  /// Throws for any parameter under the node's namespace that no call asked for.
  void rejectUnknownKeys(const std::string& where_documented) const {
    std::vector<std::string> names;
    nh_.getParamNames(names);
    const std::string ns = nh_.getNamespace() + "/";
    for (const std::string& name : names) {
      if (name.compare(0, ns.size(), ns) != 0) continue;
      if (!known_.count(name.substr(ns.size())))
        throw std::invalid_argument("unknown parameter '" + name + "' (see " + where_documented +
                                    " for the valid keys)");
    }
  }

 private:
  double checkRange(const std::string& key, double value, double min, double max) const {
    if (std::isnan(value) || value < min || value > max)
      throw std::invalid_argument("parameter '" + fullName(key) + "' = " + std::to_string(value) +
                                  " is outside [" + std::to_string(min) + ", " + std::to_string(max) +
                                  "]");
    return value;
  }

  const ros::NodeHandle& nh_;
  std::set<std::string> known_;
};

}  // namespace palcas::common
