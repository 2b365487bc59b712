// SumoSession::insertionDropped on the tiny road, in-process: a demand far over what the
// 40 m warm-up edge can take fills SUMO's insertion queue; with --max-depart-delay the
// vehicles that waited too long are dropped and counted, without it none is. Sessions run
// one after the other in this process (as the bridge's episodes do).
#include "palcas_sim/sumo_session.h"

#include <gtest/gtest.h>
#include <libsumo/libsumo.h>

#include <cmath>
#include <cstdlib>

#include "palcas_sim/scenario.h"
#include "scenario_test_util.h"

using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;

namespace {

constexpr double RUN_S = 120.0;
constexpr double MAINLINE_VPHPL = 4000.0;  // 12000 veh/h into 3 lanes from a 40 m edge
constexpr double ONRAMP_VPH = 300.0;

struct Counts {
  std::uint64_t departed = 0, pending = 0, dropped = 0;
};

Counts runTiny(double max_depart_delay_s, const std::string& name) {
  palcas::sim::ScenarioConfig c;
  c.scenario_dir = palcas::sim::test::scenarioDir("tiny");
  c.road = palcas::sim::test::tinyRoad();
  c.penetration_rate = 0.0;
  c.duration_s = RUN_S;
  c.seed = 5;
  c.mainline_flow_vphpl = MAINLINE_VPHPL;
  c.onramp_flow_vphpl = ONRAMP_VPH;
  c.max_depart_delay_s = max_depart_delay_s;
  const auto files = palcas::sim::writeScenario(c, palcas::sim::test::freshDir(name));
  SessionOptions o;
  o.sumo_args = {"-c", files.sumocfg_file, "--no-warnings", "true", "--no-step-log", "true",
                 "--time-to-teleport.remove", "true"};
  o.cluster_length_m = 300.0;
  SumoSession session(o);
  Counts n;
  while (session.timeS() < RUN_S - 1e-9) n.departed += session.step().departed.size();
  n.pending = libsumo::Simulation::getPendingVehicles().size();
  n.dropped = session.insertionDropped();
  return n;
}

}  // namespace

TEST(InsertionDropped, VehiclesThatWaitedTooLongAreCountedAndNoneWithoutADelay) {
  // What the flows offered in RUN_S (SUMO spaces a flow's vehicles evenly: within one
  // vehicle per flow of vehsPerHour x t).
  const double offered = (3 * MAINLINE_VPHPL + 2 * ONRAMP_VPH) * RUN_S / 3600.0;  // 420
  // Flows of the tiny road's default route shares: main -> end, off0, off1; on0 -> end,
  // off1; on1 -> end. Each may be one vehicle off.
  const double flows = 6;

  const Counts dropping = runTiny(1.0, "dropped_delay_1");
  // About half enters (the road takes ~6500 veh/h, measured: 218 departed, 201 dropped).
  EXPECT_GT(dropping.dropped, 0.3 * offered) << "departed " << dropping.departed;
  EXPECT_LT(dropping.pending, 0.05 * offered);  // a queue of at most ~1 s of demand is left
  EXPECT_NEAR(static_cast<double>(dropping.departed + dropping.pending + dropping.dropped),
              offered, flows);

  const Counts queueing = runTiny(-1.0, "dropped_never");
  EXPECT_EQ(queueing.dropped, 0u);
  EXPECT_GT(queueing.pending, 0.3 * offered);  // the excess waits instead
  EXPECT_NEAR(static_cast<double>(queueing.departed + queueing.pending), offered, flows);
  // The road takes about as much either way.
  EXPECT_NEAR(static_cast<double>(queueing.departed), static_cast<double>(dropping.departed),
              0.2 * dropping.departed);
}
