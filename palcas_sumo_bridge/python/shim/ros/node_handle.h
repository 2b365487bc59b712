#pragma once
// A stand-in for roscpp's ros::NodeHandle, for the Python module palcas_env only: the
// parameter calls the suite's options loaders make (ParamReader, loadBridgeOptions,
// loadRsuNodeOptions), answered from a parameter tree the module assembles from the same
// YAML files, in the same order, as the launch files. So the module reads its parameters
// with the nodes' own loaders (same keys, defaults, ranges and errors) without linking
// roscpp. This directory comes first on the module's include path; nothing else sees it.
//
// The semantics are roscpp's where the loaders depend on them: getParam into a double
// accepts an integer, into an int or a bool only its own type; hasParam is true for a
// namespace with keys under it; getParamNames lists the leaves by full name.

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace ros {

/// One parameter value (XmlRpc's types that the loaders read).
struct ParamValue {
  enum class Type { kBool, kInt, kDouble, kString, kList } type = Type::kString;
  bool b = false;
  int i = 0;
  double d = 0.0;
  std::string s;
  std::vector<ParamValue> list;
};

/// Full name ("/palcas_sumo_bridge/scenario/seed") -> value.
using ParamTree = std::map<std::string, ParamValue>;

class NodeHandle {
 public:
  NodeHandle(std::shared_ptr<const ParamTree> tree, std::string ns) : tree_(std::move(tree)), ns_(clean(ns)) {}
  NodeHandle(const NodeHandle& parent, const std::string& ns)
      : tree_(parent.tree_), ns_(clean(ns.rfind('/', 0) == 0 ? ns : parent.ns_ + "/" + ns)) {}

  const std::string& getNamespace() const { return ns_; }
  std::string resolveName(const std::string& key) const {
    return key.rfind('/', 0) == 0 ? key : clean(ns_ + "/" + key);
  }

  bool hasParam(const std::string& key) const {
    const std::string name = resolveName(key);
    if (tree_->count(name)) return true;
    const auto it = tree_->lower_bound(name + "/");
    return it != tree_->end() && it->first.compare(0, name.size() + 1, name + "/") == 0;
  }
  void getParamNames(std::vector<std::string>& names) const {
    names.clear();
    for (const auto& entry : *tree_) names.push_back(entry.first);
  }

  bool getParam(const std::string& key, double& out) const {
    const ParamValue* v = find(key);
    return v && toDouble(*v, out);
  }
  bool getParam(const std::string& key, float& out) const {
    double d = 0.0;
    if (!getParam(key, d)) return false;
    out = static_cast<float>(d);
    return true;
  }
  bool getParam(const std::string& key, int& out) const {
    const ParamValue* v = find(key);
    if (!v || v->type != ParamValue::Type::kInt) return false;
    out = v->i;
    return true;
  }
  bool getParam(const std::string& key, bool& out) const {
    const ParamValue* v = find(key);
    if (!v || v->type != ParamValue::Type::kBool) return false;
    out = v->b;
    return true;
  }
  bool getParam(const std::string& key, std::string& out) const {
    const ParamValue* v = find(key);
    if (!v || v->type != ParamValue::Type::kString) return false;
    out = v->s;
    return true;
  }
  bool getParam(const std::string& key, std::vector<double>& out) const {
    return getList(key, out, [](const ParamValue& v, double& d) { return toDouble(v, d); });
  }
  bool getParam(const std::string& key, std::vector<int>& out) const {
    return getList(key, out, [](const ParamValue& v, int& i) {
      if (v.type != ParamValue::Type::kInt) return false;
      i = v.i;
      return true;
    });
  }
  bool getParam(const std::string& key, std::vector<std::string>& out) const {
    return getList(key, out, [](const ParamValue& v, std::string& s) {
      if (v.type != ParamValue::Type::kString) return false;
      s = v.s;
      return true;
    });
  }

 private:
  static std::string clean(std::string ns) {
    std::string out;
    for (char c : ns)
      if (!(c == '/' && !out.empty() && out.back() == '/')) out += c;
    if (out.empty() || out[0] != '/') out = "/" + out;
    if (out.size() > 1 && out.back() == '/') out.pop_back();
    return out;
  }
  static bool toDouble(const ParamValue& v, double& out) {
    if (v.type == ParamValue::Type::kDouble) out = v.d;
    else if (v.type == ParamValue::Type::kInt) out = v.i;
    else return false;
    return true;
  }
  const ParamValue* find(const std::string& key) const {
    const auto it = tree_->find(resolveName(key));
    return it == tree_->end() ? nullptr : &it->second;
  }
  template <class T, class F>
  bool getList(const std::string& key, std::vector<T>& out, F&& convert) const {
    const ParamValue* v = find(key);
    if (!v || v->type != ParamValue::Type::kList) return false;
    std::vector<T> values(v->list.size());
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!convert(v->list[i], values[i])) return false;
    out = std::move(values);
    return true;
  }

  std::shared_ptr<const ParamTree> tree_;
  std::string ns_;
};

}  // namespace ros
