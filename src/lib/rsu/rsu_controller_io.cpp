// RsuController: federation model exchange and checkpoints. Reasons: src/doc/rsu.md.
#include <algorithm>
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
#include <variant>

#include "palcas_core/common/atomic_file.h"
#include "palcas_core/rsu/rsu_controller.h"
#include "palcas_core/state/state_layout.h"

namespace palcas::rsu {

namespace {

constexpr const char* CONTROLLER_FILE = "controller.txt";
constexpr const char* AGENT_FILE = "agent.ckpt";
constexpr const char* CONTROLLER_MAGIC = "palcas_rsu_controller 1";

// Everything controller.txt holds: the counters, and what ties the file to an RSU, an agent
// layout and one write.
struct ControllerFile : ControllerCounters {
  std::string rsu_id;
  uint64_t layout_checksum = 0;
  uint64_t checkpoint_id = 0;  ///< random per write; 0 in files from before it existed
};

// The one list of controller.txt's keys, in the order they are written (byte-compatible
// with every file written before this table: keep the order). Each is required exactly
// once when read, but checkpoint_id (absent from older files).
using FileMember = std::variant<std::string ControllerFile::*, uint64_t ControllerFile::*,
                                uint32_t ControllerFile::*, double ControllerFile::*>;
struct FileKey {
  const char* name;
  FileMember member;
  bool required;
};
const FileKey FILE_KEYS[] = {
    {"rsu_id", &ControllerFile::rsu_id, true},
    {"layout_checksum", &ControllerFile::layout_checksum, true},
    {"samples_since_federation", &ControllerFile::samples_since_federation, true},
    {"gradient_credit", &ControllerFile::gradient_credit, true},
    {"grad_steps_at_round", &ControllerFile::grad_steps_at_round, true},
    {"model_version", &ControllerFile::model_version, true},
    {"federation_round", &ControllerFile::federation_round, true},
    {"transitions_stored", &ControllerFile::transitions_stored, true},
    {"decisions", &ControllerFile::decisions, true},
    {"checkpoint_id", &ControllerFile::checkpoint_id, false},
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

// Sets the member of `key` from its text `value` (`where`: file and key, for the errors).
void parseValue(const FileKey& key, const std::string& value, const std::string& path,
                const std::string& where, ControllerFile& file) {
  struct Parse {
    const std::string &value, &path, &where;
    ControllerFile& file;
    void operator()(std::string ControllerFile::*m) const { file.*m = value; }
    void operator()(uint64_t ControllerFile::*m) const { file.*m = parseU64(value, where); }
    void operator()(uint32_t ControllerFile::*m) const {
      const uint64_t v = parseU64(value, where);
      if (v > UINT32_MAX) throw std::runtime_error(path + ": version or round beyond 32 bits");
      file.*m = static_cast<uint32_t>(v);
    }
    void operator()(double ControllerFile::*m) const { file.*m = parseCredit(value, where); }
  };
  std::visit(Parse{value, path, where, file}, key.member);
}

ControllerFile readControllerFile(const std::string& path) {
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
  ControllerFile file;
  for (const auto& [name, value] : kv) {
    const auto key = std::find_if(std::begin(FILE_KEYS), std::end(FILE_KEYS),
                                  [&name = name](const FileKey& k) { return name == k.name; });
    if (key == std::end(FILE_KEYS)) throw std::runtime_error(path + ": unknown key '" + name + "'");
    parseValue(*key, value, path, path + ": key '" + name + "'", file);
  }
  for (const FileKey& key : FILE_KEYS)
    if (key.required && kv.count(key.name) == 0)
      throw std::runtime_error(path + ": missing key '" + key.name + "'");
  return file;
}

std::string formatControllerFile(const ControllerFile& file) {
  std::ostringstream text;
  text.precision(17);  // the credit round-trips exactly
  text << CONTROLLER_MAGIC << "\n";
  for (const FileKey& key : FILE_KEYS)
    std::visit([&](auto member) { text << key.name << " " << file.*member << "\n"; }, key.member);
  return text.str();
}

}  // namespace

void RsuController::loadGlobalModel(const ModelBlob& blob, uint32_t version) {
  if (version < counters_.model_version)
    throw std::invalid_argument("RsuController::loadGlobalModel: version " +
                                std::to_string(version) + " is older than the current " +
                                std::to_string(counters_.model_version));
  if (personal_head_.empty()) {
    agent_.importModel(blob);  // throws std::invalid_argument, agent untouched
  } else {
    // The federation's body under this RSU's own head. A blob of another shape is left to
    // importModel's checks, which name what is wrong.
    ModelBlob merged = blob;
    const ModelBlob own = agent_.exportModel();
    if (merged.layout_id == own.layout_id && merged.values.size() == own.values.size())
      for (const nn::Network::StateSpan& span : personal_head_)
        std::copy_n(own.values.begin() + span.begin, span.count, merged.values.begin() + span.begin);
    agent_.importModel(merged);
  }
  counters_.model_version = version;
  ++counters_.federation_round;
  counters_.samples_since_federation = 0;
  counters_.grad_steps_at_round = agent_.gradientSteps();
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
    const ControllerFile on_disk = readControllerFile(counters_path);
    if (!checkpoint_owned_ || on_disk.checkpoint_id != checkpoint_seen_id_)
      throw std::runtime_error(
          dir + " holds a checkpoint this process neither loaded nor wrote (decisions " +
          std::to_string(on_disk.decisions) + ", this process " +
          std::to_string(counters_.decisions) +
          "): another process owns it, so it is not overwritten");
  }
  static thread_local std::mt19937_64 ids{std::random_device{}()};
  uint64_t id = 0;
  while (id == 0) id = ids();
  agent_.saveCheckpoint(joinPath(dir, AGENT_FILE));  // atomic (temp file + rename)
  ControllerFile file;
  static_cast<ControllerCounters&>(file) = counters_;
  file.rsu_id = options_.rsu_id;
  file.layout_checksum = agent_.layoutChecksum();
  file.checkpoint_id = id;
  writeFileAtomically(counters_path, formatControllerFile(file));
  checkpoint_owned_ = true;
  checkpoint_seen_id_ = id;
}

void RsuController::loadCheckpoint(const std::string& dir) {
  const std::string path = joinPath(dir, CONTROLLER_FILE);
  const ControllerFile c = readControllerFile(path);  // every check before any change
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
  counters_ = c;  // the counters part of the file
  book_.dropPending();  // they belong to the run that wrote the checkpoint
  have_last_step_ = false;
  checkpoint_owned_ = true;  // this process continues that checkpoint and may replace it
  checkpoint_seen_id_ = c.checkpoint_id;
}

}  // namespace palcas::rsu
