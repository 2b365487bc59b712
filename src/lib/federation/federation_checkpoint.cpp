// FederationServer checkpoints (global model file + state JSON) and the status JSON line.
#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "federation_json.h"
#include "palcas_core/common/atomic_file.h"
#include "palcas_core/federation/federation_server.h"
#include "palcas_core/learning/nn/serialization.h"

namespace palcas {

namespace {

constexpr char STATE_FORMAT[] = "palcas_federation_state";
constexpr uint64_t STATE_FORMAT_VERSION = 1;

// FNV-1a 64 of the model's float bytes: ties the state file to the model file it was
// written with (a crash between the two renames leaves a detectable mismatch).
uint64_t valuesChecksum(const ModelBlob& blob) {
  return nn::fnv1a64(blob.values.data(), blob.values.size() * sizeof(float));
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

uint32_t asUint32(const json::Value& v, const std::string& what) {
  const uint64_t x = json::asUint(v, what);
  if (x < 1 || x > UINT32_MAX)
    throw std::runtime_error(what + " = " + std::to_string(x) + " is outside [1, 2^32)");
  return static_cast<uint32_t>(x);
}

std::string countsJson(const std::map<std::string, uint64_t>& counts) {
  std::string out = "{";
  for (const auto& [name, n] : counts)
    out += (out.size() > 1 ? "," : "") + json::quote(name) + ":" + std::to_string(n);
  return out + "}";
}

}  // namespace

void FederationServer::saveCheckpoint(const std::string& dir) const {
  if (!global_) throw std::runtime_error("FederationServer::saveCheckpoint before initialize()");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error(dir + ": cannot create the checkpoint folder: " + ec.message());
  const FederationStatus s = status();
  // Model first, state second: the state names the model it belongs to by checksum.
  saveModelBlob(*global_, dir + "/" + MODEL_FILE);
  std::ostringstream out;
  out << "{\n  \"format\": " << json::quote(STATE_FORMAT)
      << ",\n  \"format_version\": " << STATE_FORMAT_VERSION << ",\n  \"round\": " << round_
      << ",\n  \"global_version\": " << version_
      << ",\n  \"model_file\": " << json::quote(MODEL_FILE)
      << ",\n  \"model_value_count\": " << global_->values.size()
      << ",\n  \"model_values_fnv1a64\": " << valuesChecksum(*global_)
      << ",\n  \"rejected_by_reason\": " << countsJson(s.rejected_by_reason)
      << ",\n  \"fetch_unknown_rsu\": " << fetch_unknown_rsu_
      << ",\n  \"accepted_total\": " << accepted_total_
      << ",\n  \"rounds_closed\": " << rounds_closed_
      << ",\n  \"failed_aggregations\": " << failed_aggregations_
      << ",\n  \"last_round_s\": " << json::number(last_round_.duration_s)
      << ",\n  \"bytes_in_last_round\": " << last_round_.bytes_in << "\n}\n";
  writeFileAtomically(dir + "/" + STATE_FILE, out.str());
}

void FederationServer::loadCheckpoint(const std::string& dir) {
  const std::string state_path = dir + "/" + STATE_FILE;
  const json::Value st = json::parse(readText(state_path), state_path);
  auto key = [&](const char* k) -> const json::Value& { return json::at(st, k, state_path); };
  auto name = [&](const char* k) { return state_path + ": '" + k + "'"; };
  auto uintOf = [&](const char* k) { return json::asUint(key(k), name(k)); };
  const std::string& format = json::asString(key("format"), name("format"));
  if (format != STATE_FORMAT)
    throw std::runtime_error(state_path + ": not a PALCAS federation state file (format '" +
                             format + "')");
  const uint64_t format_version = uintOf("format_version");
  if (format_version != STATE_FORMAT_VERSION)
    throw std::runtime_error(state_path + ": format_version " + std::to_string(format_version) +
                             " is not supported (expected " +
                             std::to_string(STATE_FORMAT_VERSION) + ")");
  const uint32_t round = asUint32(key("round"), name("round"));
  const uint32_t version = asUint32(key("global_version"), name("global_version"));
  if (version > round)  // the version advances at most once per round
    throw std::runtime_error(state_path + ": global_version " + std::to_string(version) +
                             " > round " + std::to_string(round));
  const std::string model_path = dir + "/" + MODEL_FILE;
  ModelBlob model = loadModelBlob(model_path);  // runtime_error on any file check
  if (model.values.empty() || model.values.size() != uintOf("model_value_count") ||
      valuesChecksum(model) != uintOf("model_values_fnv1a64"))
    throw std::runtime_error(model_path + " is not the model " + state_path +
                             " was written with (value count or checksum differs)");
  uint64_t rejected[REJECTION_COUNT] = {};
  const json::Value& by_reason = key("rejected_by_reason");
  if (!by_reason.is_object())
    throw std::runtime_error(name("rejected_by_reason") + " must be an object, got " +
                             json::shown(by_reason));
  // A reason added after the file was written (update_too_large, unauthenticated) counts 0;
  // an unknown one means the file is not ours.
  for (size_t i = 0; i < REJECTION_COUNT; ++i) {
    const char* reason = rejectionName(static_cast<Rejection>(i));
    const bool present = by_reason.contains(reason);
    const bool optional = static_cast<Rejection>(i) == Rejection::kUpdateTooLarge ||
                          static_cast<Rejection>(i) == Rejection::kUnauthenticated;
    if (!present && optional) continue;
    rejected[i] =
        json::asUint(json::at(by_reason, reason, name("rejected_by_reason")), name(reason));
  }
  for (const auto& item : by_reason.items()) {
    bool ours = false;
    for (size_t i = 0; i < REJECTION_COUNT && !ours; ++i)
      ours = item.key() == rejectionName(static_cast<Rejection>(i));
    if (!ours)
      throw std::runtime_error(state_path + ": 'rejected_by_reason' holds an unknown reason '" +
                               item.key() + "'");
  }
  const uint64_t fetch_unknown = uintOf("fetch_unknown_rsu");
  const uint64_t accepted = uintOf("accepted_total");
  const uint64_t closed = uintOf("rounds_closed");
  const uint64_t failed = uintOf("failed_aggregations");
  const double last_s = json::asDouble(key("last_round_s"), name("last_round_s"));
  const uint64_t last_bytes = uintOf("bytes_in_last_round");

  // Every check passed: commit.
  initialize(std::move(model));
  round_ = round;
  version_ = version;
  std::copy(std::begin(rejected), std::end(rejected), std::begin(rejected_));
  fetch_unknown_rsu_ = fetch_unknown;
  accepted_total_ = accepted;
  rounds_closed_ = closed;
  failed_aggregations_ = failed;
  last_round_.round = round - 1;
  last_round_.global_version = version;
  last_round_.duration_s = last_s;
  last_round_.bytes_in = last_bytes;
}

std::string federationStatusJson(const FederationStatus& s) {
  std::string submitted = "[";
  for (const std::string& id : s.submitted)
    submitted += (submitted.size() > 1 ? "," : "") + json::quote(id);
  submitted += "]";
  std::ostringstream out;
  out << "{\"round\":" << s.round << ",\"version\":" << s.global_version
      << ",\"submitted\":" << submitted
      << ",\"rejected_by_reason\":" << countsJson(s.rejected_by_reason)
      << ",\"fetch_unknown_rsu\":" << s.fetch_unknown_rsu
      << ",\"accepted_total\":" << s.accepted_total << ",\"rounds_closed\":" << s.rounds_closed
      << ",\"failed_aggregations\":" << s.failed_aggregations
      << ",\"last_round_s\":" << json::number(s.last_round_s)
      << ",\"bytes_in_round\":" << s.bytes_in_round
      << ",\"bytes_in_last_round\":" << s.bytes_in_last_round << "}";
  return out.str();
}

}  // namespace palcas
