// Runs SUMO in-process (libsumo) for 60 simulated seconds on a generated scenario at PR 0.6.
// Built twice (PALCAS_SMOKE_SCENARIO = "tiny" / "paper"): libsumo holds one simulation per
// process.
#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <cmath>
#include <map>
#include <set>

#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

#ifndef PALCAS_SMOKE_SCENARIO
#error "PALCAS_SMOKE_SCENARIO must name a scenario folder (tiny or paper)"
#endif

namespace {

constexpr double PR = 0.6;
constexpr double RUN_S = 60.0;

palcas::sim::ScenarioConfig smokeConfig() {
  palcas::sim::ScenarioConfig c;
  const std::string name = PALCAS_SMOKE_SCENARIO;
  c.scenario_dir = palcas::sim::test::scenarioDir(name);
  c.penetration_rate = PR;
  c.duration_s = RUN_S;
  if (name == "tiny") {  // config/scenarios/tiny/scenario.yaml
    c.road = palcas::sim::test::tinyRoad();
    c.mainline_flow_vphpl = 1000.0;
    c.onramp_flow_vphpl = 300.0;
  }
  return c;
}

/// "main->end", "main->off", "on->end", "on->off" of a route id r_<from>_<to>.
std::string routeKind(const std::string& route) {
  const std::string from = route.rfind("r_main_", 0) == 0 ? "main" : "on";
  const bool to_end = route.size() >= 4 && route.compare(route.size() - 4, 4, "_end") == 0;
  return from + (to_end ? "->end" : "->off");
}

}  // namespace

TEST(ScenarioSmoke, SumoRunsTheGeneratedScenarioAndEveryRouteDeparts) {
  const palcas::sim::ScenarioConfig config = smokeConfig();
  const auto files = palcas::sim::writeScenario(
      config, palcas::sim::test::freshDir(std::string("smoke_") + PALCAS_SMOKE_SCENARIO));
  std::set<std::string> expected_routes;
  for (const auto& r : palcas::sim::buildRoutes(config, palcas::sim::readNetEdges(files.net_file)))
    if (r.vehs_per_hour > 0.0) expected_routes.insert(r.id);

  ASSERT_NO_THROW(libsumo::Simulation::load({"-c", files.sumocfg_file, "--no-warnings", "true"}));
  std::map<std::string, int> departures_per_route;
  std::set<std::string> kinds;
  int departed = 0, cavs = 0, teleports = 0, collisions = 0;
  while (libsumo::Simulation::getTime() < RUN_S - 1e-6) {
    ASSERT_NO_THROW(libsumo::Simulation::step());
    for (const std::string& id : libsumo::Simulation::getDepartedIDList()) {
      const std::string route = libsumo::Vehicle::getRouteID(id);
      ++departures_per_route[route];
      kinds.insert(routeKind(route));
      ++departed;
      if (palcas::sim::isCavType(libsumo::Vehicle::getTypeID(id))) ++cavs;
    }
    teleports += libsumo::Simulation::getStartingTeleportNumber();
    collisions += libsumo::Simulation::getCollidingVehiclesNumber();
  }
  libsumo::Simulation::close();

  for (const std::string& route : expected_routes)
    EXPECT_GT(departures_per_route[route], 0) << "no vehicle departed on " << route;
  EXPECT_EQ(kinds, (std::set<std::string>{"main->end", "main->off", "on->end", "on->off"}));
  ASSERT_GT(departed, 30);
  // Each vehicle is a CAV with probability PR: the share lies within 4 binomial standard
  // deviations, 4 sqrt(PR (1 - PR) / n), of PR (fixed seed: the run is deterministic).
  const double share = static_cast<double>(cavs) / departed;
  EXPECT_NEAR(share, PR, 4.0 * std::sqrt(PR * (1.0 - PR) / departed)) << departed << " departed";
  EXPECT_EQ(teleports, 0);
  RecordProperty("departed", departed);
  RecordProperty("collisions", collisions);
  std::cout << PALCAS_SMOKE_SCENARIO << ": " << departed << " departed, CAV share " << share
            << ", " << collisions << " colliding, " << teleports << " teleports\n";
}
