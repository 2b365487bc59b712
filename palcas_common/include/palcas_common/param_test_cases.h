#pragma once
// The options tests' cases (rostest gtests of each node's parameter loader): a copy of the
// shipped parameters under a namespace of its own with one thing changed, and a loader
// that must refuse it with an error naming what was wrong. Include from tests only.

#include <gtest/gtest.h>
#include <ros/ros.h>

#include <functional>
#include <stdexcept>
#include <string>

namespace palcas::common {

/// A copy of the parameters under `from` (e.g. "~shipped") as "~<name>", with `change` applied.
inline ros::NodeHandle paramCase(const std::string& from, const std::string& name,
                                 const std::function<void(ros::NodeHandle&)>& change) {
  ros::NodeHandle shipped(from), nh("~" + name);
  XmlRpc::XmlRpcValue all;
  EXPECT_TRUE(shipped.getParam("", all));
  nh.deleteParam("");
  nh.setParam("", all);
  change(nh);
  return nh;
}

/// `load` must throw std::invalid_argument mentioning `needle` for paramCase(from, name, change).
inline void expectLoadRefused(const std::function<void(const ros::NodeHandle&)>& load, const std::string& from,
                              const std::string& name, const std::function<void(ros::NodeHandle&)>& change,
                              const std::string& needle) {
  const ros::NodeHandle nh = paramCase(from, name, change);
  try {
    load(nh);
    ADD_FAILURE() << name << ": accepted; expected an error mentioning " << needle;
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace palcas::common
