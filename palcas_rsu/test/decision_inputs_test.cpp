// DecisionInputs without a master: a decision waits for its step's events and for each
// neighbour's cluster state of the previous round, whatever order they arrive in; a
// neighbour that did not deliver is presumed down (one wait) until heard again.
#include <gtest/gtest.h>

#include <stdexcept>

#include "common/throws_naming.h"
#include "palcas_rsu/decision_inputs.h"

using palcas::rsu::DecisionInputs;
using palcas_test::expectThrowNaming;

namespace {
constexpr std::uint64_t PERIOD = 10;
}

TEST(DecisionInputs, TheFirstDecisionNeedsOnlyItsEvents) {
  DecisionInputs in(1, 3, true, PERIOD);
  EXPECT_EQ(in.missing(0), std::vector<std::string>{"events of step 0"});
  in.eventsArrived(0);
  EXPECT_TRUE(in.ready(0));
}

TEST(DecisionInputs, ALaterDecisionWaitsForBothNeighboursOfThePreviousRound) {
  DecisionInputs in(1, 3, true, PERIOD);
  in.eventsArrived(20);
  EXPECT_EQ(in.missing(20), (std::vector<std::string>{"cluster state of cluster 0 for step 10",
                                                       "cluster state of cluster 2 for step 10"}));
  in.clusterStateArrived(0, 0);  // an older round does not do
  in.clusterStateArrived(2, 10);
  EXPECT_EQ(in.missing(20), std::vector<std::string>{"cluster state of cluster 0 for step 10"});
  in.clusterStateArrived(0, 10);
  EXPECT_TRUE(in.ready(20));
  // A neighbour that already decided this round is as good (the decision uses what is
  // stamped before it; PeerStates sees to that).
  in.eventsArrived(30);
  in.clusterStateArrived(0, 30);
  in.clusterStateArrived(2, 20);
  EXPECT_TRUE(in.ready(30));
}

TEST(DecisionInputs, EventsOfAnEarlierStepDoNotDoALaterStepOfTheRoundDoes) {
  DecisionInputs in(0, 2, true, PERIOD);
  in.clusterStateArrived(1, 0);
  in.eventsArrived(9);  // a step with events between two decisions
  EXPECT_EQ(in.missing(10), std::vector<std::string>{"events of step 10"});
  in.eventsArrived(10);
  EXPECT_TRUE(in.ready(10));
  // The bridge went on without this RSU's answer: the arrays of the steps after are in too.
  in.eventsArrived(13);
  EXPECT_TRUE(in.ready(10));
}

TEST(DecisionInputs, ClustersThatAreNotNeighboursAreNotWaitedFor) {
  DecisionInputs in(0, 4, true, PERIOD);  // neighbour: 1 only
  in.eventsArrived(10);
  in.clusterStateArrived(2, 0);
  in.clusterStateArrived(3, 0);
  EXPECT_EQ(in.missing(10), std::vector<std::string>{"cluster state of cluster 1 for step 0"});
}

TEST(DecisionInputs, WithoutI2IOnlyTheEventsCount) {
  DecisionInputs in(1, 3, false, PERIOD);
  in.eventsArrived(50);
  EXPECT_TRUE(in.ready(50));
  DecisionInputs whole_road(0, 1, true, PERIOD);  // one zone: no neighbour
  whole_road.eventsArrived(50);
  EXPECT_TRUE(whole_road.ready(50));
}

TEST(DecisionInputs, ADeadNeighbourCostsOneWaitUntilHeardAgain) {
  DecisionInputs in(1, 3, true, PERIOD);
  in.eventsArrived(10);
  in.clusterStateArrived(0, 0);
  EXPECT_FALSE(in.ready(10));  // cluster 2 is silent
  EXPECT_EQ(in.gaveUp(10), std::vector<int>{2});
  EXPECT_EQ(in.presumedDown(), std::vector<int>{2});
  EXPECT_TRUE(in.ready(10));
  in.eventsArrived(20);
  in.clusterStateArrived(0, 10);
  EXPECT_TRUE(in.ready(20));  // not waited for again
  in.clusterStateArrived(2, 20);  // back
  EXPECT_TRUE(in.presumedDown().empty());
  in.eventsArrived(30);
  in.clusterStateArrived(0, 20);
  EXPECT_TRUE(in.ready(30)) << "its state of step 20 is the previous round's";
  in.eventsArrived(40);
  EXPECT_EQ(in.missing(40), (std::vector<std::string>{"cluster state of cluster 0 for step 30",
                                                       "cluster state of cluster 2 for step 30"}));
}

TEST(DecisionInputs, WhatArrivedInTheLastEpisodeDoesNotCountInTheNext) {
  DecisionInputs in(0, 2, true, PERIOD);
  in.eventsArrived(5000);
  in.clusterStateArrived(1, 4990);
  EXPECT_TRUE(in.ready(5000));
  // The step counter starts again: step 0 and 10 of the new episode.
  EXPECT_EQ(in.missing(0), std::vector<std::string>{"events of step 0"});
  in.eventsArrived(10);
  EXPECT_EQ(in.missing(10), std::vector<std::string>{"cluster state of cluster 1 for step 0"});
  in.clusterStateArrived(1, 0);
  EXPECT_TRUE(in.ready(10));
}

TEST(DecisionInputs, RefusesABadZoneOrPeriod) {
  expectThrowNaming<std::invalid_argument>([] { DecisionInputs(3, 3, true, PERIOD); }, "cluster 3");
  expectThrowNaming<std::invalid_argument>([] { DecisionInputs(-1, 3, true, PERIOD); }, "cluster -1");
  expectThrowNaming<std::invalid_argument>([] { DecisionInputs(0, 3, true, 0); }, "decision_period_steps");
}

TEST(DecisionInputs, AnEvaluatingRsuDoesNotWaitForEvents) {
  // Evaluating, a decision uses no events (RsuNode::advise), so none is waited for; the
  // neighbours of the previous round still are.
  DecisionInputs in(1, 3, true, PERIOD, false);
  EXPECT_TRUE(in.ready(0));
  EXPECT_EQ(in.missing(20), (std::vector<std::string>{"cluster state of cluster 0 for step 10",
                                                       "cluster state of cluster 2 for step 10"}));
  in.clusterStateArrived(0, 10);
  in.clusterStateArrived(2, 10);
  EXPECT_TRUE(in.ready(20));
  in.eventsArrived(20);  // still taken, changes nothing
  EXPECT_TRUE(in.ready(20));
}
