#include "palcas_rsu/peer_states.h"

#include <gtest/gtest.h>

#include <cmath>

using palcas::rsu::PeerStates;

TEST(PeerStates, GlobalDensitiesComeFromTheNeighbours) {
  PeerStates peers(1, 5.0);
  peers.update(0, "rsu_0", 20.0, 10.0);
  peers.update(2, "rsu_2", 35.5, 10.5);
  peers.update(3, "rsu_3", 99.0, 10.5);  // not a neighbour of cluster 1
  peers.update(0, "rsu_0", 77.0, 12.0);  // stamped at the decision time itself: not used yet
  const auto g = peers.global(42.0, 12.0);
  EXPECT_DOUBLE_EQ(g.upstream, 20.0);
  EXPECT_DOUBLE_EQ(g.own, 42.0);
  EXPECT_DOUBLE_EQ(g.downstream, 35.5);
}

TEST(PeerStates, MissingAndStalePeersAreUnknown) {
  PeerStates peers(0, 5.0);
  peers.update(1, "rsu_1", 30.0, 10.0);
  auto g = peers.global(1.0, 15.0);  // 15 - 10 = 5 s old: still fresh (<= 5)
  EXPECT_TRUE(std::isnan(peers.global(1.0, 10.0).downstream));  // nothing from before t = 10
  EXPECT_TRUE(std::isnan(g.upstream));  // cluster -1 does not exist
  EXPECT_DOUBLE_EQ(g.downstream, 30.0);
  EXPECT_TRUE(peers.stalePeers(15.0).empty());
  g = peers.global(1.0, 15.1);  // 5.1 s old: stale
  EXPECT_TRUE(std::isnan(g.downstream));
  EXPECT_EQ(peers.stalePeers(15.1), std::vector<std::string>{"rsu_1"});
  peers.update(1, "rsu_1", 31.0, 15.0);  // heard again
  EXPECT_DOUBLE_EQ(peers.global(1.0, 15.1).downstream, 31.0);
  EXPECT_DOUBLE_EQ(peers.global(1.0, 15.0).downstream, 30.0);  // the t = 15 sample is not before 15
}

TEST(PeerStates, KeepsTheNewerOfOutOfOrderUpdates) {
  PeerStates peers(0, 5.0);
  peers.update(1, "rsu_1", 30.0, 10.0);
  peers.update(1, "rsu_1", 12.0, 9.0);  // older: ignored
  EXPECT_DOUBLE_EQ(peers.global(0.0, 10.5).downstream, 30.0);
}

TEST(PeerStates, RejectsBadInputAndKeepsWhatItHeld) {
  EXPECT_THROW(PeerStates(-1, 1.0), std::invalid_argument);
  EXPECT_THROW(PeerStates(0, 0.0), std::invalid_argument);
  PeerStates peers(0, 5.0);
  peers.update(1, "rsu_1", 30.0, 10.0);
  EXPECT_THROW(peers.update(1, "rsu_1", std::nan(""), 11.0), std::invalid_argument);
  EXPECT_THROW(peers.update(1, "rsu_1", -3.0, 11.0), std::invalid_argument);
  EXPECT_THROW(peers.update(-2, "rsu_x", 3.0, 11.0), std::invalid_argument);
  EXPECT_DOUBLE_EQ(peers.global(0.0, 11.0).downstream, 30.0);
}
