#pragma once
// Round logic of the federation server (paper "Problem Formulation": every E local
// gradient steps each RSU k uploads theta_k and n_k; the server sets
// theta^{r+1} = sum_k (n_k / n) theta_k^r and every RSU loads it). ROS-free: time is an
// argument in seconds (sim time in the node), nothing here waits or reads a clock.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "palcas_core/learning/fedavg.h"
#include "palcas_core/learning/model_blob.h"

namespace palcas {

/// How rounds close. Defaults are documented choices (the paper gives none);
/// palcas_fedserver/README.md explains them for users.
struct FederationOptions {
  std::vector<std::string> expected_rsus;  ///< ids allowed to submit / fetch; non-empty, unique
  /// Minimum submissions to close a round on its deadline; 0 = defaultQuorum(expected).
  size_t quorum = 0;
  /// Seconds from the round's FIRST accepted submission after which the round closes
  /// with whoever submitted, if that is at least `quorum`. > 0, finite.
  double round_deadline_s = 30.0;
  /// n_k above this is implausible (a bug in the sender) and rejected. >= 1.
  uint64_t max_samples = FEDAVG_MAX_SAMPLES_DEFAULT;
  /// An expected RSU not heard from (accepted submit or fetch) for this long, or never,
  /// is not live and not waited for. Must exceed the time between two calls of a live RSU
  /// (RSU heartbeats: every 10 s by default). > 0 (+inf = an RSU once heard stays live).
  double liveness_timeout_s = 60.0;
  /// A submission whose update ||theta_k - theta_global|| exceeds this multiple of
  /// ||theta_global|| is refused (kUpdateTooLarge): one client cannot throw the global model
  /// anywhere it likes (an all-1e30 model, a scaled update). Measured honest updates of the
  /// shipped training: 0.20-0.34. >= 0, finite; 0 = no bound.
  double max_update_norm_ratio = 5.0;
  /// How a round's models become the global one. kFedAvg: the paper's sample-weighted mean.
  /// kMedian: coordinate-wise median (n_k ignored; robust while fewer than half the
  /// submissions are poisoned). kTrimmedMean: per coordinate, the mean after dropping the
  /// trim_fraction largest and smallest values (n_k ignored).
  enum class Aggregation { kFedAvg, kMedian, kTrimmedMean };
  Aggregation aggregation = Aggregation::kFedAvg;
  /// Share dropped at each end by kTrimmedMean, in [0, 0.5).
  double trim_fraction = 0.2;

  /// ceil(2 n / 3) computed as (2 n + 2) / 3 in integers: 3 -> 2, 4 -> 3, 1 -> 1.
  static size_t defaultQuorum(size_t expected) { return (2 * expected + 2) / 3; }
  /// quorum, or defaultQuorum(expected_rsus.size()) when quorum == 0.
  size_t effectiveQuorum() const;
  /// Throws std::invalid_argument naming the first invalid field and its value.
  void validate() const;
};

/// Why a submission was refused; each has its own counter (names: rejectionName()).
enum class Rejection {
  kUnknownRsu,        ///< not in expected_rsus
  kWrongRound,        ///< round != the open round (stale or from the future)
  kStaleBaseVersion,  ///< trained from another global version than the current one
  kDuplicate,         ///< this RSU already submitted in the open round
  kBadSampleCount,    ///< n_k == 0 or n_k > max_samples
  kLayoutMismatch,    ///< layout id or checksum differs from the global model's
  kWrongValueCount,   ///< value count differs from the global model's
  kNonFinite,         ///< a value is NaN or infinite
  kUpdateTooLarge,    ///< ||theta_k - theta_global|| > max_update_norm_ratio ||theta_global||
  kUnauthenticated,   ///< the message's authentication tag is missing or wrong (node-checked)
};
constexpr size_t REJECTION_COUNT = 10;
/// Stable snake_case name of a rejection ("unknown_rsu", ...), used in status JSON.
const char* rejectionName(Rejection r);

struct SubmitResult {
  bool accepted = false;
  Rejection rejection = Rejection::kUnknownRsu;  ///< meaningful only when !accepted
  std::string reason;        ///< human-readable, names the offending value; "" if accepted
  uint32_t round = 0;        ///< the open round after the call
  uint32_t global_version = 0;
};

struct FetchResult {
  bool available = false;  ///< global_version >= min_version and the RSU is known
  std::string reason;      ///< why not available ("" when available)
  uint32_t round = 0;      ///< the open round
  uint32_t global_version = 0;
  std::shared_ptr<const ModelBlob> model;  ///< the global model when available, else null
};

/// What the last poll() that closed a round did (for the node's log).
struct RoundReport {
  uint32_t round = 0;            ///< the round that closed
  uint32_t global_version = 0;   ///< the global version after it
  bool aggregated = false;       ///< false: the average was not finite, the old global kept
  bool on_deadline = false;      ///< true: deadline with quorum; false: every live RSU submitted
  std::map<std::string, uint64_t> sample_counts;  ///< n_k of each RSU that took part
  double duration_s = 0.0;       ///< first accepted submission -> close (the caller's seconds)
  uint64_t bytes_in = 0;         ///< model payload bytes accepted in the round
};

struct FederationStatus {
  uint32_t round = 0;
  uint32_t global_version = 0;
  std::vector<std::string> submitted;  ///< ids that submitted in the open round, sorted
  std::map<std::string, uint64_t> rejected_by_reason;  ///< every reason, zeros included
  uint64_t fetch_unknown_rsu = 0;      ///< fetches from an id not expected
  uint64_t accepted_total = 0;
  uint64_t rounds_closed = 0;
  uint64_t failed_aggregations = 0;    ///< rounds whose average was not finite
  double last_round_s = 0.0;           ///< RoundReport::duration_s of the last close; 0 before
  uint64_t bytes_in_round = 0;         ///< accepted payload bytes in the open round
  uint64_t bytes_in_last_round = 0;
};

/// Holds the global model and one federation round at a time. Single-threaded (the node
/// calls it from one spinner thread); not thread-safe.
class FederationServer {
 public:
  /// Throws std::invalid_argument (via FederationOptions::validate) on invalid options.
  explicit FederationServer(FederationOptions options);

  /// Sets the global model: version 1, round 1 open, counters zero. Every RSU must start
  /// from this model (FedAvg needs a common start). Throws std::invalid_argument if the
  /// model fails validateModelBlob or is empty (server unchanged).
  void initialize(ModelBlob initial);

  /// A local model for `round`, trained from global version `base_version` on n_k samples.
  /// Refused (see Rejection) with everything unchanged but that reason's counter.
  /// Accepted: stored for the round, the RSU marked live at now_s. Throws std::logic_error
  /// before initialize/loadCheckpoint, std::invalid_argument if now_s is not finite.
  SubmitResult submit(const std::string& rsu_id, uint32_t round, uint32_t base_version,
                      ModelBlob blob, uint64_t n_k, double now_s);
  /// A submission refused before submit() could look at it (the node found its
  /// authentication tag missing or wrong): counted under `why` like submit's refusals,
  /// nothing else changes. The reason reads "<rejectionName>: <detail>".
  SubmitResult refuse(Rejection why, const std::string& detail);

  /// Closes the open round if every live expected RSU submitted, or if round_deadline_s
  /// passed since its first accepted submission and at least `quorum` submitted. A clock
  /// that went back (sim time restarts with every episode) restarts the deadline from now_s. Closing:
  /// sample-weighted fedAverage of the submitted models; a finite result becomes the
  /// global model and version += 1; a non-finite one is dropped (old global kept, counted).
  /// Either way round += 1 and submissions are cleared. Never waits.
  /// @return true if a round closed (details in lastRound()). Throws like submit.
  bool poll(double now_s);

  /// The global model if its version >= min_version. A known RSU is marked live at now_s
  /// (even when nothing is available yet: it is alive and waiting). Unknown RSU: not
  /// available, counted. Throws like submit.
  FetchResult fetch(const std::string& rsu_id, uint32_t min_version, double now_s);

  FederationStatus status() const;
  const RoundReport& lastRound() const { return last_round_; }
  const FederationOptions& options() const { return options_; }
  uint32_t round() const { return round_; }
  uint32_t globalVersion() const { return version_; }
  /// The global model (null before initialize/loadCheckpoint). Always finite.
  std::shared_ptr<const ModelBlob> globalModel() const { return global_; }

  /// Writes <dir>/global_model.palcas (model file, saveModelBlob) then
  /// <dir>/federation_state.json (round, version, counters, model checksum), each
  /// atomically; creates dir. The open round's submissions are NOT saved (a resumed
  /// server reopens the same round empty). Throws std::runtime_error naming the path.
  void saveCheckpoint(const std::string& dir) const;
  /// Replaces the global model, round, version and counters by a checkpoint's (a
  /// successful load counts as initialization; liveness and submissions start empty).
  /// Throws std::runtime_error naming the file and the check that failed (missing file,
  /// not our format, model not matching the state's checksum); server unchanged then.
  void loadCheckpoint(const std::string& dir);

  static constexpr char MODEL_FILE[] = "global_model.palcas";
  static constexpr char STATE_FILE[] = "federation_state.json";

 private:
  struct Submission {
    ModelBlob model;
    uint64_t n_k = 0;
  };
  void requireReady(double now_s, const char* who) const;
  bool checkSubmission(const std::string& rsu_id, uint32_t round, uint32_t base_version,
                       const ModelBlob& blob, uint64_t n_k, SubmitResult& result) const;
  bool isLive(const std::string& rsu_id, double now_s) const;
  bool allLiveSubmitted(double now_s) const;
  void closeRound(double now_s, bool on_deadline);

  FederationOptions options_;
  size_t quorum_;
  std::shared_ptr<const ModelBlob> global_;
  uint32_t round_ = 0, version_ = 0;
  std::map<std::string, Submission> submissions_;  // of the open round, by RSU id
  double first_submit_s_ = 0.0;                    // of the open round
  std::map<std::string, double> last_heard_s_;     // by RSU id
  uint64_t rejected_[REJECTION_COUNT] = {};
  uint64_t fetch_unknown_rsu_ = 0, accepted_total_ = 0, rounds_closed_ = 0,
           failed_aggregations_ = 0, bytes_in_round_ = 0;
  RoundReport last_round_;
};

/// One-line JSON of the status for the node's federation_status topic:
/// {"round":..,"version":..,"submitted":[..],"rejected_by_reason":{..},
///  "fetch_unknown_rsu":..,"accepted_total":..,"rounds_closed":..,"failed_aggregations":..,
///  "last_round_s":..,"bytes_in_round":..,"bytes_in_last_round":..}
std::string federationStatusJson(const FederationStatus& status);

}  // namespace palcas
