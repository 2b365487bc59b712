// SUMO's own outputs switched on by name (palcas_sim/sumo_outputs.h): the argument list, its
// errors, and a run of the tiny road that writes every output. One libsumo simulation per
// process: one test starts SUMO.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>

#include "palcas_sim/sumo_outputs.h"
#include "palcas_sim/sumo_session.h"
#include "scenario_test_util.h"
#include "common/throws_naming.h"

using palcas::sim::sumoOutputArgs;
using palcas::sim::sumoOutputKinds;

namespace {

std::size_t countOf(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST(SumoOutputArgs, NoNamesNoArguments) { EXPECT_TRUE(sumoOutputArgs({}, "/run", 1.0).empty()); }

TEST(SumoOutputArgs, EachNameWritesItsFileIntoTheRunFolder) {
  for (const auto& kind : sumoOutputKinds()) {
    const auto args = sumoOutputArgs({kind.name}, "/run", 1.0);
    const std::string file = std::string("/run/") + kind.file_name;
    EXPECT_NE(std::find(args.begin(), args.end(), file), args.end()) << kind.name;
  }
}

TEST(SumoOutputArgs, FcdPeriodZeroMeansEveryStep) {
  const auto every_step = sumoOutputArgs({"fcd"}, "/run", 0.0);
  EXPECT_EQ(std::find(every_step.begin(), every_step.end(), "--device.fcd.period"), every_step.end());
  const auto every_second = sumoOutputArgs({"fcd"}, "/run", 1.0);
  EXPECT_NE(std::find(every_second.begin(), every_second.end(), "--device.fcd.period"), every_second.end());
}

TEST(SumoOutputArgs, BadInputIsRefusedNamingIt) {
  palcas_test::expectThrowNaming<std::invalid_argument>([] { sumoOutputArgs({"fcd", "trips"}, "/run", 1.0); },
                                                        "'trips'");
  palcas_test::expectThrowNaming<std::invalid_argument>([] { sumoOutputArgs({"ssm", "ssm"}, "/run", 1.0); },
                                                        "'ssm' named twice");
  palcas_test::expectThrowNaming<std::invalid_argument>([] { sumoOutputArgs({"fcd"}, "/run", -1.0); },
                                                        "sumo_fcd_period_s");
}

TEST(SumoOutputArgs, ThePalcasCommandKnowsTheSameNames) {
  // ./palcas run --sumo-output checks names before anything starts, from its own list
  // (tools/palcas_cli/options.py: SUMO_OUTPUTS = ("fcd", "tripinfo", ...)).
  const std::string script =
      palcas::sim::test::slurp(std::string(PALCAS_CONFIG_DIR) + "/../tools/palcas_cli/options.py");
  const std::string key = "SUMO_OUTPUTS = (";
  const auto at = script.find(key);
  ASSERT_NE(at, std::string::npos) << "no SUMO_OUTPUTS = (...) line in tools/palcas_cli/options.py";
  const auto end = script.find(')', at + key.size());
  std::string listed;
  for (char c : script.substr(at + key.size(), end - at - key.size()))
    if (c == ',') listed += ' ';
    else if (c != '"' && c != ' ') listed += c;
  std::string known;
  for (const auto& kind : sumoOutputKinds()) known += (known.empty() ? "" : " ") + std::string(kind.name);
  EXPECT_EQ(listed, known);
}

TEST(SumoOutputs, TinyRoadWritesEveryOutputAndTripinfoHasEveryArrival) {
  const std::string run = palcas::sim::test::freshDir("sumo_outputs_run");
  std::vector<std::string> names;
  for (const auto& kind : sumoOutputKinds()) names.push_back(kind.name);
  palcas::sim::SessionOptions options = palcas::sim::test::sessionOnTiny("sumo_outputs", 5);
  const auto extra = sumoOutputArgs(names, run, 1.0);
  options.sumo_args.insert(options.sumo_args.end(), extra.begin(), extra.end());
  std::set<std::string> arrived;
  {
    auto session = std::make_unique<palcas::sim::SumoSession>(options);
    for (int i = 0; i < 1200; ++i)
      for (const std::string& id : session->step().arrived) arrived.insert(id);
  }  // closing the session makes SUMO finish its files
  ASSERT_GT(arrived.size(), 20u);
  for (const auto& kind : sumoOutputKinds()) {
    const std::string path = run + "/" + kind.file_name;
    ASSERT_TRUE(std::filesystem::exists(path)) << kind.name << ": " << path;
    EXPECT_GT(std::filesystem::file_size(path), 100u) << kind.name;
  }
  using palcas::sim::test::slurp;
  const std::string trips = slurp(run + "/sumo_tripinfo.xml");
  for (const std::string& id : arrived) EXPECT_EQ(countOf(trips, "<tripinfo id=\"" + id + "\""), 1u) << id;
  // FCD at 1 s over 120 s: one timestep element per sampled second.
  const std::size_t fcd_steps = countOf(slurp(run + "/sumo_fcd.xml"), "<timestep ");
  EXPECT_GE(fcd_steps, 110u);
  EXPECT_LE(fcd_steps, 121u);
  EXPECT_GT(countOf(slurp(run + "/sumo_lanechange.xml"), "<change "), 0u);
  EXPECT_EQ(countOf(slurp(run + "/sumo_summary.xml"), "<step "), 1200u);
}
