// The bridge's episode loop without ROS (palcas_sim/episode_runner.h) on the tiny road, with
// a scripted transport in place of the topics: the lockstep waits for answers and goes on
// without an RSU that stopped answering; advisories are checked, carried out and held; the
// V2X channel delays and drops them, the same way for the same seed. Each test runs its own
// SUMO, closed before the next one loads (one libsumo simulation at a time).
#include "palcas_sim/episode_runner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <thread>

#include "common/throws_naming.h"
#include "scenario_test_util.h"

using palcas::metrics::AdvisoryRequest;
using palcas::metrics::RejectionReason;
using palcas::sim::AdviceArray;
using palcas::sim::EpisodePort;
using palcas::sim::EpisodeRun;
using palcas::sim::EpisodeRunner;
using palcas::sim::RunnerOptions;
using palcas::sim::SessionOptions;
using palcas::sim::SumoSession;
using palcas::sim::VehicleRecord;

namespace {

constexpr int LANE_LEFT = 0, LANE_RIGHT = 1, ACCELERATE = 2, KEEP = 3;

// The RSUs of a test: called once per published step with the runner to answer through.
using Rsus = std::function<void(const SumoSession&, EpisodeRunner&)>;

class ScriptedPort : public EpisodePort {
 public:
  ScriptedPort(EpisodeRunner& runner, Rsus rsus) : runner_(runner), rsus_(std::move(rsus)) {}

  bool running() const override { return true; }
  void publishStep(const SumoSession& session) override {
    ++published;
    last_published_step = session.stepCount();
    answer_due_ = true;
  }
  void receive(std::chrono::steady_clock::time_point deadline, const std::function<bool()>& done) override {
    if (answer_due_ && rsus_) {
      answer_due_ = false;
      rsus_(runner_.session(), runner_);
    }
    while (!done() && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  }
  void lockstepMissed(std::uint64_t, const std::vector<std::string>& late,
                      const std::vector<std::string>& newly_lost) override {
    for (const auto& id : late) ++late_by_rsu[id];
    for (const auto& id : newly_lost) lost.push_back(id);
  }
  void rejected(const std::string&, const std::string& vehicle_id, RejectionReason reason,
                const std::string& detail) override {
    ++rejections[reason];
    last_rejection = vehicle_id + ": " + detail;
  }
  void applied(const std::string& vehicle_id) override { applied_at[vehicle_id].push_back(runner_.session().stepCount()); }
  void actuated(const SumoSession& session, const palcas::sim::AdvisoryHolds& holds) override {
    in_force_by_step[session.stepCount()] = holds.inForce().size();
  }
  void stepped(const SumoSession&) override { ++stepped_count; }
  void progress(const SumoSession& session) override { progress_at_s.push_back(session.timeS()); }

  int published = 0, stepped_count = 0;
  std::uint64_t last_published_step = 0;
  std::map<std::string, int> late_by_rsu;
  std::vector<std::string> lost;
  std::map<RejectionReason, int> rejections;
  std::string last_rejection;
  std::map<std::string, std::vector<std::uint64_t>> applied_at;
  std::map<std::uint64_t, std::size_t> in_force_by_step;
  std::vector<double> progress_at_s;

 private:
  EpisodeRunner& runner_;
  Rsus rsus_;
  bool answer_due_ = false;
};

RunnerOptions tinyRunner(std::vector<std::string> rsus, double duration_s) {
  RunnerOptions o;
  o.duration_s = duration_s;
  o.expected_rsus = std::move(rsus);
  o.lost_after_missed_steps = 5;
  o.lockstep_deadline_s = 0.002;  // a silent RSU costs the test 2 ms a step
  o.metrics_period_s = 5.0;
  return o;
}

EpisodeRunner::SessionFactory tinySession(const std::string& name, unsigned seed = 3) {
  return [name, seed](int episode) {
    return std::make_unique<SumoSession>(palcas::sim::test::sessionOnTiny(name + std::to_string(episode), seed));
  };
}

std::shared_ptr<AdviceArray> answer(const std::string& rsu, std::uint64_t step) {
  auto a = std::make_shared<AdviceArray>();
  a->rsu_id = rsu;
  a->step = step;
  a->decision_ms = 1.5f;
  return a;
}

void advise(AdviceArray& array, const std::string& vehicle, int action, double accel_mps2 = 0.0) {
  AdvisoryRequest r;
  r.vehicle_id = vehicle;
  r.action_code = action;
  r.accel_mps2 = accel_mps2;
  r.answers_step = array.step;
  r.rsu_id = array.rsu_id;
  array.advisories.push_back(r);
}

// Mainline CAVs in lane 1 on the road now.
std::vector<std::string> cavsInLaneOne(const SumoSession& session) {
  std::vector<std::string> ids;
  for (const VehicleRecord& v : session.vehicles())
    if (v.is_cav && v.part == palcas::RoadPart::kMainline && v.lane == 1) ids.push_back(v.id);
  return ids;
}

}  // namespace

TEST(EpisodeRunner, RunsTheEpisodeInLockstepToItsDuration) {
  EpisodeRunner runner(tinyRunner({"rsu_0", "rsu_1"}, 20.0), tinySession("runner_lockstep"));
  std::string reason;
  ASSERT_TRUE(runner.lockstep().registerRsu("rsu_0", &reason));
  ASSERT_TRUE(runner.lockstep().registerRsu("rsu_1", &reason));
  ScriptedPort port(runner, [](const SumoSession& s, EpisodeRunner& r) {
    for (const char* rsu : {"rsu_1", "rsu_0"}) r.onAnswer(answer(rsu, s.stepCount()));
  });
  const EpisodeRun run = runner.runEpisode(0, port);
  EXPECT_EQ(run.steps, 200u);  // 20 s of 0.1 s steps
  EXPECT_EQ(port.published, 201);  // step 0 and each step after
  EXPECT_EQ(port.stepped_count, 200);
  EXPECT_EQ(port.last_published_step, 200u);
  EXPECT_TRUE(port.late_by_rsu.empty());
  EXPECT_TRUE(run.late_by_rsu.empty());
  EXPECT_EQ(runner.lockstep().lateSteps(), 0u);
  EXPECT_TRUE(run.decision_ms.empty());  // answers without advice are not decisions
  // Every 5 s of simulated time, the last one covering the end.
  EXPECT_EQ(port.progress_at_s, (std::vector<double>{5.0, 10.0, 15.0, 20.0}));
  std::size_t timed_steps = 0;
  for (const auto& [first, bucket] : run.timing.buckets()) timed_steps += bucket.steps;
  EXPECT_EQ(timed_steps, 200u);
}

TEST(EpisodeRunner, GoesOnWithoutAnRsuThatStoppedAnsweringAndTakesItBack) {
  EpisodeRunner runner(tinyRunner({"rsu_0", "rsu_1"}, 20.0), tinySession("runner_lost"));
  std::string reason;
  ASSERT_TRUE(runner.lockstep().registerRsu("rsu_0", &reason));
  ASSERT_TRUE(runner.lockstep().registerRsu("rsu_1", &reason));
  // rsu_1 is silent from step 50 to 119, then answers again.
  ScriptedPort port(runner, [](const SumoSession& s, EpisodeRunner& r) {
    const std::uint64_t k = s.stepCount();
    r.onAnswer(answer("rsu_0", k));
    if (k < 50 || k >= 120) {
      const EpisodeRunner::AnswerOutcome out = r.onAnswer(answer("rsu_1", k));
      EXPECT_EQ(out.verdict, EpisodeRunner::Verdict::kQueued);
      if (k == 120) {
        EXPECT_EQ(out.revived, std::vector<std::string>{"rsu_1"});
      }
    }
  });
  const EpisodeRun run = runner.runEpisode(0, port);
  EXPECT_EQ(run.steps, 200u);
  // Late on 5 steps (lost_after_missed_steps), then lost: no longer waited for.
  EXPECT_EQ(run.late_by_rsu.at("rsu_1"), 5u);
  EXPECT_EQ(run.late_by_rsu.count("rsu_0"), 0u);
  EXPECT_EQ(port.late_by_rsu.at("rsu_1"), 5);
  EXPECT_EQ(port.lost, std::vector<std::string>{"rsu_1"});
  EXPECT_TRUE(runner.lockstep().lostRsus().empty());  // live again since step 120
}

TEST(EpisodeRunner, ChecksAdvisoriesCarriesOutTheGoodOnesAndHoldsThem) {
  RunnerOptions options = tinyRunner({"rsu_0"}, 30.0);
  options.advisory_hold_steps = 10;
  EpisodeRunner runner(options, tinySession("runner_advice"));
  std::string reason;
  ASSERT_TRUE(runner.lockstep().registerRsu("rsu_0", &reason));
  std::string advised;
  std::uint64_t advised_step = 0;
  ScriptedPort port(runner, [&](const SumoSession& s, EpisodeRunner& r) {
    auto array = answer("rsu_0", s.stepCount());
    const auto lane_one = cavsInLaneOne(s);
    if (advised.empty() && lane_one.size() >= 2) {
      advised = lane_one[0];
      advised_step = s.stepCount();
      advise(*array, advised, ACCELERATE, 0.5);
      advise(*array, advised, KEEP);  // a second advisory for it this step
      advise(*array, "ghost", KEEP);
      advise(*array, lane_one[1], ACCELERATE, std::numeric_limits<double>::quiet_NaN());
      advise(*array, lane_one[1], 7);  // after the NaN one was refused: no duplicate
    }
    r.onAnswer(array);
  });
  const EpisodeRun run = runner.runEpisode(0, port);
  ASSERT_FALSE(advised.empty()) << "no two CAVs in lane 1 within 30 s";
  EXPECT_EQ(port.applied_at.at(advised), std::vector<std::uint64_t>{advised_step});
  EXPECT_EQ(port.applied_at.size(), 1u);
  EXPECT_EQ(port.rejections[RejectionReason::kDuplicate], 1);
  EXPECT_EQ(port.rejections[RejectionReason::kUnknownVehicle], 1);
  EXPECT_EQ(port.rejections[RejectionReason::kNotFinite], 1);
  EXPECT_EQ(port.rejections[RejectionReason::kUnknownAction], 1);
  EXPECT_EQ(run.decision_ms, std::vector<float>{1.5f});
  // The command holds for 10 steps, then the CAV's own driving takes over.
  EXPECT_EQ(port.in_force_by_step.at(advised_step), 1u);
  EXPECT_EQ(port.in_force_by_step.at(advised_step + 9), 1u);
  EXPECT_EQ(port.in_force_by_step.at(advised_step + 10), 0u);
  EXPECT_EQ(run.downlink.sent, 5u);
  EXPECT_EQ(run.downlink.delivered, 5u);  // the channel is off: everything arrives at once
}

TEST(EpisodeRunner, AnAdvisoryTheGuardDeclinesIsARejectionWithTheGuardsReason) {
  // Lane changes advised on the edge where SUMO inserts traffic, every second: valid advice
  // the guard declines. Each is reported as a rejection naming the guard's rule, never as
  // carried out, and the count is the guard's own.
  EpisodeRunner runner(tinyRunner({"rsu_0"}, 60.0), [](int episode) {
    SessionOptions o = palcas::sim::test::sessionOnTiny("runner_guard" + std::to_string(episode), 11, 2000.0);
    o.guard.insertion_edge = true;
    o.guard.busy_speed_share = 0.0;  // busy zones would hand the CAVs back: this is about insertion
    o.guard.busy_leave_share = 0.0;
    return std::make_unique<SumoSession>(o);
  });
  std::string reason;
  ASSERT_TRUE(runner.lockstep().registerRsu("rsu_0", &reason));
  std::size_t advised = 0;
  ScriptedPort port(runner, [&](const SumoSession& s, EpisodeRunner& r) {
    auto array = answer("rsu_0", s.stepCount());
    if (s.stepCount() % 10 == 0)
      for (const VehicleRecord& v : s.vehicles())
        if (v.is_cav && v.edge == "main_0_warmup" && v.lane >= 1 && v.lane_change_target == 0) {
          advise(*array, v.id, v.lane < 3 ? LANE_LEFT : LANE_RIGHT);
          ++advised;
        }
    r.onAnswer(array);
  });
  runner.runEpisode(0, port);
  ASSERT_GT(advised, 20u) << "too few CAVs on the warm-up edge";
  const int declined = port.rejections[RejectionReason::kGuardInsertionEdge];
  EXPECT_GT(declined, 0);
  EXPECT_EQ(static_cast<std::uint64_t>(declined), runner.session().guardCounters().lane_changes_insertion_refused);
  EXPECT_NE(port.last_rejection.find("where SUMO inserts traffic"), std::string::npos) << port.last_rejection;
  std::size_t applied = 0;
  for (const auto& [id, steps] : port.applied_at) applied += steps.size();
  std::size_t rejected = 0;
  for (const auto& [why, n] : port.rejections) rejected += static_cast<std::size_t>(n);
  EXPECT_EQ(applied + rejected, advised) << "every advisory is carried out or rejected, once";
  EXPECT_EQ(port.rejections[RejectionReason::kNoSuchLane], 0) << "the tiny road's 3 lanes all exist on the warm-up edge";
}

namespace {

// One ACCELERATE for the first CAV in lane 1, then nothing (as if every later advisory were
// lost): the steps at which it was advised and at which its command ended.
std::pair<std::uint64_t, std::uint64_t> oneAdviceThenSilence(const std::string& name, bool channel,
                                                             double keep_advice_s, double accel_mps2 = 0.5,
                                                             bool keep_slowing_advice = true) {
  RunnerOptions options = tinyRunner({"rsu_0"}, 30.0);
  options.advisory_hold_steps = 10;
  options.v2x.enabled = channel;  // latency 0, nothing lost: only the hold differs
  options.v2x.rsu_range_m = std::numeric_limits<double>::infinity();
  options.v2x.keep_advice_s = keep_advice_s;
  options.v2x.keep_slowing_advice = keep_slowing_advice;
  EpisodeRunner runner(options, tinySession(name));
  std::string reason;
  EXPECT_TRUE(runner.lockstep().registerRsu("rsu_0", &reason));
  std::uint64_t advised_step = 0;
  bool advised = false;
  ScriptedPort port(runner, [&](const SumoSession& s, EpisodeRunner& r) {
    auto array = answer("rsu_0", s.stepCount());
    const auto lane_one = cavsInLaneOne(s);
    if (!advised && !lane_one.empty()) {
      advised = true;
      advised_step = s.stepCount();
      advise(*array, lane_one[0], ACCELERATE, accel_mps2);
    }
    r.onAnswer(array);
  });
  runner.runEpisode(0, port);
  EXPECT_TRUE(advised) << "no CAV in lane 1 within 30 s";
  std::uint64_t ended = 0;
  for (const auto& [step, in_force] : port.in_force_by_step)
    if (step > advised_step && in_force == 0) {
      ended = step;
      break;
    }
  return {advised_step, ended};
}

}  // namespace

TEST(EpisodeRunner, OverTheChannelACavKeepsItsLastAdviceThroughALostOne) {
  const auto [advised, ended] = oneAdviceThenSilence("runner_keep_on", true, 1.0);
  EXPECT_EQ(ended, advised + 20);  // 10 steps of hold + 1.0 s kept
  const auto [advised_off, ended_off] = oneAdviceThenSilence("runner_keep_zero", true, 0.0);
  EXPECT_EQ(ended_off, advised_off + 10);
  // Without the channel nothing is lost: the hold ends on time whatever keep_advice_s says.
  const auto [advised_none, ended_none] = oneAdviceThenSilence("runner_keep_nochannel", false, 1.0);
  EXPECT_EQ(ended_none, advised_none + 10);
}

TEST(EpisodeRunner, WithoutKeepSlowingAdviceOnlyAdviceThatDoesNotSlowIsKept) {
  // A slowing ACCELERATE ends on time; one that does not slow is kept as before.
  const auto [advised_slow, ended_slow] = oneAdviceThenSilence("runner_keep_slow", true, 1.0, -0.5, false);
  EXPECT_EQ(ended_slow, advised_slow + 10);
  const auto [advised_fast, ended_fast] = oneAdviceThenSilence("runner_keep_fast", true, 1.0, 0.5, false);
  EXPECT_EQ(ended_fast, advised_fast + 20);
  // keep_slowing_advice on: the slowing one is kept too.
  const auto [advised_both, ended_both] = oneAdviceThenSilence("runner_keep_slow_on", true, 1.0, -0.5, true);
  EXPECT_EQ(ended_both, advised_both + 20);
}

namespace {

// Every CAV on the mainline advised KEEP every second for 30 s, through a channel with
// 0.25 s latency and 30 % loss.
EpisodeRun keepThroughChannel(const std::string& name, std::uint64_t channel_seed) {
  RunnerOptions options = tinyRunner({"rsu_0"}, 30.0);
  options.v2x.enabled = true;
  options.v2x.advisory.latency_s = 0.25;
  options.v2x.advisory.loss_probability = 0.3;
  options.v2x.rsu_range_m = std::numeric_limits<double>::infinity();
  options.v2x.seed = channel_seed;
  EpisodeRunner runner(options, tinySession(name));
  std::string reason;
  EXPECT_TRUE(runner.lockstep().registerRsu("rsu_0", &reason));
  ScriptedPort port(runner, [](const SumoSession& s, EpisodeRunner& r) {
    auto array = answer("rsu_0", s.stepCount());
    if (s.stepCount() % 10 == 0)
      for (const VehicleRecord& v : s.vehicles())
        if (v.is_cav && v.part == palcas::RoadPart::kMainline) advise(*array, v.id, KEEP);
    r.onAnswer(array);
  });
  const EpisodeRun run = runner.runEpisode(0, port);
  int applied = 0;
  for (const auto& [id, steps] : port.applied_at)
    for (std::uint64_t k : steps) {
      EXPECT_EQ(k % 10, 3u) << id << " advised at a multiple of 10 steps, applied 3 steps later";
      ++applied;
    }
  EXPECT_EQ(static_cast<std::uint64_t>(applied),
            run.downlink.delivered - static_cast<std::uint64_t>(port.rejections[RejectionReason::kUnknownVehicle]));
  return run;
}

}  // namespace

TEST(EpisodeRunner, TheChannelDelaysAndDropsAdviceTheSameWayForTheSameSeed) {
  const EpisodeRun a = keepThroughChannel("runner_channel_a", 7);
  EXPECT_GT(a.downlink.sent, 100u);
  EXPECT_GT(a.downlink.lost, 0u);
  // Sent in the last 3 steps: still in flight at the end.
  EXPECT_LE(a.downlink.lost + a.downlink.delivered, a.downlink.sent);
  EXPECT_NEAR(static_cast<double>(a.downlink.lost) / a.downlink.sent, 0.3, 0.1);
  EXPECT_EQ(a.downlink.late, a.downlink.delivered);  // 0.25 s rounds up to 3 steps
  EXPECT_NEAR(a.downlink.meanAgeS(), 0.3, 1e-9);
  const EpisodeRun b = keepThroughChannel("runner_channel_b", 7);
  EXPECT_EQ(b.downlink.sent, a.downlink.sent);
  EXPECT_EQ(b.downlink.lost, a.downlink.lost);
  EXPECT_EQ(b.downlink.delivered, a.downlink.delivered);
  const EpisodeRun c = keepThroughChannel("runner_channel_c", 8);
  EXPECT_EQ(c.downlink.sent, a.downlink.sent);  // the same traffic (SUMO's seed) ...
  EXPECT_NE(c.downlink.lost, a.downlink.lost);  // ... another channel draw
}

TEST(EpisodeRunner, FreeRunningItTakesEveryAnswerAndStartsEpisodesAfresh) {
  EpisodeRunner runner(tinyRunner({}, 5.0), tinySession("runner_free"));
  int answers = 0;
  ScriptedPort port(runner, [&](const SumoSession& s, EpisodeRunner& r) {
    ++answers;
    r.onAnswer(answer("anyone", s.stepCount()));
  });
  EXPECT_EQ(runner.runEpisode(0, port).steps, 50u);
  EXPECT_EQ(answers, 50);  // answered in the actuation's receive: no lockstep wait
  runner.startEpisode(1);
  EXPECT_EQ(runner.session().stepCount(), 0u);
  EXPECT_EQ(runner.runEpisode(1, port).steps, 50u);
}

TEST(EpisodeRunner, RefusesBadOptionsNamingThem) {
  auto never = [](int) -> std::unique_ptr<SumoSession> { ADD_FAILURE() << "no session for bad options"; return nullptr; };
  RunnerOptions o = tinyRunner({}, 0.0);
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { EpisodeRunner r(o, never); }, "duration_s");
  o = tinyRunner({}, 10.0);
  o.metrics_period_s = std::nan("");
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { EpisodeRunner r(o, never); }, "metrics_period_s");
  o = tinyRunner({}, 10.0);
  o.trajectory_period_steps = 10;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { EpisodeRunner r(o, never); }, "episode_dir");
  o = tinyRunner({"rsu_0", "rsu_0"}, 10.0);
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { EpisodeRunner r(o, never); }, "rsu_0");
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { EpisodeRunner r(tinyRunner({}, 10.0), nullptr); }, "session factory");
}
