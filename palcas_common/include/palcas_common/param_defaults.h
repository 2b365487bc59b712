#pragma once
// "One source for every default": compares the keys a namespace holds (a node's shipped
// YAML, loaded alone) with the defaults its loader compiled in (ParamDefaults, recorded
// by ParamReader). Used by each node's options test; header-only.

#include <palcas_common/param_reader.h>
#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <string>
#include <vector>

namespace palcas::common {

/// paramText of a value read from the parameter server.
inline std::string paramText(XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeInt: return paramText(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble: return paramText(static_cast<double>(v));
    case XmlRpc::XmlRpcValue::TypeBoolean: return paramText(static_cast<bool>(v));
    case XmlRpc::XmlRpcValue::TypeString: return static_cast<std::string>(v);
    case XmlRpc::XmlRpcValue::TypeArray: {
      std::string out = "[";
      for (int i = 0; i < v.size(); ++i) out += (i ? "," : "") + paramText(v[i]);
      return out + "]";
    }
    default: return "<unsupported type>";
  }
}

/// One line per key under `yaml` whose value differs from its compiled-in default, or that
/// the loader never read. Required keys (no default) are not compared. Empty = the YAML
/// and the structs agree.
inline std::vector<std::string> defaultsDisagreeing(const ros::NodeHandle& yaml, const ParamDefaults& defaults) {
  std::vector<std::string> out, names;
  yaml.getParamNames(names);
  const std::string ns = yaml.getNamespace() + "/";
  for (const std::string& name : names) {
    if (name.compare(0, ns.size(), ns) != 0) continue;
    const std::string key = name.substr(ns.size());
    XmlRpc::XmlRpcValue value;
    yaml.getParam(key, value);
    const std::string text = paramText(value);
    const auto d = defaults.values.find(key);
    if (defaults.required.count(key)) continue;
    if (d == defaults.values.end())
      out.push_back(key + ": not read by the loader");
    else if (d->second != text)
      out.push_back(key + ": YAML " + text + ", compiled-in default " + d->second);
  }
  return out;
}

}  // namespace palcas::common
