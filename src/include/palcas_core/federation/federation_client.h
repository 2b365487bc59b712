#pragma once
// The RSU's side of federation (paper "Problem Formulation": every E local gradient steps
// an RSU uploads theta_k and n_k, waits for the round to close, loads the global model).
// ROS-free: the server is reached through a FederationTransport (the node wraps ROS
// services; tests wrap a FederationServer in the same process), time is an argument in
// seconds (sim time in the node), and nothing here blocks beyond the transport's calls.
//
// Round state machine, driven by onDecision(now_s) once per decision in train mode:
//   training  -- federation due -->  submit -- accepted --> waiting (poll for the new version;
//             once the server's announcements are heard, only when one names a newer version,
//             and every heartbeat_s in case one was missed)
//   waiting   -- new global model loaded --> training
//   submit refused because the round moved on --> fetch that newer global model
//   between rounds, every heartbeat_s: a fetch (keeps the RSU live at the server and picks
//   up a global model that moved on without it)
// A call that does not go through marks the server unreachable; the next call connects
// afresh (a restarted server is rejoined without anything special).

#include <cstdint>
#include <functional>
#include <string>

#include "palcas_core/learning/model_blob.h"

namespace palcas {

/// The model a federation client submits and replaces: the RSU's controller in the node
/// (palcas::rsu::ControllerModel), a fake in tests.
class FederatedModel {
 public:
  virtual ~FederatedModel() = default;
  /// E local gradient steps were made since the last loadGlobal().
  virtual bool federationDue() const = 0;
  /// The global version the local model was trained from (0 before the first load).
  virtual uint32_t modelVersion() const = 0;
  virtual ModelBlob exportModel() const = 0;
  /// n_k: transitions learnt from since the last loadGlobal().
  virtual uint64_t samplesSinceFederation() const = 0;
  /// Replaces the local model. Throws std::invalid_argument (model kept) if it does not fit.
  virtual void loadGlobal(const ModelBlob& model, uint32_t version) = 0;
};

/// One local model for one round, as it goes to the server.
struct Submission {
  std::string rsu_id;
  uint32_t round = 0;         ///< the open round as the server last said
  uint32_t base_version = 0;  ///< the global version it was trained from
  ModelBlob model;
  uint64_t sample_count = 0;  ///< n_k
};

/// The server's answer to a fetch, as the transport received it.
struct FetchReply {
  bool reachable = false;  ///< the call went through
  bool available = false;  ///< a model of version >= the requested one came back
  /// Non-empty: the transport refused the model it got (e.g. its authentication tag is
  /// wrong); why. The model is then not loaded.
  std::string refused;
  ModelBlob model;
  uint32_t model_version = 0;
  uint32_t round = 0;  ///< the round open at the server
};

struct SubmitReply {
  bool reachable = false;
  bool accepted = false;
  std::string reason;           ///< why refused ("" when accepted)
  uint32_t round = 0;           ///< the round open at the server after the call
  uint32_t global_version = 0;  ///< the server's global version after the call
};

/// How the client reaches the server. Calls may block (a ROS service call); they must not
/// throw for an unreachable server (reachable = false instead).
class FederationTransport {
 public:
  virtual ~FederationTransport() = default;
  virtual FetchReply fetch(const std::string& rsu_id, uint32_t min_version) = 0;
  virtual SubmitReply submit(const Submission& submission) = 0;
};

/// What happened in a call, for the node's log (and tests).
enum class FederationEvent {
  kUnreachable,      ///< the server did not answer
  kLoaded,           ///< a global model was loaded (message names version and round)
  kModelRefused,     ///< a global model came back but was not loaded (message says why)
  kSubmitted,        ///< the local model was accepted for the open round
  kSubmitRefused,    ///< the server refused the submission (message has its reason)
};
const char* federationEventName(FederationEvent e);

struct FederationClientOptions {
  std::string rsu_id;
  /// Sim seconds between heartbeat fetches while training between rounds; 0 = none.
  /// Must be below the server's liveness timeout.
  double heartbeat_s = 10.0;
  /// Throws std::invalid_argument naming the bad field.
  void validate() const;
};

class FederationClient {
 public:
  using Listener = std::function<void(FederationEvent, const std::string& message)>;

  /// model and transport must outlive the client. Throws std::invalid_argument on bad options.
  FederationClient(FederationClientOptions options, FederatedModel& model,
                   FederationTransport& transport, Listener listener = {});

  /// The first exchange: every RSU starts from the server's model (FedAvg needs a common
  /// start); a resumed RSU takes only a newer one (the one it had would undo its local
  /// steps since). True if a model was loaded.
  bool join();

  /// One decision in train mode at sim time now_s: submit when due, poll while waiting,
  /// heartbeat between rounds. A sim clock that went back (a new episode) is followed.
  void onDecision(double now_s);
  /// The server announced its global model's version (the node: the server's latched
  /// version topic). From the first announcement on, a waiting client fetches only when an
  /// announced version is newer than its model's (and every heartbeat_s, for a missed one)
  /// instead of at every decision.
  void announceVersion(uint32_t version);

  bool reachable() const { return reachable_; }
  /// The round open at the server as it last said.
  uint32_t openRound() const { return server_round_; }
  /// Submitted in the open round and waiting for it to close.
  bool waiting() const { return submitted_; }
  /// Calls to the server so far (fetches and submissions).
  uint64_t calls() const { return calls_; }

 private:
  bool fetchGlobal(uint32_t min_version);
  void submit();
  void tell(FederationEvent e, const std::string& message) const;

  FederationClientOptions options_;
  FederatedModel& model_;
  FederationTransport& transport_;
  Listener listener_;
  uint32_t server_round_ = 0;
  bool submitted_ = false;
  bool reachable_ = false;
  uint64_t calls_ = 0;
  double last_call_s_ = -1e300;  ///< sim time of the last call made by onDecision
  bool announced_ = false;        ///< an announcement was heard
  uint32_t announced_version_ = 0;
};

}  // namespace palcas
