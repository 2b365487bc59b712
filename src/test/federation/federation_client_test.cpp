#include "palcas_core/federation/federation_client.h"

#include <gtest/gtest.h>

#include "common/throws_naming.h"

#include <memory>
#include <vector>

#include "palcas_core/federation/federation_server.h"
#include "palcas_core/learning/nn/serialization.h"

using namespace palcas;

namespace {

ModelBlob blob(std::vector<float> values) { return ModelBlob{"L", nn::fnv1a64("L"), std::move(values)}; }

// A local model whose "training" the test drives: due when the test says so.
class FakeModel : public FederatedModel {
 public:
  explicit FakeModel(std::vector<float> values) : values_(std::move(values)) {}
  bool federationDue() const override { return due; }
  uint32_t modelVersion() const override { return version_; }
  ModelBlob exportModel() const override { return blob(values_); }
  uint64_t samplesSinceFederation() const override { return samples; }
  void loadGlobal(const ModelBlob& model, uint32_t version) override {
    if (model.values.size() != values_.size())
      throw std::invalid_argument("expected " + std::to_string(values_.size()) + " values");
    values_ = model.values;
    version_ = version;
    due = false;
    samples = 0;
    ++loads;
  }
  const std::vector<float>& values() const { return values_; }
  void train(std::vector<float> values, uint64_t n_k) {
    values_ = std::move(values);
    samples = n_k;
    due = true;
  }

  bool due = false;
  uint64_t samples = 0;
  int loads = 0;

 private:
  std::vector<float> values_;
  uint32_t version_ = 0;
};

// The server in this process, as the fedserver node runs it: poll() after every call.
class InProcessTransport : public FederationTransport {
 public:
  InProcessTransport(FederationServer* server, const double* now) : server_(server), now_(now) {}
  FetchReply fetch(const std::string& rsu_id, uint32_t min_version) override {
    FetchReply reply;
    if (!server_) return reply;
    reply.reachable = true;
    const FetchResult r = server_->fetch(rsu_id, min_version, *now_);
    server_->poll(*now_);
    reply.round = r.round;
    reply.model_version = r.global_version;
    reply.available = r.available;
    if (r.model) reply.model = *r.model;
    reply.refused = refuse_models;
    return reply;
  }
  SubmitReply submit(const Submission& s) override {
    SubmitReply reply;
    if (!server_) return reply;
    reply.reachable = true;
    const SubmitResult r = server_->submit(s.rsu_id, s.round, s.base_version, s.model, s.sample_count, *now_);
    server_->poll(*now_);
    reply.accepted = r.accepted;
    reply.reason = r.reason;
    reply.round = server_->round();
    reply.global_version = server_->globalVersion();
    return reply;
  }
  void connect(FederationServer* server) { server_ = server; }
  std::string refuse_models;

 private:
  FederationServer* server_;
  const double* now_;
};

FederationOptions abcOptions() {
  FederationOptions o;
  o.expected_rsus = {"a", "b", "c"};
  o.round_deadline_s = 10.0;
  o.liveness_timeout_s = 30.0;
  o.max_update_norm_ratio = 0.0;
  return o;
}

struct Event {
  FederationEvent kind;
  std::string message;
};

// Three RSUs a, b, c with their models, transports and clients around one server.
struct Federation {
  double now = 0.0;
  std::unique_ptr<FederationServer> server;
  std::vector<std::unique_ptr<FakeModel>> models;
  std::vector<std::unique_ptr<InProcessTransport>> transports;
  std::vector<std::unique_ptr<FederationClient>> clients;
  std::vector<Event> events;

  explicit Federation(double heartbeat_s = 10.0) : server(std::make_unique<FederationServer>(abcOptions())) {
    server->initialize(blob({1, 2, 3}));
    for (const char* id : {"a", "b", "c"}) {
      models.push_back(std::make_unique<FakeModel>(std::vector<float>{0, 0, 0}));
      transports.push_back(std::make_unique<InProcessTransport>(server.get(), &now));
      FederationClientOptions o;
      o.rsu_id = id;
      o.heartbeat_s = heartbeat_s;
      clients.push_back(std::make_unique<FederationClient>(
          o, *models.back(), *transports.back(),
          [this](FederationEvent e, const std::string& m) { events.push_back({e, m}); }));
    }
  }
  int count(FederationEvent kind) const {
    int n = 0;
    for (const Event& e : events) n += e.kind == kind;
    return n;
  }
};

}  // namespace

TEST(FederationClientOptions, RejectsBadFieldsNamingThem) {
  FederationClientOptions o;
  EXPECT_THROW(o.validate(), std::invalid_argument);  // no rsu_id
  o.rsu_id = "a";
  o.heartbeat_s = -1;
  palcas_test::expectThrowNaming<std::invalid_argument>([&] { o.validate(); }, "heartbeat_s");
}

TEST(FederationClient, JoinStartsFromTheServersModel) {
  Federation f;
  for (auto& c : f.clients) EXPECT_TRUE(c->join());
  for (auto& m : f.models) {
    EXPECT_EQ(m->modelVersion(), 1u);
    EXPECT_EQ(m->values(), (std::vector<float>{1, 2, 3}));
  }
  EXPECT_EQ(f.clients[0]->openRound(), 1u);
  EXPECT_TRUE(f.clients[0]->reachable());
  EXPECT_EQ(f.count(FederationEvent::kLoaded), 3);
}

TEST(FederationClient, AResumedRsuTakesOnlyANewerModel) {
  Federation f;
  f.models[0]->loadGlobal(blob({5, 5, 5}), 1);  // resumed at version 1 with local steps
  EXPECT_FALSE(f.clients[0]->join());            // the server has only version 1
  EXPECT_EQ(f.models[0]->values(), (std::vector<float>{5, 5, 5}));
}

TEST(FederationClient, ARoundSubmitsWaitsAndLoadsTheSampleWeightedAverage) {
  Federation f;
  for (auto& c : f.clients) c->join();
  f.now = 1.0;
  f.models[0]->train({3, 3, 3}, 1);
  f.models[1]->train({6, 6, 6}, 2);
  f.clients[0]->onDecision(f.now);
  f.clients[1]->onDecision(f.now);
  EXPECT_TRUE(f.clients[0]->waiting());
  EXPECT_EQ(f.count(FederationEvent::kSubmitted), 2);
  f.models[2]->train({0, 0, 0}, 3);
  f.clients[2]->onDecision(f.now);  // the last one closes the round: (3 + 12 + 0) / 6
  EXPECT_EQ(f.server->globalVersion(), 2u);
  f.now = 2.0;
  for (auto& c : f.clients) c->onDecision(f.now);  // polling while waiting picks it up
  for (size_t k = 0; k < 3; ++k) {
    EXPECT_FALSE(f.clients[k]->waiting()) << k;
    EXPECT_EQ(f.models[k]->modelVersion(), 2u) << k;
    EXPECT_FLOAT_EQ(f.models[k]->values()[0], 2.5f) << k;
    EXPECT_EQ(f.clients[k]->openRound(), 2u) << k;
  }
}

TEST(FederationClient, AnnouncedVersionsReplaceThePollWhileWaiting) {
  Federation f(10.0);
  for (auto& c : f.clients) c->join();
  for (auto& c : f.clients) c->announceVersion(f.server->globalVersion());
  f.now = 1.0;
  f.models[0]->train({3, 3, 3}, 1);
  f.clients[0]->onDecision(f.now);  // submits
  ASSERT_TRUE(f.clients[0]->waiting());
  const uint64_t after_submit = f.clients[0]->calls();
  for (int t = 2; t <= 8; ++t) f.clients[0]->onDecision(t);  // nothing newer announced: no call
  EXPECT_EQ(f.clients[0]->calls(), after_submit);
  f.models[1]->train({6, 6, 6}, 2);
  f.models[2]->train({0, 0, 0}, 3);
  f.clients[1]->onDecision(f.now);
  f.clients[2]->onDecision(f.now);  // closes the round
  ASSERT_EQ(f.server->globalVersion(), 2u);
  f.clients[0]->onDecision(9.0);  // the round closed, but nobody said so yet
  EXPECT_TRUE(f.clients[0]->waiting());
  f.clients[0]->announceVersion(2);
  f.clients[0]->onDecision(9.5);  // told: one fetch loads it
  EXPECT_EQ(f.clients[0]->calls(), after_submit + 1);
  EXPECT_FALSE(f.clients[0]->waiting());
  EXPECT_EQ(f.models[0]->modelVersion(), 2u);
}

TEST(FederationClient, AMissedAnnouncementIsCaughtByTheHeartbeat) {
  Federation f(10.0);
  for (auto& c : f.clients) c->join();
  f.clients[0]->announceVersion(1);
  for (size_t k = 0; k < 3; ++k) f.models[k]->train({1, 1, 1}, 1);
  for (auto& c : f.clients) c->onDecision(1.0);  // all submit; the round closes
  ASSERT_EQ(f.server->globalVersion(), 2u);
  for (int t = 2; t <= 10; ++t) f.clients[0]->onDecision(t);  // no announcement: waits
  EXPECT_TRUE(f.clients[0]->waiting());
  f.clients[0]->onDecision(11.0);  // heartbeat_s after its last call: polls, and loads
  EXPECT_FALSE(f.clients[0]->waiting());
  EXPECT_EQ(f.models[0]->modelVersion(), 2u);
  // Without any announcement a waiting client polls at every decision, as before.
  f.clients[1]->onDecision(2.0);
  EXPECT_FALSE(f.clients[1]->waiting());
}

TEST(FederationClient, HeartbeatsKeepAnRsuLiveBetweenRoundsAndFollowTheClockBack) {
  Federation f(10.0);
  f.clients[0]->join();
  const uint64_t after_join = f.clients[0]->calls();
  for (int t = 0; t <= 60; ++t) f.clients[0]->onDecision(t);
  EXPECT_EQ(f.clients[0]->calls() - after_join, 7u);  // t = 0, 10, ..., 60
  // A new episode: the sim clock starts again at 0; heartbeats go on from there.
  for (int t = 0; t <= 20; ++t) f.clients[0]->onDecision(t);
  EXPECT_EQ(f.clients[0]->calls() - after_join, 9u);  // t = 10, 20
}

TEST(FederationClient, NoHeartbeatWhenSwitchedOff) {
  Federation f(0.0);
  f.clients[0]->join();
  const uint64_t after_join = f.clients[0]->calls();
  for (int t = 0; t <= 60; ++t) f.clients[0]->onDecision(t);
  EXPECT_EQ(f.clients[0]->calls(), after_join);
}

TEST(FederationClient, AnUnreachableServerIsRetriedAndARestartedOneRejoined) {
  Federation f;
  for (auto& c : f.clients) c->join();
  f.transports[0]->connect(nullptr);  // the server died
  f.models[0]->train({4, 4, 4}, 1);
  f.clients[0]->onDecision(1.0);
  EXPECT_FALSE(f.clients[0]->reachable());
  EXPECT_FALSE(f.clients[0]->waiting());
  EXPECT_EQ(f.count(FederationEvent::kUnreachable), 1);
  // It comes back from its checkpoint (round 1, version 1, nothing submitted).
  const std::string dir = testing::TempDir() + "/palcas_fed_client_restart";
  f.server->saveCheckpoint(dir);
  FederationServer restarted(abcOptions());
  restarted.loadCheckpoint(dir);
  f.transports[0]->connect(&restarted);
  f.clients[0]->onDecision(2.0);  // still due: submits again, to the new server
  EXPECT_TRUE(f.clients[0]->reachable());
  EXPECT_TRUE(f.clients[0]->waiting());
  EXPECT_EQ(restarted.status().accepted_total, 1u);
}

TEST(FederationClient, ALateRsuTakesTheGlobalModelThatMovedOn) {
  Federation f;
  for (auto& c : f.clients) c->join();
  f.models[0]->train({2, 2, 2}, 1);
  f.models[1]->train({2, 2, 2}, 1);
  f.clients[0]->onDecision(1.0);
  f.clients[1]->onDecision(1.0);
  f.now = 20.0;  // past the deadline: the round closes with a and b (quorum 2)
  f.clients[0]->onDecision(f.now);
  ASSERT_EQ(f.server->globalVersion(), 2u);
  f.models[2]->train({9, 9, 9}, 1);  // c finishes its round-1 model late
  f.clients[2]->onDecision(f.now);
  EXPECT_EQ(f.count(FederationEvent::kSubmitRefused), 1);
  EXPECT_EQ(f.models[2]->modelVersion(), 2u);
  EXPECT_EQ(f.models[2]->values(), (std::vector<float>{2, 2, 2}));
  EXPECT_FALSE(f.models[2]->due);
}

TEST(FederationClient, AModelTheTransportRefusesIsNotLoaded) {
  Federation f;
  f.transports[0]->refuse_models = "unauthenticated: tag does not match";
  EXPECT_FALSE(f.clients[0]->join());
  EXPECT_EQ(f.models[0]->modelVersion(), 0u);
  EXPECT_EQ(f.models[0]->values(), (std::vector<float>{0, 0, 0}));
  ASSERT_EQ(f.count(FederationEvent::kModelRefused), 1);
  EXPECT_NE(f.events.back().message.find("unauthenticated"), std::string::npos);
  EXPECT_NE(f.events.back().message.find("a: "), std::string::npos);  // names the RSU
}

TEST(FederationClient, AModelThatDoesNotFitIsRefusedAndTheLocalOneKept) {
  Federation f;
  FakeModel bigger({0, 0, 0, 0});
  FederationClientOptions o;
  o.rsu_id = "a";
  std::vector<Event> events;
  FederationClient client(o, bigger, *f.transports[0],
                          [&](FederationEvent e, const std::string& m) { events.push_back({e, m}); });
  EXPECT_FALSE(client.join());
  EXPECT_EQ(bigger.modelVersion(), 0u);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, FederationEvent::kModelRefused);
  EXPECT_NE(events[0].message.find("expected 4 values"), std::string::npos) << events[0].message;
}
