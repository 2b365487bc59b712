#include "palcas_core/federation/federation_server.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <limits>

#include "palcas_core/learning/nn/serialization.h"

using namespace palcas;

namespace {

ModelBlob blob(std::vector<float> values, const std::string& layout = "L") {
  return ModelBlob{layout, nn::fnv1a64(layout), std::move(values)};
}

// Expected RSUs a, b, c; quorum default (2 of 3); deadline 10 s; liveness 100 s.
FederationOptions abcOptions() {
  FederationOptions o;
  o.expected_rsus = {"a", "b", "c"};
  o.round_deadline_s = 10.0;
  o.liveness_timeout_s = 100.0;
  o.max_update_norm_ratio = 0.0;  // these tests move the model far; the bound has its own
  return o;
}

// A server with global model v1 = [1, 2, 3] and a, b, c all heard from at t = 0.
FederationServer liveAbcServer(FederationOptions o = abcOptions()) {
  FederationServer s(std::move(o));
  s.initialize(blob({1, 2, 3}));
  for (const char* id : {"a", "b", "c"}) s.fetch(id, 0, 0.0);
  return s;
}

std::string tempDir(const std::string& name) {
  const std::string dir = testing::TempDir() + "/palcas_fed_" + name;
  std::filesystem::remove_all(dir);
  return dir;
}

template <typename E, typename F>
void expectThrowMentioning(F f, const std::string& needle) {
  palcas_test::expectThrowNaming<E>(f, needle);
}

}  // namespace

TEST(FederationOptions, DefaultQuorumIsTwoThirdsRoundedUp) {
  // ceil(2n/3): n=1 -> 1, n=2 -> 2, n=3 -> 2, n=4 -> ceil(8/3) = 3, n=6 -> 4.
  EXPECT_EQ(FederationOptions::defaultQuorum(1), 1u);
  EXPECT_EQ(FederationOptions::defaultQuorum(2), 2u);
  EXPECT_EQ(FederationOptions::defaultQuorum(3), 2u);
  EXPECT_EQ(FederationOptions::defaultQuorum(4), 3u);
  EXPECT_EQ(FederationOptions::defaultQuorum(6), 4u);
  FederationOptions o = abcOptions();
  EXPECT_EQ(o.effectiveQuorum(), 2u);
  o.quorum = 3;
  EXPECT_EQ(o.effectiveQuorum(), 3u);
}

TEST(FederationOptions, RejectsInvalidFieldsNamingThem) {
  auto expectBad = [](auto mutate, const std::string& needle) {
    FederationOptions o = abcOptions();
    mutate(o);
    expectThrowMentioning<std::invalid_argument>([&] { FederationServer s(o); }, needle);
  };
  expectBad([](FederationOptions& o) { o.expected_rsus.clear(); }, "expected_rsus is empty");
  expectBad([](FederationOptions& o) { o.expected_rsus = {"a", "b", "a"}; }, "'a' twice");
  expectBad([](FederationOptions& o) { o.expected_rsus = {"a", ""}; }, "empty id");
  expectBad([](FederationOptions& o) { o.quorum = 4; }, "quorum = 4");
  expectBad([](FederationOptions& o) { o.round_deadline_s = 0; }, "round_deadline_s");
  expectBad([](FederationOptions& o) { o.round_deadline_s = NAN; }, "round_deadline_s");
  expectBad([](FederationOptions& o) { o.liveness_timeout_s = NAN; }, "liveness_timeout_s");
  expectBad([](FederationOptions& o) { o.liveness_timeout_s = -1; }, "liveness_timeout_s");
  expectBad([](FederationOptions& o) { o.max_samples = 0; }, "max_samples");
}

TEST(FederationServer, InitializeStartsAtVersionOneRoundOne) {
  FederationServer s(abcOptions());
  EXPECT_THROW(s.submit("a", 1, 1, blob({1, 2, 3}), 1, 0.0), std::logic_error);
  EXPECT_THROW(s.poll(0.0), std::logic_error);
  EXPECT_THROW(s.fetch("a", 1, 0.0), std::logic_error);
  expectThrowMentioning<std::invalid_argument>([&] { s.initialize(blob({1, NAN})); }, "value 1");
  expectThrowMentioning<std::invalid_argument>([&] { s.initialize(blob({})); }, "no values");
  EXPECT_EQ(s.globalModel(), nullptr);  // failed initialize left it uninitialized
  s.initialize(blob({1, 2, 3}));
  EXPECT_EQ(s.round(), 1u);
  EXPECT_EQ(s.globalVersion(), 1u);
  const FetchResult f = s.fetch("a", 1, 0.0);
  ASSERT_TRUE(f.available);
  EXPECT_EQ(f.model->values, (std::vector<float>{1, 2, 3}));
  expectThrowMentioning<std::invalid_argument>([&] { s.poll(NAN); }, "now_s");
}

TEST(FederationServer, IdenticalModelsAverageToThatModel) {
  FederationServer s = liveAbcServer();
  const std::vector<float> m{0.1f, -3.7f, 12345.678f};
  s.submit("a", 1, 1, blob(m), 5, 1.0);
  s.submit("b", 1, 1, blob(m), 70, 1.0);
  s.submit("c", 1, 1, blob(m), 1000, 1.0);
  ASSERT_TRUE(s.poll(1.0));
  EXPECT_EQ(s.globalModel()->values, m);
}

TEST(FederationServer, WeightsFollowTheSampleCounts) {
  FederationServer s = liveAbcServer();
  s.submit("a", 1, 1, blob({4, -2, 1}), 1, 1.0);
  s.submit("b", 1, 1, blob({8, 2, 0}), 3, 1.0);
  s.submit("c", 1, 1, blob({0, 0, 0}), 4, 1.0);
  ASSERT_TRUE(s.poll(1.0));
  // n = 1 + 3 + 4 = 8: weights 1/8, 3/8, 4/8.
  // [4/8 + 24/8 + 0, -2/8 + 6/8 + 0, 1/8 + 0 + 0] = [3.5, 0.5, 0.125]
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{3.5f, 0.5f, 0.125f}));
  EXPECT_EQ(s.lastRound().sample_counts, (std::map<std::string, uint64_t>{{"a", 1}, {"b", 3}, {"c", 4}}));
}

TEST(FederationServer, ClosesWhenEveryLiveRsuSubmitted) {
  FederationServer s = liveAbcServer();
  EXPECT_FALSE(s.poll(0.5));  // nothing submitted: never closes empty
  EXPECT_TRUE(s.submit("a", 1, 1, blob({4, -2, 1}), 1, 1.0).accepted);
  EXPECT_TRUE(s.submit("b", 1, 1, blob({8, 2, 0}), 3, 1.0).accepted);
  EXPECT_FALSE(s.poll(1.0));  // c is live and has not submitted; deadline (10 s) not reached
  EXPECT_TRUE(s.submit("c", 1, 1, blob({0, 0, 0}), 4, 2.0).accepted);
  ASSERT_TRUE(s.poll(2.0));
  EXPECT_FALSE(s.lastRound().on_deadline);
  EXPECT_TRUE(s.lastRound().aggregated);
  EXPECT_EQ(s.lastRound().round, 1u);
  EXPECT_EQ(s.lastRound().duration_s, 1.0);  // first submission at 1.0, closed at 2.0
  EXPECT_EQ(s.lastRound().bytes_in, 36u);    // 3 models x 3 values x 4 bytes
  EXPECT_EQ(s.round(), 2u);
  EXPECT_EQ(s.globalVersion(), 2u);
  EXPECT_TRUE(s.status().submitted.empty());
}

TEST(FederationServer, DoesNotCloseOnDeadlineBelowQuorum) {
  FederationServer s = liveAbcServer();
  s.submit("a", 1, 1, blob({4, -2, 1}), 1, 0.0);
  EXPECT_FALSE(s.poll(10.0));  // deadline reached (10 - 0 >= 10) but 1 < quorum 2
  EXPECT_FALSE(s.poll(50.0));
  EXPECT_EQ(s.globalVersion(), 1u);
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{1, 2, 3}));
  // b arrives late: quorum reached, deadline long past -> closes at once, c absent.
  s.submit("b", 1, 1, blob({8, 2, 0}), 3, 51.0);
  ASSERT_TRUE(s.poll(51.0));
  EXPECT_TRUE(s.lastRound().on_deadline);
  EXPECT_EQ(s.lastRound().duration_s, 51.0);  // from a's submission at 0
}

TEST(FederationServer, ClosesOnDeadlineWithQuorumWithoutTheMissingRsu) {
  FederationServer s = liveAbcServer();
  s.submit("a", 1, 1, blob({4, -2, 1}), 1, 2.0);
  s.submit("b", 1, 1, blob({8, 2, 0}), 3, 5.0);
  EXPECT_FALSE(s.poll(11.9));  // 11.9 - 2.0 = 9.9 < 10 and c (heard at 0) is live
  ASSERT_TRUE(s.poll(12.0));   // 12.0 - 2.0 = 10 >= 10, 2 submissions >= quorum 2
  EXPECT_TRUE(s.lastRound().on_deadline);
  // c is simply absent: n = 1 + 3, [0.25*4 + 0.75*8, 0.25*(-2) + 0.75*2, 0.25*1] = [7, 1, 0.25]
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{7.0f, 1.0f, 0.25f}));
  EXPECT_EQ(s.lastRound().sample_counts.count("c"), 0u);
}

TEST(FederationServer, EveryRejectionLeavesTheGlobalModelUnchanged) {
  FederationOptions o = abcOptions();
  o.max_samples = 1000;
  FederationServer s = liveAbcServer(o);
  ASSERT_TRUE(s.submit("a", 1, 1, blob({4, -2, 1}), 1, 1.0).accepted);
  struct Case {
    std::string rsu;
    uint32_t round, base;
    ModelBlob model;
    uint64_t n;
    Rejection why;
    std::string needle;
  };
  ModelBlob bad_checksum = blob({1, 1, 1});
  bad_checksum.layout_checksum += 1;
  const std::vector<Case> cases{
      {"z", 1, 1, blob({1, 1, 1}), 1, Rejection::kUnknownRsu, "RSU 'z'"},
      {"b", 0, 1, blob({1, 1, 1}), 1, Rejection::kWrongRound, "round 0 is not the open round 1"},
      {"b", 2, 1, blob({1, 1, 1}), 1, Rejection::kWrongRound, "round 2"},
      {"b", 1, 0, blob({1, 1, 1}), 1, Rejection::kStaleBaseVersion, "global version 0"},
      {"a", 1, 1, blob({9, 9, 9}), 1, Rejection::kDuplicate, "'a' already submitted"},
      {"b", 1, 1, blob({1, 1, 1}), 0, Rejection::kBadSampleCount, "n_k = 0"},
      {"b", 1, 1, blob({1, 1, 1}), 1001, Rejection::kBadSampleCount, "n_k = 1001"},
      {"b", 1, 1, blob({1, 1, 1}, "other"), 1, Rejection::kLayoutMismatch, "layout 'other'"},
      {"b", 1, 1, bad_checksum, 1, Rejection::kLayoutMismatch, "layout checksum"},
      {"b", 1, 1, blob({1, 1}), 1, Rejection::kWrongValueCount, "2 values"},
      {"b", 1, 1, blob({1, 1, NAN}), 1, Rejection::kNonFinite, "value 2 is not finite"},
      {"b", 1, 1, blob({INFINITY, 1, 1}), 1, Rejection::kNonFinite, "value 0"},
  };
  std::map<std::string, uint64_t> expected_counts = s.status().rejected_by_reason;
  for (const Case& c : cases) {
    const SubmitResult r = s.submit(c.rsu, c.round, c.base, c.model, c.n, 2.0);
    EXPECT_FALSE(r.accepted) << c.needle;
    EXPECT_EQ(r.rejection, c.why) << c.needle;
    EXPECT_NE(r.reason.find(c.needle), std::string::npos) << r.reason;
    EXPECT_NE(r.reason.find(rejectionName(c.why)), std::string::npos) << r.reason;
    ++expected_counts[rejectionName(c.why)];
    EXPECT_EQ(s.status().rejected_by_reason, expected_counts);
    EXPECT_EQ(s.status().submitted, std::vector<std::string>{"a"});
    EXPECT_EQ(s.globalModel()->values, (std::vector<float>{1, 2, 3}));
    EXPECT_EQ(s.globalVersion(), 1u);
  }
  EXPECT_EQ(s.status().bytes_in_round, 12u);  // only a's accepted 3 values x 4 bytes
  // The duplicate did not replace a's model: b, c join and the round closes on a's values.
  s.submit("b", 1, 1, blob({4, -2, 1}), 1, 3.0);
  s.submit("c", 1, 1, blob({4, -2, 1}), 1, 3.0);
  ASSERT_TRUE(s.poll(3.0));
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{4, -2, 1}));
}

TEST(FederationServer, APoisonedUpdateIsRefusedCountedAndLeavesTheModel) {
  FederationOptions o = abcOptions();
  o.max_update_norm_ratio = 5.0;  // the default
  o.max_samples = FEDAVG_MAX_SAMPLES_DEFAULT;
  FederationServer s = liveAbcServer(o);  // global [1, 2, 3], norm 3.74
  // The attack: an expected RSU's name, every value 1e30, n_k 1e9.
  const SubmitResult r = s.submit("a", 1, 1, blob({1e30f, 1e30f, 1e30f}), 1000000000ULL, 1.0);
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.rejection, Rejection::kUpdateTooLarge);
  EXPECT_NE(r.reason.find("above the bound 5"), std::string::npos) << r.reason;
  EXPECT_EQ(s.status().rejected_by_reason.at("update_too_large"), 1u);
  // A scaled update just over the bound is refused too; one just under is accepted.
  EXPECT_FALSE(s.submit("b", 1, 1, blob({1 + 20.0f, 2, 3}), 1, 1.0).accepted);  // 20 / 3.74 = 5.3
  EXPECT_TRUE(s.submit("b", 1, 1, blob({1 + 18.0f, 2, 3}), 1, 1.0).accepted);   // 4.8
  EXPECT_TRUE(s.submit("c", 1, 1, blob({1, 2, 3}), 1, 1.0).accepted);
  EXPECT_TRUE(s.submit("a", 1, 1, blob({1, 2, 3}), 1, 1.0).accepted);  // a may still submit
  ASSERT_TRUE(s.poll(1.0));
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{7, 2, 3}));  // (19 + 1 + 1) / 3
}

TEST(FederationServer, MedianAndTrimmedMeanKeepOneOutlierOut) {
  for (auto how : {FederationOptions::Aggregation::kMedian, FederationOptions::Aggregation::kTrimmedMean}) {
    FederationOptions o = abcOptions();
    o.aggregation = how;
    o.trim_fraction = 0.34;  // 3 models: drop 1 at each end = the median
    FederationServer s = liveAbcServer(o);
    s.submit("a", 1, 1, blob({1, 2, 3}), 1, 1.0);
    s.submit("b", 1, 1, blob({2, 3, 4}), 1, 1.0);
    s.submit("c", 1, 1, blob({1e6f, -1e6f, 1e6f}), 1000000, 1.0);  // n_k cannot buy weight
    ASSERT_TRUE(s.poll(1.0));
    EXPECT_EQ(s.globalModel()->values, (std::vector<float>{2, 2, 4}));
  }
  FederationOptions bad = abcOptions();
  bad.trim_fraction = 0.5;
  expectThrowMentioning<std::invalid_argument>([&] { FederationServer x(bad); }, "trim_fraction");
  bad = abcOptions();
  bad.max_update_norm_ratio = -1;
  expectThrowMentioning<std::invalid_argument>([&] { FederationServer x(bad); }, "max_update_norm_ratio");
}

TEST(FederationServer, LivenessTimeoutMakesASilentRsuNotNeeded) {
  FederationOptions o = abcOptions();
  o.round_deadline_s = 1000.0;  // far away: only liveness can close the round
  FederationServer s = liveAbcServer(o);  // a, b, c heard at t = 0; timeout 100 s
  s.fetch("a", 2, 60.0);  // a and b keep polling, c is silent
  s.fetch("b", 2, 60.0);
  s.submit("a", 1, 1, blob({4, -2, 1}), 1, 90.0);
  s.submit("b", 1, 1, blob({8, 2, 0}), 3, 90.0);
  EXPECT_FALSE(s.poll(100.0));  // c heard 100 s ago: 100 <= 100, still live
  ASSERT_TRUE(s.poll(100.5));   // 100.5 > 100: c not live; a, b are all the live RSUs
  EXPECT_FALSE(s.lastRound().on_deadline);
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{7.0f, 1.0f, 0.25f}));  // as above
}

TEST(FederationServer, ADeadlineSurvivesTheClockRestartingWithAnEpisode) {
  FederationServer s = liveAbcServer();  // deadline 10 s; a, b, c heard at t = 0
  s.fetch("c", 2, 1195.0);
  ASSERT_TRUE(s.submit("a", 1, 1, blob({4, -2, 1}), 1, 1195.0).accepted);
  ASSERT_TRUE(s.submit("b", 1, 1, blob({8, 2, 0}), 3, 1195.0).accepted);
  EXPECT_FALSE(s.poll(1199.0));  // c still live, the deadline not reached
  // The next episode starts at sim time 0: the deadline counts from the restart, it does
  // not wait for the new clock to pass 1205 s.
  EXPECT_FALSE(s.poll(0.0));
  EXPECT_FALSE(s.poll(9.0));
  ASSERT_TRUE(s.poll(10.0));
  EXPECT_TRUE(s.lastRound().on_deadline);
}

TEST(FederationServer, AnRsuNeverHeardFromIsNotWaitedFor) {
  FederationServer s(abcOptions());
  s.initialize(blob({1, 2, 3}));
  s.submit("a", 1, 1, blob({5, 5, 5}), 2, 0.0);  // b and c never called
  ASSERT_TRUE(s.poll(0.0));
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{5, 5, 5}));
}

TEST(FederationServer, VersionsIncreaseByOnePerRound) {
  FederationServer s = liveAbcServer();
  for (uint32_t r = 1; r <= 4; ++r) {
    for (const char* id : {"a", "b", "c"})
      ASSERT_TRUE(s.submit(id, r, r, blob({1, 2, float(r)}), 1, r).accepted);
    ASSERT_TRUE(s.poll(r));
    EXPECT_EQ(s.round(), r + 1);
    EXPECT_EQ(s.globalVersion(), r + 1);
    EXPECT_EQ(s.status().rounds_closed, r);
  }
  EXPECT_EQ(s.globalModel()->values[2], 4.0f);  // round 4: all three sent 4
}

TEST(FederationServer, FetchWaitsForTheVersionAndRefusesUnknownRsus) {
  FederationServer s = liveAbcServer();
  FetchResult f = s.fetch("a", 2, 1.0);
  EXPECT_FALSE(f.available);
  EXPECT_EQ(f.model, nullptr);
  EXPECT_NE(f.reason.find("global version 1 < requested 2"), std::string::npos) << f.reason;
  f = s.fetch("nobody", 0, 1.0);
  EXPECT_FALSE(f.available);
  EXPECT_NE(f.reason.find("unknown_rsu"), std::string::npos) << f.reason;
  EXPECT_EQ(s.status().fetch_unknown_rsu, 1u);
  f = s.fetch("b", 1, 1.0);
  EXPECT_TRUE(f.available);
  EXPECT_EQ(f.global_version, 1u);
  EXPECT_EQ(f.round, 1u);
}

TEST(FederationServer, CheckpointRoundTripResumesTheSameRound) {
  const std::string dir = tempDir("roundtrip");
  FederationServer s = liveAbcServer();
  s.submit("a", 1, 1, blob({4, -2, 1}), 1, 1.0);
  s.submit("b", 1, 1, blob({8, 2, 0}), 3, 1.0);
  s.submit("z", 1, 1, blob({8, 2, 0}), 3, 1.0);  // rejected: unknown
  ASSERT_TRUE(s.poll(11.0));                       // deadline with quorum
  s.saveCheckpoint(dir);

  FederationServer r(abcOptions());
  r.loadCheckpoint(dir);
  EXPECT_EQ(r.round(), 2u);
  EXPECT_EQ(r.globalVersion(), 2u);
  EXPECT_EQ(r.globalModel()->values, (std::vector<float>{7.0f, 1.0f, 0.25f}));
  EXPECT_EQ(federationStatusJson(r.status()), federationStatusJson(s.status()));
  // Resume: round 2 continues, the next close gives version 3 / round 3.
  EXPECT_FALSE(r.submit("a", 1, 1, blob({0, 0, 0}), 1, 0.0).accepted);  // round 1 is gone
  ASSERT_TRUE(r.submit("a", 2, 2, blob({1, 1, 1}), 1, 0.0).accepted);
  ASSERT_TRUE(r.poll(0.0));  // nobody else heard since the restart
  EXPECT_EQ(r.round(), 3u);
  EXPECT_EQ(r.globalVersion(), 3u);
}

TEST(FederationServer, LoadCheckpointRefusesWhatIsNotOursAndKeepsState) {
  const std::string good = tempDir("good"), other = tempDir("other");
  FederationServer s = liveAbcServer();
  s.saveCheckpoint(good);
  FederationServer o(abcOptions());
  o.initialize(blob({7, 7, 7}));
  o.saveCheckpoint(other);
  auto expectRefused = [&](const std::string& dir, const std::string& needle) {
    expectThrowMentioning<std::runtime_error>([&] { s.loadCheckpoint(dir); }, needle);
    EXPECT_EQ(s.globalModel()->values, (std::vector<float>{1, 2, 3}));
    EXPECT_EQ(s.round(), 1u);
  };
  expectRefused(tempDir("missing"), "cannot open");
  // The model file of another checkpoint next to this state file.
  std::filesystem::copy_file(other + "/" + FederationServer::MODEL_FILE,
                             good + "/" + FederationServer::MODEL_FILE,
                             std::filesystem::copy_options::overwrite_existing);
  expectRefused(good, "is not the model");
  const std::string state = other + "/" + FederationServer::STATE_FILE;
  std::ofstream(state) << "{\"format\": \"something_else\"}";
  expectRefused(other, "not a PALCAS federation state file");
  std::ofstream(state) << "round 3";
  expectRefused(other, "not valid JSON");
  o.saveCheckpoint(other);  // a valid state again, then a model file that is not ours
  std::ofstream(other + "/" + FederationServer::MODEL_FILE) << "garbage";
  expectRefused(other, "not a PALCAS model file");
}

namespace {

std::string readAll(const std::string& path) {
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

// `text` with its one occurrence of `from` replaced by `to` (fails the test if not once).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from << " not in " << text;
  EXPECT_EQ(text.find(from, at + 1), std::string::npos) << from << " twice in " << text;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

}  // namespace

TEST(FederationServer, LoadCheckpointNamesTheKeyOfAMissingOrWrongValueAndKeepsState) {
  const std::string dir = tempDir("bad_values");
  FederationServer o(abcOptions());
  o.initialize(blob({7, 7, 7}));
  o.saveCheckpoint(dir);
  const std::string path = dir + "/" + FederationServer::STATE_FILE;
  const std::string good = readAll(path);
  FederationServer s = liveAbcServer();
  s.submit("a", 1, 1, blob({4, -2, 1}), 1, 1.0);
  const std::string before = federationStatusJson(s.status());
  const struct {
    std::string from, to, needle;
  } cases[] = {
      {"  \"accepted_total\": 0,\n", "", "missing key 'accepted_total'"},
      {"\"round\": 1,", "\"round\": \"1\",", "'round' must be an unsigned integer, got '\"1\"'"},
      {"\"rounds_closed\": 0", "\"rounds_closed\": -1", "'rounds_closed' must be an unsigned integer, got '-1'"},
      {"\"global_version\": 1", "\"global_version\": 1.5", "'global_version' must be an unsigned integer"},
      {"\"global_version\": 1", "\"global_version\": 1e0", "'global_version' must be an unsigned integer"},
      {"\"round\": 1,", "\"round\": 4294967296,", "'round' = 4294967296 is outside [1, 2^32)"},
      {"\"round\": 1,", "\"round\": 0,", "'round' = 0 is outside [1, 2^32)"},
      {"\"fetch_unknown_rsu\": 0", "\"fetch_unknown_rsu\": 18446744073709551616",
       "'fetch_unknown_rsu' must be an unsigned integer"},
      {"\"failed_aggregations\": 0", "\"failed_aggregations\": [0]",
       "'failed_aggregations' must be an unsigned integer, got a JSON array"},
      {"\"last_round_s\": 0", "\"last_round_s\": null", "'last_round_s' must be a finite number, got 'null'"},
      {"\"last_round_s\": 0", "\"last_round_s\": 1e999", "not valid JSON"},
      {"\"format\": \"palcas_federation_state\"", "\"format\": 3", "'format' must be a string, got '3'"},
      {"\"format_version\": 1", "\"format_version\": 2", "format_version 2 is not supported"},
      {"\"global_version\": 1", "\"global_version\": 2", "global_version 2 > round 1"},
      {"\"duplicate\":0", "\"duplicate\":\"0\"", "'duplicate' must be an unsigned integer"},
      {"\"duplicate\":0", "\"duplicated\":0", "missing key 'duplicate'"},
      {"\"duplicate\":0,", "\"duplicate\":0,\"tampered\":0,", "'rejected_by_reason' holds an unknown reason 'tampered'"},
      {"\"rejected_by_reason\": {", "\"rejected_by_reason\": \"none\", \"x\": {",
       "'rejected_by_reason' must be an object, got '\"none\"'"},
      {"\n}\n", "\n} x\n", "not valid JSON at byte"},
      {"\"model_file\"", "\"model_file", "not valid JSON at byte"},
      {"\"round\": 1,", "\"round\": 1,,", "not valid JSON at byte"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.to);
    std::ofstream(path) << replaced(good, c.from, c.to);
    expectThrowMentioning<std::runtime_error>([&] { s.loadCheckpoint(dir); }, c.needle);
    EXPECT_EQ(federationStatusJson(s.status()), before);
    EXPECT_EQ(s.globalModel()->values, (std::vector<float>{1, 2, 3}));
  }
  for (const std::string& text : {std::string(""), std::string("[1, 2]"), good.substr(0, good.size() / 2)}) {
    SCOPED_TRACE(text);
    std::ofstream(path) << text;
    expectThrowMentioning<std::runtime_error>([&] { s.loadCheckpoint(dir); }, path);
    EXPECT_EQ(federationStatusJson(s.status()), before);
  }
  std::ofstream(path) << good;  // and the untouched file loads
  s.loadCheckpoint(dir);
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{7, 7, 7}));
}

TEST(FederationServer, TheShippedPoliciesStateFilesLoadAndSaveByteForByte) {
  // The state files committed with the shipped policies (their models are not committed: a
  // small one stands in, named by count and checksum). Loading one and saving it again gives
  // the same bytes, so old and new files read alike.
  const std::filesystem::path policies = PALCAS_POLICIES_DIR;
  int found = 0;
  for (const auto& entry : std::filesystem::directory_iterator(policies)) {
    const auto state = entry.path() / "checkpoints/fedserver" / FederationServer::STATE_FILE;
    if (!std::filesystem::exists(state)) continue;
    SCOPED_TRACE(state.string());
    ++found;
    const std::string text = readAll(state.string());
    const ModelBlob model = blob({7, 7, 7});
    const std::string count = "\"model_value_count\": " + std::to_string(model.values.size());
    const std::string checksum =
        "\"model_values_fnv1a64\": " +
        std::to_string(nn::fnv1a64(model.values.data(), model.values.size() * sizeof(float)));
    const auto field = [&](const std::string& key) {  // `"key": value` as the file has it
      const auto at = text.find("\"" + key + "\": ");
      return text.substr(at, text.find(',', at) - at);
    };
    const std::string stand_in =
        replaced(replaced(text, field("model_value_count"), count), field("model_values_fnv1a64"), checksum);
    const std::string dir = tempDir("shipped_" + entry.path().filename().string());
    FederationServer writer(abcOptions());
    writer.initialize(model);
    writer.saveCheckpoint(dir);  // the stand-in model file
    std::ofstream(dir + "/" + FederationServer::STATE_FILE) << stand_in;
    FederationServer r(abcOptions());
    r.loadCheckpoint(dir);
    EXPECT_GE(r.round(), 1u);
    const std::string again = tempDir("shipped_again");
    r.saveCheckpoint(again);
    EXPECT_EQ(readAll(again + "/" + FederationServer::STATE_FILE), stand_in);
  }
  EXPECT_GE(found, 1) << "no shipped federation state under " << policies;
}

TEST(FederationServer, ARefusalFromTheNodeIsCountedAndChangesNothingElse) {
  FederationServer s = liveAbcServer();
  const std::string before = federationStatusJson(s.status());
  const SubmitResult r = s.refuse(Rejection::kUnauthenticated, "forged_tag from 'a'");
  EXPECT_FALSE(r.accepted);
  EXPECT_EQ(r.reason, "unauthenticated: forged_tag from 'a'");
  EXPECT_EQ(r.round, 1u);
  EXPECT_EQ(s.status().rejected_by_reason.at("unauthenticated"), 1u);
  EXPECT_EQ(s.status().accepted_total, 0u);
  EXPECT_TRUE(s.status().submitted.empty());
  EXPECT_EQ(s.globalModel()->values, (std::vector<float>{1, 2, 3}));
  // a may still submit its genuine model in the same round.
  EXPECT_TRUE(s.submit("a", 1, 1, blob({1, 2, 3}), 1, 1.0).accepted);
  EXPECT_NE(before, federationStatusJson(s.status()));
}

TEST(FederationServer, ACheckpointWrittenBeforeTheNewCountersStillLoads) {
  const std::string dir = tempDir("old_counters");
  FederationServer s = liveAbcServer();
  s.refuse(Rejection::kUnauthenticated, "missing_tag");
  s.saveCheckpoint(dir);
  const std::string path = dir + "/" + FederationServer::STATE_FILE;
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  std::string state = text.str();
  for (const std::string key : {"\"unauthenticated\":1,", "\"update_too_large\":0,"}) {
    const auto at = state.find(key);
    ASSERT_NE(at, std::string::npos) << key << " not in " << state;
    state.erase(at, key.size());
  }
  std::ofstream(path) << state;
  FederationServer r(abcOptions());
  r.loadCheckpoint(dir);
  EXPECT_EQ(r.status().rejected_by_reason.at("unauthenticated"), 0u);
  EXPECT_EQ(r.round(), 1u);
}

TEST(FederationServer, StatusJsonHoldsRoundVersionAndCounters) {
  FederationServer s = liveAbcServer();
  s.submit("b", 1, 1, blob({1, 1, 1}), 1, 1.0);
  s.submit("b", 1, 1, blob({1, 1, 1}), 1, 1.0);  // duplicate
  EXPECT_EQ(federationStatusJson(s.status()),
            "{\"round\":1,\"version\":1,\"submitted\":[\"b\"],\"rejected_by_reason\":"
            "{\"bad_sample_count\":0,\"duplicate\":1,\"layout_mismatch\":0,\"non_finite\":0,"
            "\"stale_base_version\":0,\"unauthenticated\":0,\"unknown_rsu\":0,\"update_too_large\":0,\"wrong_round\":0,"
            "\"wrong_value_count\":0},\"fetch_unknown_rsu\":0,\"accepted_total\":1,"
            "\"rounds_closed\":0,\"failed_aggregations\":0,\"last_round_s\":0,"
            "\"bytes_in_round\":12,\"bytes_in_last_round\":0}");
}
