// palcas_reward: the paper's reward for hand-written CAV situations, one JSON line in,
// one JSON line out, with every component and intermediate (wired as ./palcas reward).
// Output conventions: +inf prints as the string "inf" (JSON has no infinity); a value
// that does not apply (no lead -> no delta_long_lead) prints as null.
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>

#include "palcas_core/reward/reward.h"

namespace {

using nlohmann::json;
using palcas::CavSituation;

const char* const USAGE = R"(usage: palcas_reward [--param name=value ...] < situations.jsonl

Reads one CAV situation per line (JSON) on stdin and prints one JSON line per input with
the paper's reward components and intermediates. Blank lines are skipped.

Input keys (SI units, lanes 1..L from the right, 0 = acceleration lane / ramp):
  v, a, lane, num_lanes, length            ego speed, acceleration, lane, L, length
  distance_to_exit                         metres to the off-ramp; null = no exit
  lead, follow                             {"gap": m bumper to bumper, "v": m/s} or null
  lateral                                  up to 4 {"gap", "v_lat_ego", "v_lat_other"[, "long_gap"]} or null
                                           (lateral speeds positive from ego toward the other)
  target_lead                              {"distance" front-to-front, "v", "length"} or null
  target_follow                            {"distance" front-to-front, "v"} or null
  cluster_mean_speed                       m/s
  accel_lane                               {"x": position along it, "length"} or null
  v_max (optional)                         the CAV's own max speed; default param v_max_ego

Output keys: line, delta_long_lead, delta_long_follow, delta_lat, p_ttc_min, p, tau_need,
tau_tte, n, lc_factor, u, w, p_stage, r_ego, r_cluster, r_e, r_s_long, r_s_lat, r_s, r_c,
r_lc, r_d, total. +inf prints as "inf"; null = does not apply.
A malformed line prints {"line": N, "error": "..."} on stdout and the error on stderr;
the other lines are still processed and the exit status is 1.

options:
  --param name=value   override a reward constant (repeatable); see config/reward.yaml
  --help               this text
)";

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Every key of `object` must be in `allowed`; names the first stranger.
void checkKeys(const json& object, const std::string& where, const std::set<std::string>& allowed) {
  for (const auto& item : object.items())
    if (!allowed.count(item.key())) throw InputError("unknown key '" + where + item.key() + "'");
}

const json& need(const json& object, const std::string& where, const std::string& key) {
  const auto it = object.find(key);
  if (it == object.end()) throw InputError("missing key '" + where + key + "'");
  return *it;
}

double number(const json& object, const std::string& where, const std::string& key) {
  const json& value = need(object, where, key);
  if (!value.is_number()) throw InputError("'" + where + key + "' must be a number");
  const double x = value.get<double>();
  if (!std::isfinite(x)) throw InputError("'" + where + key + "' must be finite");
  return x;
}

int integer(const json& object, const std::string& key) {
  const json& value = need(object, "", key);
  if (!value.is_number_integer()) throw InputError("'" + key + "' must be an integer");
  return value.get<int>();
}

// A key that must be present and is either null or an object with exactly `keys`.
const json* optionalObject(const json& in, const std::string& key,
                           const std::set<std::string>& keys) {
  const json& value = need(in, "", key);
  if (value.is_null()) return nullptr;
  if (!value.is_object()) throw InputError("'" + key + "' must be an object or null");
  checkKeys(value, key + ".", keys);
  return &value;
}

CavSituation parseSituation(const json& in) {
  if (!in.is_object()) throw InputError("a line must be a JSON object");
  checkKeys(
      in, "",
      {"v", "a", "lane", "num_lanes", "length", "distance_to_exit", "lead", "follow", "lateral",
       "target_lead", "target_follow", "cluster_mean_speed", "accel_lane", "v_max"});
  CavSituation s;
  s.v = number(in, "", "v");
  s.a = number(in, "", "a");
  s.lane = integer(in, "lane");
  s.num_lanes = integer(in, "num_lanes");
  s.length = number(in, "", "length");
  s.distance_to_exit = need(in, "", "distance_to_exit").is_null()
                           ? std::numeric_limits<double>::infinity()
                           : number(in, "", "distance_to_exit");
  if (const json* o = optionalObject(in, "lead", {"gap", "v"}))
    s.lead = CavSituation::GapSpeed{number(*o, "lead.", "gap"), number(*o, "lead.", "v")};
  if (const json* o = optionalObject(in, "follow", {"gap", "v"}))
    s.follow = CavSituation::GapSpeed{number(*o, "follow.", "gap"), number(*o, "follow.", "v")};
  const json& lateral = need(in, "", "lateral");
  if (!lateral.is_null() && !lateral.is_array())
    throw InputError("'lateral' must be an array or null");
  if (lateral.is_array()) {
    for (size_t i = 0; i < lateral.size(); ++i) {
      const std::string where = "lateral[" + std::to_string(i) + "].";
      if (!lateral[i].is_object())
        throw InputError("'" + where.substr(0, where.size() - 1) + "' must be an object");
      checkKeys(lateral[i], where, {"gap", "v_lat_ego", "v_lat_other", "long_gap"});
      CavSituation::Lateral m{number(lateral[i], where, "gap"), number(lateral[i], where, "v_lat_ego"),
                              number(lateral[i], where, "v_lat_other")};
      if (lateral[i].contains("long_gap")) m.long_gap = number(lateral[i], where, "long_gap");
      s.lateral.push_back(m);
    }
  }
  if (const json* o = optionalObject(in, "target_lead", {"distance", "v", "length"}))
    s.target_lead = CavSituation::TargetLead{number(*o, "target_lead.", "distance"),
                                             number(*o, "target_lead.", "v"),
                                             number(*o, "target_lead.", "length")};
  if (const json* o = optionalObject(in, "target_follow", {"distance", "v"}))
    s.target_follow = CavSituation::TargetFollow{number(*o, "target_follow.", "distance"),
                                                 number(*o, "target_follow.", "v")};
  s.cluster_mean_speed = number(in, "", "cluster_mean_speed");
  if (const json* o = optionalObject(in, "accel_lane", {"x", "length"}))
    s.accel_lane = CavSituation::AccelLane{number(*o, "accel_lane.", "x"),
                                           number(*o, "accel_lane.", "length")};
  if (in.contains("v_max") && !in.at("v_max").is_null()) s.v_max = number(in, "", "v_max");
  return s;
}

// +inf -> "inf"; -0 -> 0 (u w is -0 when u = -0).
using OrderedJson = nlohmann::ordered_json;
OrderedJson value(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return x + 0.0;
}
OrderedJson value(const std::optional<double>& x) { return x ? value(*x) : OrderedJson(nullptr); }

nlohmann::ordered_json toJson(long line, const palcas::RewardBreakdown& r) {
  nlohmann::ordered_json out;
  out["line"] = line;
  out["delta_long_lead"] = value(r.delta_long_lead);
  out["delta_long_follow"] = value(r.delta_long_follow);
  out["delta_lat"] = OrderedJson::array();
  for (double d : r.delta_lat) out["delta_lat"].push_back(value(d));
  const std::pair<const char*, double> fields[] = {{"p_ttc_min", r.p_ttc_min},
                                                   {"p", r.p},
                                                   {"tau_need", r.tau_need},
                                                   {"tau_tte", r.tau_tte},
                                                   {"lc_factor", r.lc_factor},
                                                   {"u", r.u},
                                                   {"w", r.w},
                                                   {"p_stage", r.p_stage},
                                                   {"r_ego", r.r_ego},
                                                   {"r_cluster", r.r_cluster},
                                                   {"r_e", r.r_e},
                                                   {"r_s_long", r.r_s_long},
                                                   {"r_s_lat", r.r_s_lat},
                                                   {"r_s", r.r_s},
                                                   {"r_c", r.r_c},
                                                   {"r_lc", r.r_lc},
                                                   {"r_d", r.r_d},
                                                   {"total", r.total}};
  for (const auto& [key, x] : fields) out[key] = value(x);
  out["n"] = r.n;
  return out;
}

// Parses "--param name=value" into params; throws std::invalid_argument naming the problem.
void applyParam(palcas::RewardParams& params, const std::string& assignment) {
  const auto eq = assignment.find('=');
  if (eq == std::string::npos)
    throw std::invalid_argument("--param expects name=value, got '" + assignment + "'");
  const std::string name = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  char* end = nullptr;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(x))
    throw std::invalid_argument("--param " + name + ": '" + text + "' is not a finite number");
  palcas::setRewardParam(params, name, x);
}

}  // namespace

int main(int argc, char** argv) {
  palcas::RewardParams params;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--help" || arg == "-h") {
        std::cout << USAGE;
        return 0;
      }
      if (arg == "--param" && i + 1 < argc)
        applyParam(params, argv[++i]);
      else if (arg.rfind("--param=", 0) == 0)
        applyParam(params, arg.substr(8));
      else
        throw std::invalid_argument("unknown argument '" + arg + "' (see --help)");
    }
    palcas::validateRewardParams(params);
  } catch (const std::exception& e) {
    std::cerr << "palcas_reward: " << e.what() << "\n";
    return 2;
  }
  bool failed = false;
  std::string text;
  for (long line = 1; std::getline(std::cin, text); ++line) {
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      const palcas::RewardBreakdown r =
          palcas::computeReward(parseSituation(json::parse(text)), params);
      std::cout << toJson(line, r).dump() << "\n";
    } catch (const std::exception& e) {  // json::exception, InputError, std::invalid_argument
      failed = true;
      std::cerr << "palcas_reward: line " << line << ": " << e.what() << "\n";
      std::cout << nlohmann::ordered_json{{"line", line}, {"error", e.what()}}.dump() << "\n";
    }
    std::cout.flush();
  }
  return failed ? 1 : 0;
}
