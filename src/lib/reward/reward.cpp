// The paper's reward (paper "Reward Function"), one CAV at a time.
#include "palcas_core/reward/reward.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace palcas {
namespace {

constexpr double INF = std::numeric_limits<double>::infinity();

// r_e = w_c r_cluster + w_e r_ego,  r_ego = -|v - v_max| / (v_max - v_min),
// r_cluster = -|v_bar - v_bar_max| / (v_bar_max - v_bar_min)   (paper, Efficiency Reward)
void efficiency(const CavSituation& s, const RewardParams& p, RewardBreakdown& r) {
  const double v_max = s.v_max ? *s.v_max : p.v_max_ego;
  r.r_ego = -std::fabs(s.v - v_max) / (v_max - p.v_min_ego);
  r.r_cluster = -std::fabs(s.cluster_mean_speed - p.v_bar_max) / (p.v_bar_max - p.v_bar_min);
  r.r_e = p.w_c * r.r_cluster + p.w_e * r.r_ego;
}

// r_s = r_s,long + r_s,lat, each a sum of min((d - delta)/delta, 0)   (paper, Safety Reward).
// A missing lead or follower contributes no term (nothing to keep a distance from).
// Follow pair: the follower is the rear vehicle (its speed plays v_i), the ego the lead.
void safety(const CavSituation& s, const RewardParams& p, RewardBreakdown& r) {
  const RssParams rss = p.rss();
  if (s.lead) {
    r.delta_long_lead = rssLongitudinalSafeDistance(s.v, s.lead->v, rss);
    r.r_s_long += rssSafetyTerm(s.lead->gap, *r.delta_long_lead);
  }
  if (s.follow) {
    r.delta_long_follow = rssLongitudinalSafeDistance(s.follow->v, s.v, rss);
    r.r_s_long += rssSafetyTerm(s.follow->gap, *r.delta_long_follow);
  }
  for (const auto& m : s.lateral) {
    if (p.lateral_rss_overlap_only != 0.0 && m.long_gap >= 0.0) continue;  // not side by side
    const double delta = p.lateral_rss_signed != 0.0
                             ? rssLateralSafeDistanceSigned(m.v_lat_ego, m.v_lat_other, rss)
                             : rssLateralSafeDistance(m.v_lat_ego, m.v_lat_other, rss);
    r.delta_lat.push_back(delta);
    r.r_s_lat += rssSafetyTerm(m.gap, delta);
  }
  r.r_s = r.r_s_long + r.r_s_lat;
}

// p-ttc of one pair: gap / closing speed when closing, else +inf (paper eqs. p-ttc).
// An existing overlap (gap <= 0) gives 0 whatever the speeds: moving into an occupied
// spot is never feasible, even if the paper's formula would say +inf.
double projectedTtc(double gap, double closing_speed) {
  if (gap <= 0.0) return 0.0;
  return closing_speed > 0.0 ? gap / closing_speed : INF;
}

// r_lc = u w + p_stage  (paper, Priority-guided Lane-Change Reward).
void priorityLaneChange(const CavSituation& s, const RewardParams& p, RewardBreakdown& r) {
  const double d = s.distance_to_exit;  // +inf = no exit
  // n = |l - l*| with l* = 1; the acceleration lane (0) is one lane change from lane 1.
  r.n = std::abs(s.lane - 1);
  // L = 1: n/(L-1) is 0/0. The only lane is the exit lane, so the LC factor is 1 if a
  // lane change is still needed (ramp) else 0, and there is no staging choice: p_stage = 0.
  const int L = s.num_lanes;
  r.lc_factor = L > 1 ? static_cast<double>(r.n) / (L - 1) : std::min(r.n, 1);
  const double inverse_lc = L > 1 ? 1.0 - r.lc_factor : 0.0;

  // p = sigma((min p-ttc - ttc*) / sigma_ttc); no target vehicle -> +inf -> p = 1.
  const double ttc_lead =
      s.target_lead
          ? projectedTtc(s.target_lead->distance - s.target_lead->length, s.v - s.target_lead->v)
          : INF;
  const double ttc_follow =
      s.target_follow ? projectedTtc(s.target_follow->distance - s.length, s.target_follow->v - s.v)
                      : INF;
  r.p_ttc_min = std::min(ttc_lead, ttc_follow);
  r.p = stableSigmoid((r.p_ttc_min - p.ttc_star) / p.sigma_ttc);

  // tau_need = n tau0 / (p + eps); tau_tte = d / (v + eps) (+inf with no exit).
  r.tau_need = r.n * p.tau0 / (r.p + p.epsilon);
  r.tau_tte = std::isinf(d) ? INF : d / std::max(s.v + p.epsilon, p.tte_speed_floor_mps);
  // u = -p near the exit and slow, else -1/(1 + exp(tau_tte - tau_need)) = -sigma(tau_need -
  // tau_tte).
  r.u = (d < p.d_th && s.v < p.v_th) ? -r.p : -stableSigmoid(r.tau_need - r.tau_tte);
  // w = 2 (1 - sigma(d / 1000)) n/(L-1); 1 - sigma(x) = sigma(-x) avoids cancellation.
  r.w = 2.0 * stableSigmoid(-d / p.exit_scale) * r.lc_factor;
  // p_stage = -2 (sigma(d / 1000) - 0.5) (1 - n/(L-1)); no exit: -(1 - n/(L-1)).
  r.p_stage = -2.0 * (stableSigmoid(d / p.exit_scale) - 0.5) * inverse_lc;
  r.r_lc = r.u * r.w + r.p_stage;
}

}  // namespace

double stableSigmoid(double x) {
  if (x >= 0.0) return 1.0 / (1.0 + std::exp(-x));
  const double e = std::exp(x);  // x < 0: exp cannot overflow
  return e / (1.0 + e);
}

RewardBreakdown computeReward(const CavSituation& s, const RewardParams& p) {
  validateRewardParams(p);
  validateSituation(s, p);
  RewardBreakdown r;
  efficiency(s, p, r);
  safety(s, p, r);
  // r_c = (a_th - |a|) / (|a_min| - a_max)   (paper, Comfort Reward; 1.9 with defaults)
  r.r_c = (p.a_th - std::fabs(s.a)) / (std::fabs(p.a_min) - p.a_max);
  if (p.comfort_penalty_only != 0.0) r.r_c = std::min(r.r_c, 0.0);
  priorityLaneChange(s, p, r);
  // r_d = -exp(-(x - len)^2 / (beta len)) on the acceleration lane, else 0 (paper eq. deadlock).
  if (s.accel_lane) {
    const double off = s.accel_lane->x - s.accel_lane->length;
    r.r_d = -std::exp(-off * off / (p.beta * s.accel_lane->length));
  }
  r.total = p.iota * r.r_e + p.zeta * r.r_s + p.xi * r.r_c + p.lambda * r.r_lc + p.psi * r.r_d;
  return r;
}

}  // namespace palcas
