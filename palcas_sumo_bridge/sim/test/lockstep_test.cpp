#include "palcas_sim/lockstep.h"

#include <gtest/gtest.h>

using palcas::sim::Lockstep;

TEST(Lockstep, WaitsForEveryRegisteredRsu) {
  Lockstep ls({"rsu_0", "rsu_1"}, 3);
  EXPECT_TRUE(ls.enabled());
  EXPECT_FALSE(ls.allRegistered());
  std::string reason;
  EXPECT_TRUE(ls.registerRsu("rsu_0", &reason));
  EXPECT_EQ(ls.unregistered(), std::vector<std::string>{"rsu_1"});
  EXPECT_TRUE(ls.registerRsu("rsu_1", &reason));
  EXPECT_TRUE(ls.allRegistered());
  ls.beginStep(0);
  EXPECT_FALSE(ls.complete());
  EXPECT_EQ(ls.onAnswer("rsu_1", 0), Lockstep::Answer::kAccepted);
  EXPECT_EQ(ls.waitingFor(), std::vector<std::string>{"rsu_0"});
  EXPECT_EQ(ls.onAnswer("rsu_0", 0), Lockstep::Answer::kAccepted);
  EXPECT_TRUE(ls.complete());
  EXPECT_TRUE(ls.endStep(nullptr).empty());
  EXPECT_EQ(ls.lateSteps(), 0u);
}

TEST(Lockstep, RejectsUnknownStaleAndDuplicateAnswers) {
  Lockstep ls({"rsu_0"}, 3);
  std::string reason;
  EXPECT_FALSE(ls.registerRsu("rsu_9", &reason));
  EXPECT_NE(reason.find("rsu_9"), std::string::npos);
  ls.registerRsu("rsu_0", &reason);
  ls.beginStep(5);
  EXPECT_EQ(ls.onAnswer("rsu_9", 5), Lockstep::Answer::kUnknownRsu);
  EXPECT_EQ(ls.onAnswer("rsu_0", 4), Lockstep::Answer::kStale);
  EXPECT_EQ(ls.lateAnswers("rsu_0"), 1u);
  EXPECT_FALSE(ls.complete());
  EXPECT_EQ(ls.onAnswer("rsu_0", 5), Lockstep::Answer::kAccepted);
  EXPECT_EQ(ls.onAnswer("rsu_0", 5), Lockstep::Answer::kDuplicate);
}

TEST(Lockstep, LateRsuIsCountedThenLostThenRevived) {
  Lockstep ls({"rsu_0", "rsu_1"}, 2);
  std::string reason;
  ls.registerRsu("rsu_0", &reason);
  ls.registerRsu("rsu_1", &reason);
  std::vector<std::string> lost;
  // Step 0: rsu_1 misses its deadline (1st miss): late, still live.
  ls.beginStep(0);
  ls.onAnswer("rsu_0", 0);
  EXPECT_EQ(ls.endStep(&lost), std::vector<std::string>{"rsu_1"});
  EXPECT_TRUE(lost.empty());
  EXPECT_TRUE(ls.isLive("rsu_1"));
  // Step 1: 2nd consecutive miss -> lost; no longer waited for.
  ls.beginStep(1);
  ls.onAnswer("rsu_0", 1);
  ls.endStep(&lost);
  EXPECT_EQ(lost, std::vector<std::string>{"rsu_1"});
  EXPECT_FALSE(ls.isLive("rsu_1"));
  EXPECT_EQ(ls.lostRsus(), std::vector<std::string>{"rsu_1"});
  EXPECT_EQ(ls.lateSteps(), 2u);
  ls.beginStep(2);
  ls.onAnswer("rsu_0", 2);
  EXPECT_TRUE(ls.complete());  // the lost RSU is not waited for
  lost.clear();
  EXPECT_TRUE(ls.endStep(&lost).empty());
  EXPECT_EQ(ls.lateSteps(), 2u);
  // Step 3: it answers again and is live once more.
  ls.beginStep(3);
  EXPECT_EQ(ls.onAnswer("rsu_1", 3), Lockstep::Answer::kAccepted);
  EXPECT_TRUE(ls.isLive("rsu_1"));
  EXPECT_FALSE(ls.complete());  // now rsu_0 is waited for
  EXPECT_EQ(ls.takeRevived(), std::vector<std::string>{"rsu_1"});
  EXPECT_TRUE(ls.takeRevived().empty());
}

TEST(Lockstep, ALostRsuAnsweringARecentClosedStepIsWaitedForAgain) {
  Lockstep ls({"rsu_0"}, 1);
  std::string reason;
  ls.registerRsu("rsu_0", &reason);
  std::vector<std::string> lost;
  ls.beginStep(0);
  ls.endStep(&lost);  // lost after one miss
  ASSERT_FALSE(ls.isLive("rsu_0"));
  // Its link comes back: answers arrive after their step closed (it is not waited for).
  ls.beginStep(50);
  ls.endStep(&lost);
  EXPECT_EQ(ls.onAnswer("rsu_0", 30), Lockstep::Answer::kStale);  // 20 steps old: backlog
  EXPECT_FALSE(ls.isLive("rsu_0"));
  EXPECT_EQ(ls.onAnswer("rsu_0", 45), Lockstep::Answer::kStale);  // recent: it is back
  EXPECT_TRUE(ls.isLive("rsu_0"));
  EXPECT_EQ(ls.takeRevived(), std::vector<std::string>{"rsu_0"});
  ls.beginStep(51);
  EXPECT_FALSE(ls.complete());  // waited for again
  EXPECT_EQ(ls.onAnswer("rsu_0", 51), Lockstep::Answer::kAccepted);
  EXPECT_TRUE(ls.complete());
}

TEST(Lockstep, NoRsusMeansNoLockstep) {
  Lockstep ls({}, 1);
  EXPECT_FALSE(ls.enabled());
  EXPECT_TRUE(ls.allRegistered());
  ls.beginStep(0);
  EXPECT_TRUE(ls.complete());
}

TEST(Lockstep, RejectsBadConfiguration) {
  EXPECT_THROW(Lockstep({"a", "a"}, 1), std::invalid_argument);
  EXPECT_THROW(Lockstep({""}, 1), std::invalid_argument);
  EXPECT_THROW(Lockstep({"a"}, 0), std::invalid_argument);
}

TEST(Lockstep, AnRsuWithAnAnswerPeriodIsWaitedForOnlyOnItsSteps) {
  Lockstep ls({"every", "tenth"}, 2);
  std::string reason;
  ASSERT_TRUE(ls.registerRsu("every", &reason, 0));  // 0 = every step, as before the period
  ASSERT_TRUE(ls.registerRsu("tenth", &reason, 10));
  std::vector<std::string> lost;
  for (std::uint64_t step = 0; step < 25; ++step) {
    ls.beginStep(step);
    const bool tenth_due = step % 10 == 0;
    const std::vector<std::string> waited =
        tenth_due ? std::vector<std::string>{"every", "tenth"} : std::vector<std::string>{"every"};
    EXPECT_EQ(ls.waitingFor(), waited) << "step " << step;
    ls.onAnswer("every", step);
    EXPECT_EQ(ls.complete(), !tenth_due) << "step " << step;
    if (step == 0) ls.onAnswer("tenth", step);
    // Steps 10 and 20 go unanswered: two misses of due steps, not the 15 steps between.
    const std::vector<std::string> late = ls.endStep(&lost);
    EXPECT_EQ(late.size(), step == 10 || step == 20 ? 1u : 0u) << "step " << step;
    EXPECT_EQ(ls.isLive("tenth"), step < 20) << "step " << step;
  }
  EXPECT_EQ(lost, std::vector<std::string>{"tenth"});
  EXPECT_EQ(ls.lateSteps(), 2u);
}

TEST(Lockstep, RegisteringDuringAStepIsDueOnlyIfTheStepIsItsOwn) {
  Lockstep ls({"rsu_0"}, 3);
  std::string reason;
  ls.beginStep(7);
  ASSERT_TRUE(ls.registerRsu("rsu_0", &reason, 10));
  EXPECT_TRUE(ls.complete());  // step 7 is not one of its steps
  ls.endStep(nullptr);
  ls.beginStep(10);
  EXPECT_FALSE(ls.complete());
  EXPECT_EQ(ls.onAnswer("rsu_0", 10), Lockstep::Answer::kAccepted);
  EXPECT_TRUE(ls.complete());
}

TEST(Lockstep, AnRsuMayDecideOnlyOnItsStepsOnceEveryRsuIsRegistered) {
  EXPECT_TRUE(Lockstep({}, 1).mayDecideOnOpenStep());  // free-running: periods unknown
  Lockstep ls({"a", "b"}, 3);
  std::string reason;
  ls.beginStep(3);
  EXPECT_TRUE(ls.mayDecideOnOpenStep());  // nobody registered: any step may be a decision
  ASSERT_TRUE(ls.registerRsu("a", &reason, 10));
  EXPECT_TRUE(ls.mayDecideOnOpenStep());  // "b" still unknown
  ASSERT_TRUE(ls.registerRsu("b", &reason, 5));
  EXPECT_FALSE(ls.mayDecideOnOpenStep());
  ls.endStep(nullptr);
  for (std::uint64_t step = 4; step <= 20; ++step) {
    ls.beginStep(step);
    EXPECT_EQ(ls.mayDecideOnOpenStep(), step % 5 == 0) << "step " << step;
    ls.endStep(nullptr);
  }
}
