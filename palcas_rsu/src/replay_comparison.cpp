#include "palcas_rsu/replay_comparison.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <set>

namespace palcas::rsu {

const char* const REPLAY_USAGE =
    "usage: replay_policy BAG --policy DIR [--csv FILE] [--accel-tolerance MPS2]\n"
    "  BAG      a bag recorded by ./palcas run --record (system.launch record:=true)\n"
    "  DIR      a training's checkpoints/ folder, or a policy folder that contains checkpoints/\n"
    "  FILE     every disagreement as CSV (default: BAG without .bag + .replay.csv)\n"
    "  MPS2     ACCELERATE advisories agree within this [m/s^2] (default 0.001)\n"
    "RSU parameters: from the parameter server under ~ (./palcas replay loads them).\n";

const char* const ReplayComparison::CSV_HEADER =
    "step,time_s,rsu,vehicle,recorded_action,recorded_accel_mps2,replayed_action,replayed_accel_mps2";

ReplayArgs parseReplayArgs(const std::vector<std::string>& argv) {
  ReplayArgs a;
  for (std::size_t i = 0; i < argv.size(); ++i) {
    const std::string& s = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argv.size() || argv[i + 1].rfind("--", 0) == 0)
        throw ReplayUsageError("option " + s + " needs a value");
      return argv[++i];
    };
    if (s == "--policy") {
      a.policy = value();
    } else if (s == "--csv") {
      a.csv = value();
    } else if (s == "--accel-tolerance") {
      const std::string v = value();
      char* end = nullptr;
      a.accel_tolerance = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(a.accel_tolerance >= 0.0) || !std::isfinite(a.accel_tolerance))
        throw ReplayUsageError("--accel-tolerance '" + v + "': expected a number >= 0");
    } else if (s == "-h" || s == "--help") {
      a.help = true;
      return a;
    } else if (s.rfind("--", 0) == 0) {
      throw ReplayUsageError("unknown option '" + s + "'");
    } else if (a.bag.empty()) {
      a.bag = s;
    } else {
      throw ReplayUsageError("one bag only; '" + s + "' is a second");
    }
  }
  if (a.bag.empty()) throw ReplayUsageError("no bag given");
  if (a.policy.empty()) throw ReplayUsageError("--policy DIR is required");
  if (a.csv.empty()) {
    const std::filesystem::path p(a.bag);
    a.csv = (p.parent_path() / (p.stem().string() + ".replay.csv")).string();
  }
  return a;
}

const char* replayActionName(int action) {
  switch (action) {
    case -1: return "none";
    case palcas_msgs::Advisory::LANE_LEFT: return "LANE_LEFT";
    case palcas_msgs::Advisory::LANE_RIGHT: return "LANE_RIGHT";
    case palcas_msgs::Advisory::ACCELERATE: return "ACCELERATE";
    case palcas_msgs::Advisory::KEEP: return "KEEP";
    default: return "UNKNOWN";
  }
}

std::string Agreement::percent() const {
  if (compared == 0) return "n/a";
  char text[32];
  std::snprintf(text, sizeof text, "%.2f %%", 100.0 * static_cast<double>(agreed) / static_cast<double>(compared));
  return text;
}

namespace {

struct Advice {
  int action = -1;  ///< -1: none for that vehicle
  double accel_mps2 = 0.0;
};

std::map<std::string, Advice> byVehicle(const palcas_msgs::AdvisoryArray& array) {
  std::map<std::string, Advice> out;
  for (const palcas_msgs::Advisory& a : array.advisories) out[a.vehicle_id] = Advice{a.action, a.accel_mps2};
  return out;
}

std::string adviceText(const Advice& a) {
  if (a.action != palcas_msgs::Advisory::ACCELERATE) return replayActionName(a.action);
  char text[64];
  std::snprintf(text, sizeof text, "ACCELERATE %+.4f", a.accel_mps2);
  return text;
}

}  // namespace

void ReplayComparison::compare(std::uint64_t step, double time_s, const std::string& rsu_id,
                               const palcas_msgs::AdvisoryArray& recorded, const palcas_msgs::AdvisoryArray& replayed) {
  const std::map<std::string, Advice> said = byVehicle(recorded), now = byVehicle(replayed);
  std::set<std::string> vehicles;
  for (const auto& [v, _] : said) vehicles.insert(v);
  for (const auto& [v, _] : now) vehicles.insert(v);
  for (const std::string& v : vehicles) {
    const auto w = said.find(v), n = now.find(v);
    const Advice was = w == said.end() ? Advice{} : w->second;
    const Advice got = n == now.end() ? Advice{} : n->second;
    const bool agree = was.action == got.action && (was.action != palcas_msgs::Advisory::ACCELERATE ||
                                                    std::abs(was.accel_mps2 - got.accel_mps2) <= tolerance_);
    for (Agreement* t : {&total_, &by_rsu_[rsu_id], &by_action_[was.action]}) {
      ++t->compared;
      if (agree) ++t->agreed;
    }
    if (agree) continue;
    char row[512];
    std::snprintf(row, sizeof row, "%lu,%.3f,%s,%s,%s,%.6f,%s,%.6f", static_cast<unsigned long>(step), time_s,
                  rsu_id.c_str(), v.c_str(), replayActionName(was.action), was.accel_mps2, replayActionName(got.action),
                  got.accel_mps2);
    rows_.emplace_back(row);
    if (first_divergence_.empty()) {
      char text[512];
      std::snprintf(text, sizeof text, "step %lu (t = %.1f s), %s, vehicle %s: recorded %s, replayed %s",
                    static_cast<unsigned long>(step), time_s, rsu_id.c_str(), v.c_str(), adviceText(was).c_str(),
                    adviceText(got).c_str());
      first_divergence_ = text;
    }
  }
}

}  // namespace palcas::rsu
