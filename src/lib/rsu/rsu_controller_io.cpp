// RsuController: federation model exchange and checkpoints. Reasons: src/doc/rsu.md.
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "palcas_core/common/atomic_file.h"
#include "palcas_core/rsu/rsu_controller.h"
#include "palcas_core/state/state_layout.h"

namespace palcas::rsu {

namespace {

constexpr const char* CONTROLLER_FILE = "controller.txt";
constexpr const char* AGENT_FILE = "agent.ckpt";
constexpr const char* CONTROLLER_MAGIC = "palcas_rsu_controller 1";

// Counters of the controller file, every key required exactly once.
struct ControllerCounters {
  std::string rsu_id;
  uint64_t layout_checksum = 0;
  uint64_t samples_since_federation = 0;
  double gradient_credit = 0.0;
  uint64_t grad_steps_at_round = 0;
  uint64_t model_version = 0;
  uint64_t federation_round = 0;
  uint64_t transitions_stored = 0;
  uint64_t decisions = 0;
  uint64_t checkpoint_id = 0;  ///< random per write; 0 in files from before it existed
};

std::string joinPath(const std::string& dir, const char* file) {
  return (std::filesystem::path(dir) / file).string();
}

uint64_t parseU64(const std::string& text, const std::string& where) {
  size_t used = 0;
  unsigned long long v = 0;
  try {
    if (!text.empty() && text[0] != '-') v = std::stoull(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw std::runtime_error(where + ": '" + text + "' is not an unsigned integer");
  return v;
}

double parseCredit(const std::string& text, const std::string& where) {
  size_t used = 0;
  double v = -1.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v) || v < 0.0 || v >= 1.0)
    throw std::runtime_error(where + ": '" + text + "' is not a gradient credit in [0, 1)");
  return v;
}

ControllerCounters readCounters(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read RSU checkpoint file " + path);
  std::string line;
  if (!std::getline(in, line) || line != CONTROLLER_MAGIC)
    throw std::runtime_error(path + ": not a PALCAS RSU controller checkpoint (first line '" +
                             line + "', expected '" + CONTROLLER_MAGIC + "')");
  std::map<std::string, std::string> kv;
  for (int number = 2; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    const size_t space = line.find(' ');
    const std::string key = line.substr(0, space);
    const std::string value = space == std::string::npos ? "" : line.substr(space + 1);
    if (!kv.emplace(key, value).second)
      throw std::runtime_error(path + ":" + std::to_string(number) + ": duplicate key '" + key +
                               "'");
  }
  ControllerCounters c;
  const std::map<std::string, uint64_t*> numbers = {
      {"layout_checksum", &c.layout_checksum},
      {"samples_since_federation", &c.samples_since_federation},
      {"grad_steps_at_round", &c.grad_steps_at_round},
      {"model_version", &c.model_version},
      {"federation_round", &c.federation_round},
      {"transitions_stored", &c.transitions_stored},
      {"decisions", &c.decisions}};
  for (const auto& [key, value] : kv) {
    const std::string where = path + ": key '" + key + "'";
    if (key == "rsu_id") c.rsu_id = value;
    else if (key == "checkpoint_id") c.checkpoint_id = parseU64(value, where);  // optional
    else if (key == "gradient_credit") c.gradient_credit = parseCredit(value, where);
    else if (numbers.count(key) > 0) *numbers.at(key) = parseU64(value, where);
    else throw std::runtime_error(path + ": unknown key '" + key + "'");
  }
  for (const char* key : {"rsu_id", "gradient_credit"})
    if (kv.count(key) == 0) throw std::runtime_error(path + ": missing key '" + key + "'");
  for (const auto& entry : numbers)
    if (kv.count(entry.first) == 0)
      throw std::runtime_error(path + ": missing key '" + entry.first + "'");
  for (uint64_t v : {c.model_version, c.federation_round})
    if (v > UINT32_MAX) throw std::runtime_error(path + ": version or round beyond 32 bits");
  return c;
}

}  // namespace

void RsuController::loadGlobalModel(const ModelBlob& blob, uint32_t version) {
  if (version < model_version_)
    throw std::invalid_argument("RsuController::loadGlobalModel: version " +
                                std::to_string(version) + " is older than the current " +
                                std::to_string(model_version_));
  agent_.importModel(blob);  // throws std::invalid_argument, agent untouched
  model_version_ = version;
  ++federation_round_;
  samples_since_federation_ = 0;
  grad_steps_at_round_ = agent_.gradientSteps();
}

void RsuController::loadPolicy(const std::string& path) { agent_.loadModel(path); }

void RsuController::saveCheckpoint(const std::string& dir) const {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create checkpoint directory " + dir + ": " + ec.message());
  // Only the owner of the checkpoint on disk may replace it: the process that loaded it or
  // wrote it last. A stale or orphaned process (an older launch still running) finds
  // another writer's id there and must not overwrite newer state.
  const std::string counters_path = joinPath(dir, CONTROLLER_FILE);
  if (std::filesystem::exists(counters_path)) {
    const ControllerCounters on_disk = readCounters(counters_path);
    if (!checkpoint_owned_ || on_disk.checkpoint_id != checkpoint_seen_id_)
      throw std::runtime_error(
          dir + " holds a checkpoint this process neither loaded nor wrote (decisions " +
          std::to_string(on_disk.decisions) + ", this process " + std::to_string(stats_.decisions) +
          "): another process owns it, so it is not overwritten");
  }
  static thread_local std::mt19937_64 ids{std::random_device{}()};
  uint64_t id = 0;
  while (id == 0) id = ids();
  agent_.saveCheckpoint(joinPath(dir, AGENT_FILE));  // atomic (temp file + rename)
  std::ostringstream text;
  text.precision(17);  // the credit round-trips exactly
  text << CONTROLLER_MAGIC << "\n"
       << "rsu_id " << options_.rsu_id << "\n"
       << "layout_checksum " << agent_.layoutChecksum() << "\n"
       << "samples_since_federation " << samples_since_federation_ << "\n"
       << "gradient_credit " << gradient_credit_ << "\n"
       << "grad_steps_at_round " << grad_steps_at_round_ << "\n"
       << "model_version " << model_version_ << "\n"
       << "federation_round " << federation_round_ << "\n"
       << "transitions_stored " << stats_.transitions_stored << "\n"
       << "decisions " << stats_.decisions << "\n"
       << "checkpoint_id " << id << "\n";
  writeFileAtomically(counters_path, text.str());
  checkpoint_owned_ = true;
  checkpoint_seen_id_ = id;
}

void RsuController::loadCheckpoint(const std::string& dir) {
  const std::string path = joinPath(dir, CONTROLLER_FILE);
  const ControllerCounters c = readCounters(path);  // every check before any change
  if (c.rsu_id != options_.rsu_id)
    throw std::runtime_error(path + ": written by RSU '" + c.rsu_id + "', this is '" +
                             options_.rsu_id + "'");
  if (c.layout_checksum != agent_.layoutChecksum())
    throw std::runtime_error(path + ": written by an agent of another layout (checksum " +
                             std::to_string(c.layout_checksum) + ", this agent " +
                             std::to_string(agent_.layoutChecksum()) + ")");
  // An agent.ckpt written before the masks were stored holds transitions without them: the
  // lane of s' is read from its ego-lane feature (lane / L) as the agent read it then, so a
  // resumed training computes the same TD targets as if it had not stopped.
  const int lanes = options_.num_lanes;
  const nn::Index lane_row = StateLayout(lanes).ego(EgoFeature::kLane);
  const auto mask_of_next_state = [lanes, lane_row](const nn::Vector& next_state) {
    return possibleActions(static_cast<int>(std::lround(next_state(lane_row) * lanes)), lanes);
  };
  // throws std::runtime_error, agent untouched
  agent_.loadCheckpoint(joinPath(dir, AGENT_FILE), mask_of_next_state);
  samples_since_federation_ = c.samples_since_federation;
  gradient_credit_ = c.gradient_credit;
  grad_steps_at_round_ = c.grad_steps_at_round;
  model_version_ = static_cast<uint32_t>(c.model_version);
  federation_round_ = static_cast<uint32_t>(c.federation_round);
  stats_.transitions_stored = c.transitions_stored;
  stats_.decisions = c.decisions;
  book_.dropPending();  // they belong to the run that wrote the checkpoint
  have_last_step_ = false;
  checkpoint_owned_ = true;  // this process continues that checkpoint and may replace it
  checkpoint_seen_id_ = c.checkpoint_id;
}

}  // namespace palcas::rsu
