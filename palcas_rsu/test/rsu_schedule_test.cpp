// RsuSchedule without a master: the decision steps, what follows a decision in train and
// eval, the checkpoint period, and the learner thread's start / join.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>

#include "common/throws_naming.h"
#include "palcas_rsu/rsu_schedule.h"

using palcas::rsu::AfterDecision;
using palcas::rsu::RsuSchedule;
using palcas::rsu::RsuScheduleOptions;
using palcas_test::expectThrowNaming;

namespace {

RsuScheduleOptions training() {
  RsuScheduleOptions o;
  o.decision_period_steps = 10;
  o.train = true;
  o.reward_over_period = true;
  o.learner_thread = true;
  o.checkpoint_every_decisions = 3;
  o.checkpoint_dir_set = true;
  o.federation = true;
  return o;
}

}  // namespace

TEST(RsuSchedule, DecidesEveryPeriodFromStepZero) {
  RsuSchedule s(training());
  EXPECT_TRUE(s.decidesAt(0));
  EXPECT_FALSE(s.decidesAt(1));
  EXPECT_FALSE(s.decidesAt(9));
  EXPECT_TRUE(s.decidesAt(10));
  EXPECT_TRUE(s.decidesAt(120));
  RsuScheduleOptions every_step = training();
  every_step.decision_period_steps = 1;
  EXPECT_TRUE(RsuSchedule(every_step).decidesAt(7));
}

TEST(RsuSchedule, TrainingLearnsOnTheThreadTicksAndCheckpointsEveryPeriod) {
  RsuSchedule s(training());
  EXPECT_TRUE(s.observesBetweenDecisions());
  for (int n = 1; n <= 6; ++n) {
    const AfterDecision a = s.decided();
    EXPECT_FALSE(a.learn_inline);
    EXPECT_TRUE(a.learn_on_thread);
    EXPECT_TRUE(a.federation_tick);
    EXPECT_EQ(a.checkpoint, n % 3 == 0) << n;
  }
  EXPECT_EQ(s.decisions(), 6u);
}

TEST(RsuSchedule, WithoutALearnerThreadLearningIsInline) {
  RsuScheduleOptions o = training();
  o.learner_thread = false;
  const AfterDecision a = RsuSchedule(o).decided();
  EXPECT_TRUE(a.learn_inline);
  EXPECT_FALSE(a.learn_on_thread);
}

TEST(RsuSchedule, EvalNeitherObservesTicksNorCheckpoints) {
  RsuScheduleOptions o = training();
  o.train = false;
  RsuSchedule s(o);
  EXPECT_FALSE(s.observesBetweenDecisions());
  for (int n = 1; n <= 3; ++n) {
    const AfterDecision a = s.decided();
    EXPECT_FALSE(a.learn_on_thread);
    EXPECT_FALSE(a.federation_tick);
    EXPECT_FALSE(a.checkpoint);
  }
  o.learner_thread = false;  // the controller's learn() is a no-op in eval: called as always
  EXPECT_TRUE(RsuSchedule(o).decided().learn_inline);
}

TEST(RsuSchedule, CheckpointsNeedADirectoryAndAPeriod) {
  for (int variant = 0; variant < 3; ++variant) {
    RsuScheduleOptions o = training();
    o.checkpoint_every_decisions = 1;
    if (variant == 0) o.checkpoint_dir_set = false;
    if (variant == 1) o.checkpoint_every_decisions = 0;  // only at shutdown
    if (variant == 2) o.reward_over_period = false;      // unrelated: still due
    EXPECT_EQ(RsuSchedule(o).decided().checkpoint, variant == 2) << variant;
  }
  RsuScheduleOptions no_federation = training();
  no_federation.federation = false;
  EXPECT_FALSE(RsuSchedule(no_federation).decided().federation_tick);
}

TEST(RsuSchedule, TheLearnerRunsUntilFinishedAndItsErrorReachesTheNode) {
  RsuSchedule s(training());
  std::atomic<int> runs{0};
  s.startLearning([&] { ++runs; });
  EXPECT_TRUE(s.learning());
  expectThrowNaming<std::logic_error>([&] { s.startLearning([] {}); }, "still runs");
  s.finishLearning();
  EXPECT_FALSE(s.learning());
  EXPECT_EQ(runs.load(), 1);
  s.finishLearning();  // nothing running: returns
  s.startLearning([] { throw std::runtime_error("gradient step failed"); });
  expectThrowNaming<std::runtime_error>([&] { s.finishLearning(); }, "gradient step failed");
  EXPECT_FALSE(s.learning());
}

TEST(RsuSchedule, RefusesBadOptionsNamingThem) {
  RsuScheduleOptions o = training();
  o.decision_period_steps = 0;
  expectThrowNaming<std::invalid_argument>([&] { RsuSchedule s(o); }, "decision_period_steps = 0");
  o = training();
  o.checkpoint_every_decisions = -1;
  expectThrowNaming<std::invalid_argument>([&] { RsuSchedule s(o); }, "checkpoint_every_decisions = -1");
}
