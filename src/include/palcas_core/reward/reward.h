#pragma once
// The paper's per-CAV reward (paper "Reward Function"):
//   R_k = sum over CAVs of (iota r_e + zeta r_s + xi r_c + lambda r_lc + psi r_d)
// computeReward() gives one CAV's term with every intermediate; the RSU sums over its
// CAVs. Every ambiguity choice is documented next to its code in lib/reward/reward.cpp and in
// src/doc/state_and_reward.md.

#include <optional>
#include <string>
#include <vector>

#include "palcas_core/common/road_snapshot.h"
#include "palcas_core/reward/rss.h"
#include "palcas_core/state/neighbours.h"

namespace palcas {

/// Every reward constant; defaults are the paper's values (w_c, w_e: not given by the
/// paper, 0.5 / 0.5 chosen). Field names are the paper's symbols, so they double as the
/// `--param` names of palcas_reward and the keys of config/reward.yaml.
struct RewardParams {
  double iota = 0.05, zeta = 0.5, xi = 0.05, lambda = 0.4, psi = 0.1;  ///< weights of r_e..r_d
  double w_c = 0.5, w_e = 0.5;                 ///< r_e = w_c r_cluster + w_e r_ego (paper: unset)
  double v_max_ego = 33.528;                   ///< [m/s] used when the CAV's own v_max is unknown
  double v_min_ego = 0.0;                      ///< [m/s]
  double v_bar_max = 33.528, v_bar_min = 0.0;  ///< cluster mean-speed target / floor [m/s]
  double rho = 0.2;                            ///< RSS response time [s]
  double a_max = 2.6;                          ///< RSS and comfort max acceleration [m/s^2]
  double a_b_min = 4.5, a_b_max = 4.5;         ///< RSS braking of rear / front vehicle [m/s^2]
  double mu = 0.1;                             ///< RSS lateral buffer [m]
  double a_b_lat = 1.0, a_lat_max = 1.0;       ///< RSS lateral braking / acceleration [m/s^2]
  double a_th = 1.47;                          ///< comfort threshold [m/s^2]
  double a_min = -4.5;                         ///< comfort: r_c denominator |a_min| - a_max [m/s^2]
  double d_th = 50.0, v_th = 5.0;              ///< u = -p below both thresholds [m], [m/s]
  double tau0 = 2.0;                           ///< nominal time of one lane change [s]
  double epsilon = 1e-6;                       ///< divide-by-zero guard
  double ttc_star = 1.5;                       ///< p-ttc threshold [s]
  double sigma_ttc = 0.1;                      ///< temperature of p [s]
  double exit_scale = 1000.0;                  ///< exit-proximity scale in sigma(d / scale) [m]
  double beta = 10.0;                          ///< deadlock penalty width factor
  // Departures from the printed paper (src/doc/state_and_reward.md, "Departures"); each is
  // 0 = the paper's formula. Flags are 0 or 1.
  /// 1: the lateral RSS term counts only side neighbours that overlap the ego along the
  /// road (longitudinal bumper gap < 0): RSS's lateral rule is about cars side by side.
  /// 0 (paper): every side-lane leader and follower, at any longitudinal distance.
  double lateral_rss_overlap_only = 0.0;
  /// 1: the lateral response distances use v|v| (signed) instead of v^2, so moving away
  /// from a neighbour does not count as moving toward it. 0 (paper): v^2.
  double lateral_rss_signed = 0.0;
  /// 1: r_c = min(0, paper r_c): only discomfort is paid; no bonus for standing still.
  /// 0 (paper): r_c is positive whenever |a| < a_th, stopped cars included.
  double comfort_penalty_only = 0.0;
  /// tau_tte = d / max(v + epsilon, this) [m/s]: a stopped car far from its exit still
  /// feels the urgency at this speed. 0 (paper): d / (v + epsilon), +inf when stopped.
  double tte_speed_floor_mps = 0.0;

  RssParams rss() const { return {rho, a_max, a_b_min, a_b_max, mu, a_b_lat, a_lat_max}; }
};

/// Names of all RewardParams fields, in declaration order.
const std::vector<std::string>& rewardParamNames();
/// Value of parameter `name`. Throws std::invalid_argument listing the valid names.
double getRewardParam(const RewardParams& params, const std::string& name);
/// Sets parameter `name`. Throws std::invalid_argument (listing the valid names) on an
/// unknown name; `params` is unchanged then. Does not validate: call validateRewardParams.
void setRewardParam(RewardParams& params, const std::string& name, double value);
/// Throws std::invalid_argument naming the first constant that is non-finite or makes a
/// formula undefined (zero denominators, sigma_ttc/epsilon/beta/exit_scale <= 0, ...).
void validateRewardParams(const RewardParams& params);

/// Inputs of one CAV's reward; field names are exactly the palcas_reward JSON keys.
/// SI units; lanes 1..L from the right, 0 = acceleration lane / ramp.
struct CavSituation {
  struct GapSpeed {
    double gap = 0.0, v = 0.0;
  };  ///< bumper-to-bumper gap [m], speed [m/s]
  /// Lateral neighbour: gap [m] (negative = overlap); lateral speeds [m/s] in the frame
  /// "positive = from the ego toward this neighbour".
  struct Lateral {
    double gap = 0.0, v_lat_ego = 0.0, v_lat_other = 0.0;
    /// Longitudinal bumper-to-bumper gap [m] (negative = side by side); used only with
    /// lateral_rss_overlap_only. JSON key "long_gap", optional (default -1: overlapping).
    double long_gap = -1.0;
  };
  /// Leader in the lane toward the exit: front-to-front distance [m], speed, length [m].
  struct TargetLead {
    double distance = 0.0, v = 0.0, length = 5.0;
  };
  /// Follower in the lane toward the exit: front-to-front distance [m], speed [m/s].
  struct TargetFollow {
    double distance = 0.0, v = 0.0;
  };
  struct AccelLane {
    double x = 0.0, length = 0.0;
  };  ///< position along / length [m]

  double v = 0.0;                        ///< ego speed [m/s], >= 0
  double a = 0.0;                        ///< ego acceleration [m/s^2]
  int lane = 1;                          ///< 0..num_lanes
  int num_lanes = 5;                     ///< L >= 1
  double length = 5.0;                   ///< ego length [m]
  double distance_to_exit = 0.0;         ///< [m], +inf = no exit (JSON null)
  std::optional<GapSpeed> lead, follow;  ///< own-lane neighbours; empty = none
  std::vector<Lateral> lateral;          ///< up to 4 adjacent-lane neighbours
  std::optional<TargetLead> target_lead;
  std::optional<TargetFollow> target_follow;
  double cluster_mean_speed = 0.0;      ///< [m/s]
  std::optional<AccelLane> accel_lane;  ///< present = on the acceleration lane
  std::optional<double> v_max;          ///< the CAV's own max speed [m/s]; else params.v_max_ego
};

/// Throws std::invalid_argument naming the key ("lead.gap", "lateral[2].v_lat_ego",
/// "lane", ...) of the first value that is NaN/inf where not allowed, a lane outside
/// 0..num_lanes, num_lanes < 1, a negative speed, length or distance, more than four
/// lateral neighbours, accel_lane on a mainline lane, or v_max <= v_min_ego.
void validateSituation(const CavSituation& s, const RewardParams& params);

/// One CAV's reward and its intermediates. Infinite values stay +inf (tau_tte with no
/// exit, p_ttc_min with no closing target vehicle).
struct RewardBreakdown {
  std::optional<double> delta_long_lead, delta_long_follow;  ///< empty = no such vehicle
  std::vector<double> delta_lat;                             ///< one per lateral neighbour
  double r_ego = 0, r_cluster = 0, r_s_long = 0, r_s_lat = 0;
  int n = 0;             ///< remaining lane changes |l - 1|
  double lc_factor = 0;  ///< n / (L - 1)
  double p_ttc_min = 0;  ///< [s], +inf = nobody closing in
  double p = 0, tau_need = 0, tau_tte = 0, u = 0, w = 0, p_stage = 0;
  double r_e = 0, r_s = 0, r_c = 0, r_lc = 0, r_d = 0;
  double total = 0;  ///< iota r_e + zeta r_s + xi r_c + lambda r_lc + psi r_d
};

/// Numerically stable logistic 1 / (1 + exp(-x)); sigma(+inf) = 1, sigma(-inf) = 0.
double stableSigmoid(double x);

/// The paper's reward of one CAV. Validates params and situation first (see above);
/// throws std::invalid_argument naming the bad key.
RewardBreakdown computeReward(const CavSituation& situation, const RewardParams& params);

/// Builds the situation of CAV `cav_id` from an indexed snapshot: own-lane lead/follow;
/// the up-to-4 left/right lead/follow as lateral neighbours with gap = |lateral_m
/// difference| - (w_ego + w_other) / 2; target lane = the lane toward the exit (lane - 1;
/// lane 1 for the acceleration lane; none for lane 1 and ramps) and its lead / follower.
/// Throws std::invalid_argument on an unknown id.
CavSituation situationFromSnapshot(const NeighbourFinder& finder, const std::string& cav_id,
                                   const ClusterStats& cluster);

}  // namespace palcas
