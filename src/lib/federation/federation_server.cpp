#include "palcas_core/federation/federation_server.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

namespace palcas {

namespace {

[[noreturn]] void badOption(const std::string& what) {
  throw std::invalid_argument("FederationOptions." + what);
}

// Model payload bytes of a submission: 4 per float32 value (the message's float32[]).
uint64_t payloadBytes(const ModelBlob& blob) { return 4ULL * blob.values.size(); }

}  // namespace

const char* rejectionName(Rejection r) {
  switch (r) {
    case Rejection::kUnknownRsu: return "unknown_rsu";
    case Rejection::kWrongRound: return "wrong_round";
    case Rejection::kStaleBaseVersion: return "stale_base_version";
    case Rejection::kDuplicate: return "duplicate";
    case Rejection::kBadSampleCount: return "bad_sample_count";
    case Rejection::kLayoutMismatch: return "layout_mismatch";
    case Rejection::kWrongValueCount: return "wrong_value_count";
    case Rejection::kNonFinite: return "non_finite";
    case Rejection::kUpdateTooLarge: return "update_too_large";
    case Rejection::kUnauthenticated: return "unauthenticated";
  }
  return "unknown";
}

size_t FederationOptions::effectiveQuorum() const {
  return quorum == 0 ? defaultQuorum(expected_rsus.size()) : quorum;
}

void FederationOptions::validate() const {
  if (expected_rsus.empty()) badOption("expected_rsus is empty: at least one RSU is needed");
  std::vector<std::string> ids = expected_rsus;
  std::sort(ids.begin(), ids.end());
  for (size_t i = 0; i < ids.size(); ++i) {
    if (ids[i].empty()) badOption("expected_rsus holds an empty id");
    if (i > 0 && ids[i] == ids[i - 1]) badOption("expected_rsus lists '" + ids[i] + "' twice");
  }
  if (quorum > expected_rsus.size())
    badOption("quorum = " + std::to_string(quorum) + " exceeds the " +
              std::to_string(expected_rsus.size()) + " expected RSUs");
  if (!(std::isfinite(round_deadline_s) && round_deadline_s > 0))
    badOption("round_deadline_s = " + std::to_string(round_deadline_s) + " must be finite and > 0");
  if (!(liveness_timeout_s > 0))  // also rejects NaN; +inf allowed
    badOption("liveness_timeout_s = " + std::to_string(liveness_timeout_s) + " must be > 0");
  if (max_samples == 0) badOption("max_samples = 0 must be >= 1");
  if (!(std::isfinite(max_update_norm_ratio) && max_update_norm_ratio >= 0))
    badOption("max_update_norm_ratio = " + std::to_string(max_update_norm_ratio) +
              " must be finite and >= 0");
  if (!(trim_fraction >= 0 && trim_fraction < 0.5))
    badOption("trim_fraction = " + std::to_string(trim_fraction) + " must be in [0, 0.5)");
}

FederationServer::FederationServer(FederationOptions options)
    : options_(std::move(options)), quorum_(0) {
  options_.validate();
  quorum_ = options_.effectiveQuorum();
}

void FederationServer::initialize(ModelBlob initial) {
  if (initial.values.empty())
    throw std::invalid_argument("FederationServer::initialize: the initial model has no values");
  validateModelBlob(initial);  // throws invalid_argument naming the problem
  global_ = std::make_shared<const ModelBlob>(std::move(initial));
  round_ = 1;
  version_ = 1;
  submissions_.clear();
  last_heard_s_.clear();
  std::fill(std::begin(rejected_), std::end(rejected_), 0);
  fetch_unknown_rsu_ = accepted_total_ = rounds_closed_ = failed_aggregations_ = 0;
  bytes_in_round_ = 0;
  last_round_ = RoundReport{};
}

void FederationServer::requireReady(double now_s, const char* who) const {
  if (!global_)
    throw std::logic_error(std::string("FederationServer::") + who +
                           " before initialize() or loadCheckpoint()");
  if (!std::isfinite(now_s))
    throw std::invalid_argument(std::string("FederationServer::") + who + ": now_s = " +
                                std::to_string(now_s) + " is not finite");
}

bool FederationServer::checkSubmission(const std::string& rsu_id, uint32_t round,
                                       uint32_t base_version, const ModelBlob& blob,
                                       uint64_t n_k, SubmitResult& r) const {
  auto refuse = [&r](Rejection why, const std::string& text) {
    r.rejection = why;
    r.reason = std::string(rejectionName(why)) + ": " + text;
    return false;
  };
  const ModelBlob& g = *global_;
  const auto& ids = options_.expected_rsus;
  if (std::find(ids.begin(), ids.end(), rsu_id) == ids.end())
    return refuse(Rejection::kUnknownRsu, "RSU '" + rsu_id + "' is not an expected RSU");
  if (round != round_)
    return refuse(Rejection::kWrongRound, "round " + std::to_string(round) +
                                              " is not the open round " + std::to_string(round_));
  if (base_version != version_)
    return refuse(Rejection::kStaleBaseVersion,
                  "trained from global version " + std::to_string(base_version) +
                      ", the current one is " + std::to_string(version_));
  if (submissions_.count(rsu_id))
    return refuse(Rejection::kDuplicate, "RSU '" + rsu_id + "' already submitted in round " +
                                             std::to_string(round_));
  if (n_k == 0 || n_k > options_.max_samples)
    return refuse(Rejection::kBadSampleCount, "n_k = " + std::to_string(n_k) + " is outside [1, " +
                                                  std::to_string(options_.max_samples) + "]");
  const BlobCheck check = checkModelBlob(blob, &g, "the global model");
  switch (check.problem) {
    case BlobProblem::kNone: break;
    case BlobProblem::kLayoutMismatch: return refuse(Rejection::kLayoutMismatch, check.detail);
    case BlobProblem::kWrongValueCount: return refuse(Rejection::kWrongValueCount, check.detail);
    case BlobProblem::kNonFinite: return refuse(Rejection::kNonFinite, check.detail);
  }
  if (options_.max_update_norm_ratio > 0) {
    double update2 = 0.0, global2 = 0.0;
    for (size_t i = 0; i < blob.values.size(); ++i) {
      const double d = double(blob.values[i]) - double(g.values[i]);
      update2 += d * d;
      global2 += double(g.values[i]) * double(g.values[i]);
    }
    const double ratio = std::sqrt(update2) / std::max(std::sqrt(global2), 1e-12);
    if (!(ratio <= options_.max_update_norm_ratio)) {
      std::ostringstream text;
      text << "update norm " << std::sqrt(update2) << " is " << ratio
           << " x the global model's norm, above the bound " << options_.max_update_norm_ratio;
      return refuse(Rejection::kUpdateTooLarge, text.str());
    }
  }
  return true;
}

SubmitResult FederationServer::submit(const std::string& rsu_id, uint32_t round,
                                      uint32_t base_version, ModelBlob blob, uint64_t n_k,
                                      double now_s) {
  requireReady(now_s, "submit");
  SubmitResult r;
  r.accepted = checkSubmission(rsu_id, round, base_version, blob, n_k, r);
  if (!r.accepted) {
    ++rejected_[static_cast<size_t>(r.rejection)];
  } else {
    if (submissions_.empty()) first_submit_s_ = now_s;  // the deadline counts from here
    bytes_in_round_ += payloadBytes(blob);
    submissions_[rsu_id] = Submission{std::move(blob), n_k};
    last_heard_s_[rsu_id] = now_s;
    ++accepted_total_;
  }
  r.round = round_;
  r.global_version = version_;
  return r;
}

SubmitResult FederationServer::refuse(Rejection why, const std::string& detail) {
  SubmitResult r;
  r.rejection = why;
  r.reason = std::string(rejectionName(why)) + ": " + detail;
  ++rejected_[static_cast<size_t>(why)];
  r.round = round_;
  r.global_version = version_;
  return r;
}

bool FederationServer::isLive(const std::string& rsu_id, double now_s) const {
  const auto it = last_heard_s_.find(rsu_id);
  return it != last_heard_s_.end() && now_s - it->second <= options_.liveness_timeout_s;
}

bool FederationServer::allLiveSubmitted(double now_s) const {
  for (const std::string& id : options_.expected_rsus)
    if (!submissions_.count(id) && isLive(id, now_s)) return false;
  return true;
}

bool FederationServer::poll(double now_s) {
  requireReady(now_s, "poll");
  if (submissions_.empty()) return false;  // a round never closes empty
  // Sim time restarts with each episode: count the deadline from the restart instead of
  // waiting for the new episode's clock to pass the old one's.
  if (now_s < first_submit_s_) first_submit_s_ = now_s;
  if (allLiveSubmitted(now_s)) {
    closeRound(now_s, false);
    return true;
  }
  if (now_s - first_submit_s_ >= options_.round_deadline_s && submissions_.size() >= quorum_) {
    closeRound(now_s, true);
    return true;
  }
  return false;
}

void FederationServer::closeRound(double now_s, bool on_deadline) {
  RoundReport report;
  report.round = round_;
  report.on_deadline = on_deadline;
  report.duration_s = now_s - first_submit_s_;
  report.bytes_in = bytes_in_round_;
  std::vector<ModelBlob> models;
  std::vector<uint64_t> counts;
  models.reserve(submissions_.size());
  for (auto& [id, s] : submissions_) {
    report.sample_counts[id] = s.n_k;
    models.push_back(std::move(s.model));
    counts.push_back(s.n_k);
  }
  // theta^{r+1} = sum_k (n_k / n) theta_k^r over the whole model (paper "Problem
  // Formulation"). Inputs were validated at submit; a convex combination of finite floats
  // is finite, so the checks below guard against a broken invariant, not a normal case.
  ModelBlob average;
  try {
    switch (options_.aggregation) {
      case FederationOptions::Aggregation::kFedAvg:
        average = fedAverage(models, counts, options_.max_samples);
        break;
      case FederationOptions::Aggregation::kMedian:
        average = coordinateMedian(models);
        break;
      case FederationOptions::Aggregation::kTrimmedMean:
        average = trimmedMean(models, options_.trim_fraction);
        break;
    }
    validateModelBlob(average);
    report.aggregated = true;
  } catch (const std::invalid_argument&) {
    report.aggregated = false;
  }
  if (report.aggregated) {
    global_ = std::make_shared<const ModelBlob>(std::move(average));
    ++version_;
  } else {
    ++failed_aggregations_;
  }
  ++round_;
  ++rounds_closed_;
  submissions_.clear();
  bytes_in_round_ = 0;
  report.global_version = version_;
  last_round_ = std::move(report);
}

FetchResult FederationServer::fetch(const std::string& rsu_id, uint32_t min_version,
                                    double now_s) {
  requireReady(now_s, "fetch");
  FetchResult r;
  r.round = round_;
  r.global_version = version_;
  const auto& ids = options_.expected_rsus;
  if (std::find(ids.begin(), ids.end(), rsu_id) == ids.end()) {
    ++fetch_unknown_rsu_;
    r.reason = "unknown_rsu: RSU '" + rsu_id + "' is not an expected RSU";
    return r;
  }
  last_heard_s_[rsu_id] = now_s;
  if (version_ < min_version) {
    r.reason = "global version " + std::to_string(version_) + " < requested " +
               std::to_string(min_version) + " (round " + std::to_string(round_) + " open)";
    return r;
  }
  r.available = true;
  r.model = global_;
  return r;
}

FederationStatus FederationServer::status() const {
  FederationStatus s;
  s.round = round_;
  s.global_version = version_;
  for (const auto& entry : submissions_) s.submitted.push_back(entry.first);  // map: sorted
  for (size_t i = 0; i < REJECTION_COUNT; ++i)
    s.rejected_by_reason[rejectionName(static_cast<Rejection>(i))] = rejected_[i];
  s.fetch_unknown_rsu = fetch_unknown_rsu_;
  s.accepted_total = accepted_total_;
  s.rounds_closed = rounds_closed_;
  s.failed_aggregations = failed_aggregations_;
  s.last_round_s = last_round_.duration_s;
  s.bytes_in_round = bytes_in_round_;
  s.bytes_in_last_round = last_round_.bytes_in;
  return s;
}

}  // namespace palcas
