#include "palcas_core/federation/federation_client.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace palcas {

const char* federationEventName(FederationEvent e) {
  switch (e) {
    case FederationEvent::kUnreachable: return "unreachable";
    case FederationEvent::kLoaded: return "loaded";
    case FederationEvent::kModelRefused: return "model_refused";
    case FederationEvent::kSubmitted: return "submitted";
    case FederationEvent::kSubmitRefused: return "submit_refused";
  }
  return "unknown";
}

void FederationClientOptions::validate() const {
  if (rsu_id.empty()) throw std::invalid_argument("federation client: rsu_id is empty");
  if (!std::isfinite(heartbeat_s) || heartbeat_s < 0)
    throw std::invalid_argument("federation client: heartbeat_s must be >= 0 and finite, got " +
                                std::to_string(heartbeat_s));
}

FederationClient::FederationClient(FederationClientOptions options, FederatedModel& model,
                                   FederationTransport& transport, Listener listener)
    : options_(std::move(options)), model_(model), transport_(transport), listener_(std::move(listener)) {
  options_.validate();
}

void FederationClient::tell(FederationEvent e, const std::string& message) const {
  if (listener_) listener_(e, options_.rsu_id + ": " + message);
}

bool FederationClient::join() {
  return fetchGlobal(model_.modelVersion() == 0 ? 1 : model_.modelVersion() + 1);
}

bool FederationClient::fetchGlobal(uint32_t min_version) {
  ++calls_;
  FetchReply reply = transport_.fetch(options_.rsu_id, min_version);
  reachable_ = reply.reachable;
  if (!reply.reachable) {
    tell(FederationEvent::kUnreachable, "federation server unreachable; advising with the local model");
    return false;
  }
  if (!reply.available) return false;
  if (!reply.refused.empty()) {
    tell(FederationEvent::kModelRefused,
         "refused a global model that is not the server's (" + reply.refused + "); keeping the local one");
    return false;
  }
  server_round_ = reply.round;
  try {
    model_.loadGlobal(reply.model, reply.model_version);
  } catch (const std::invalid_argument& e) {
    tell(FederationEvent::kModelRefused,
         std::string("refused the global model: ") + e.what() + "; keeping the local one");
    return false;
  }
  submitted_ = false;
  tell(FederationEvent::kLoaded, "loaded global model version " + std::to_string(reply.model_version) +
                                     " (round " + std::to_string(server_round_) + " open)");
  return true;
}

void FederationClient::submit() {
  Submission s;
  s.rsu_id = options_.rsu_id;
  s.round = server_round_;
  s.base_version = model_.modelVersion();
  s.model = model_.exportModel();
  s.sample_count = model_.samplesSinceFederation();
  ++calls_;
  const SubmitReply reply = transport_.submit(s);
  reachable_ = reply.reachable;
  if (!reply.reachable) {
    tell(FederationEvent::kUnreachable, "federation server unreachable; will submit again later");
    return;
  }
  server_round_ = reply.round;
  if (reply.accepted) {
    submitted_ = true;
    tell(FederationEvent::kSubmitted, "submitted model for round " + std::to_string(s.round) +
                                          " (n_k = " + std::to_string(s.sample_count) + ")");
  } else if (reply.global_version > model_.modelVersion()) {
    // The round moved on without us (we were late or away): take the newer global model.
    tell(FederationEvent::kSubmitRefused, "submission refused (" + reply.reason +
                                              "); fetching global version " +
                                              std::to_string(reply.global_version));
    fetchGlobal(reply.global_version);
  } else {
    tell(FederationEvent::kSubmitRefused, "submission refused: " + reply.reason);
  }
}

void FederationClient::announceVersion(uint32_t version) {
  announced_ = true;
  announced_version_ = std::max(announced_version_, version);
}

void FederationClient::onDecision(double now_s) {
  if (!std::isfinite(now_s)) throw std::invalid_argument("federation client: now_s is not finite");
  // The sim clock restarts with every episode: a call "in the future" is from the last one.
  if (last_call_s_ > now_s) last_call_s_ = now_s;
  if (submitted_) {  // waiting for the round to close: poll without blocking the advisories
    const bool told_newer = announced_ && announced_version_ > model_.modelVersion();
    const bool heartbeat_due = options_.heartbeat_s > 0 && now_s - last_call_s_ >= options_.heartbeat_s;
    if (announced_ && !told_newer && !heartbeat_due) return;
    last_call_s_ = now_s;
    fetchGlobal(model_.modelVersion() + 1);
    return;
  }
  if (!model_.federationDue()) {
    if (options_.heartbeat_s > 0 && now_s - last_call_s_ >= options_.heartbeat_s) {
      last_call_s_ = now_s;
      fetchGlobal(model_.modelVersion() + 1);
    }
    return;
  }
  last_call_s_ = now_s;
  submit();
}

}  // namespace palcas
