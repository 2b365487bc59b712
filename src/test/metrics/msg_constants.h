#pragma once
// Reads the "uint8 NAME=VALUE" constants of a palcas_msgs .msg file as text, so core tests
// can check that the core's enums mirror the message contract without including ROS.
// PALCAS_MSG_DIR is defined by the test's CMake target.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <string>

namespace palcas::test {

inline std::map<std::string, int> msgConstants(const std::string& file) {
  std::ifstream in(std::string(PALCAS_MSG_DIR) + "/" + file);
  EXPECT_TRUE(in.good()) << "cannot read " << PALCAS_MSG_DIR << "/" << file;
  const std::regex constant(R"(^\s*uint8\s+([A-Z_]+)\s*=\s*(\d+))");
  std::map<std::string, int> out;
  std::string line;
  std::smatch m;
  while (std::getline(in, line))
    if (std::regex_search(line, m, constant)) out[m[1]] = std::stoi(m[2]);
  return out;
}

}  // namespace palcas::test
