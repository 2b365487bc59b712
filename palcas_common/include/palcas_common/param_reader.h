#pragma once
// ParamReader: the one way PALCAS nodes read their private parameters. Each node's options
// loader is the only code that calls it; it remembers every key it was asked for, so a key
// nobody asked for (a typo in a YAML file) is reported by rejectUnknownKeys() instead of
// being silently ignored. Errors are std::invalid_argument naming the full parameter name.
// It can also record every key's compiled-in default (ParamDefaults), so a test can prove
// that the shipped YAML and the structs agree (param_defaults.h). Header-only.

#include <ros/node_handle.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace palcas::common {

/// Canonical text of a parameter value, the same for a compiled-in default and a value
/// read from YAML: numbers with 6 significant digits (float fields compare equal to their
/// YAML decimal), bools as true/false, lists as [a,b].
inline std::string paramText(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}
inline std::string paramText(int v) { return paramText(static_cast<double>(v)); }
inline std::string paramText(bool v) { return v ? "true" : "false"; }
inline std::string paramText(const std::string& v) { return v; }
template <typename T>
std::string paramText(const std::vector<T>& values) {
  std::string out = "[";
  for (std::size_t i = 0; i < values.size(); ++i) out += (i ? "," : "") + paramText(values[i]);
  return out + "]";
}

/// Every optional key a loader read, with the default it would have used (paramText).
struct ParamDefaults {
  std::map<std::string, std::string> values;
  std::set<std::string> required;  ///< keys without a default
};

class ParamReader {
 public:
  /// defaults: if set, every key's compiled-in default is recorded there.
  explicit ParamReader(const ros::NodeHandle& nh, ParamDefaults* defaults = nullptr)
      : nh_(nh), defaults_(defaults) {}

  bool has(const std::string& key) const { return nh_.hasParam(key); }
  std::string fullName(const std::string& key) const { return nh_.resolveName(key); }

  /// An optional key: `fallback` when absent; present with the wrong type is an error.
  template <typename T>
  T get(const std::string& key, const T& fallback) {
    known_.insert(key);
    if (defaults_) defaults_->values[key] = paramText(fallback);
    T value = fallback;
    if (nh_.hasParam(key) && !nh_.getParam(key, value))
      throw std::invalid_argument("parameter '" + fullName(key) + "' has the wrong type");
    return value;
  }

  /// A required key: missing or of the wrong type is an error naming it.
  template <typename T>
  T require(const std::string& key) {
    if (defaults_) defaults_->required.insert(key);
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
  ParamDefaults* defaults_;
  std::set<std::string> known_;
};

}  // namespace palcas::common
