// Name table, accessors and validation of RewardParams.
#include <cmath>
#include <stdexcept>
#include <utility>

#include "palcas_core/common/checks.h"
#include "palcas_core/reward/reward.h"

namespace palcas {
namespace {

using Member = double RewardParams::*;

// One row per field, in declaration order; the names are the paper's symbols.
const std::vector<std::pair<std::string, Member>>& table() {
  static const std::vector<std::pair<std::string, Member>> rows = {
      {"iota", &RewardParams::iota},
      {"zeta", &RewardParams::zeta},
      {"xi", &RewardParams::xi},
      {"lambda", &RewardParams::lambda},
      {"psi", &RewardParams::psi},
      {"w_c", &RewardParams::w_c},
      {"w_e", &RewardParams::w_e},
      {"v_max_ego", &RewardParams::v_max_ego},
      {"v_min_ego", &RewardParams::v_min_ego},
      {"v_bar_max", &RewardParams::v_bar_max},
      {"v_bar_min", &RewardParams::v_bar_min},
      {"rho", &RewardParams::rho},
      {"a_max", &RewardParams::a_max},
      {"a_b_min", &RewardParams::a_b_min},
      {"a_b_max", &RewardParams::a_b_max},
      {"mu", &RewardParams::mu},
      {"a_b_lat", &RewardParams::a_b_lat},
      {"a_lat_max", &RewardParams::a_lat_max},
      {"a_th", &RewardParams::a_th},
      {"a_min", &RewardParams::a_min},
      {"d_th", &RewardParams::d_th},
      {"v_th", &RewardParams::v_th},
      {"tau0", &RewardParams::tau0},
      {"epsilon", &RewardParams::epsilon},
      {"ttc_star", &RewardParams::ttc_star},
      {"sigma_ttc", &RewardParams::sigma_ttc},
      {"exit_scale", &RewardParams::exit_scale},
      {"beta", &RewardParams::beta},
      {"lateral_rss_overlap_only", &RewardParams::lateral_rss_overlap_only},
      {"lateral_rss_signed", &RewardParams::lateral_rss_signed},
      {"comfort_penalty_only", &RewardParams::comfort_penalty_only},
      {"tte_speed_floor_mps", &RewardParams::tte_speed_floor_mps}};
  return rows;
}

Member lookup(const std::string& name) {
  for (const auto& row : table())
    if (row.first == name) return row.second;
  std::string valid;
  for (const auto& row : table()) valid += (valid.empty() ? "" : ", ") + row.first;
  throw std::invalid_argument("unknown reward parameter '" + name + "'; valid names: " + valid);
}

}  // namespace

const std::vector<std::string>& rewardParamNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& row : table()) out.push_back(row.first);
    return out;
  }();
  return names;
}

double getRewardParam(const RewardParams& params, const std::string& name) {
  return params.*lookup(name);
}

void setRewardParam(RewardParams& params, const std::string& name, double value) {
  params.*lookup(name) = value;
}

void validateRewardParams(const RewardParams& p) {
  using common::require;
  const char* const bad = "reward parameter ";
  for (const auto& row : table())
    require(std::isfinite(p.*row.second), bad, row.first, " is not finite");
  require(p.v_max_ego > p.v_min_ego, bad, "v_max_ego must be > v_min_ego (r_ego divides by it)");
  require(p.v_bar_max > p.v_bar_min, bad,
          "v_bar_max must be > v_bar_min (r_cluster divides by it)");
  require(std::fabs(p.a_min) - p.a_max != 0.0, bad,
          "a_min must satisfy |a_min| != a_max (r_c divides by it)");
  require(p.epsilon > 0.0, bad, "epsilon must be > 0");
  require(p.sigma_ttc > 0.0, bad, "sigma_ttc must be > 0");
  require(p.exit_scale > 0.0, bad, "exit_scale must be > 0");
  require(p.beta > 0.0, bad, "beta must be > 0");
  require(p.tau0 >= 0.0, bad, "tau0 must be >= 0");
  for (const char* flag : {"lateral_rss_overlap_only", "lateral_rss_signed", "comfort_penalty_only"}) {
    const double v = p.*lookup(flag);
    require(v == 0.0 || v == 1.0, bad, flag, " must be 0 (paper) or 1");
  }
  require(p.tte_speed_floor_mps >= 0.0, bad, "tte_speed_floor_mps must be >= 0");
  validateRssParams(p.rss());
}

}  // namespace palcas
