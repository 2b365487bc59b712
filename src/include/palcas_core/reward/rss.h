#pragma once
// Responsibility-Sensitive Safety (RSS) minimum safe distances and the paper's per-pair
// safety term (paper "Reward Function", Safety Reward; Shalev-Shwartz et al. 2017).

namespace palcas {

/// RSS constants; defaults are the paper's values.
struct RssParams {
  double rho_s = 0.2;           ///< response time rho [s]
  double a_max_mps2 = 2.6;      ///< max acceleration of the rear vehicle during rho [m/s^2]
  double a_b_min_mps2 = 4.5;    ///< min braking of the rear vehicle [m/s^2]
  double a_b_max_mps2 = 4.5;    ///< max braking of the front vehicle [m/s^2]
  double mu_m = 0.1;            ///< lateral clearance buffer mu [m]
  double a_b_lat_mps2 = 1.0;    ///< lateral braking a_b,lat [m/s^2]
  double a_lat_max_mps2 = 1.0;  ///< max lateral acceleration a_lat,max [m/s^2]
};

/// Throws std::invalid_argument naming the first parameter that is not finite, or
/// negative (rho, a_max, mu), or not > 0 (the braking decelerations: they divide).
void validateRssParams(const RssParams& p);

/// Longitudinal safe distance (paper eq. long-safe_distance) between a rear vehicle at
/// v_rear and a front vehicle at v_front [m/s] -> [m]:
///   delta_long = [v_r rho + a_max rho^2 / 2 + (v_r + rho a_max)^2 / (2 a_b,min)
///                 - v_f^2 / (2 a_b,max)]_+
/// For the ego's lead pair the ego is the rear vehicle; for the follow pair the follower
/// is the rear vehicle and the ego plays the lead. Precondition: finite speeds.
double rssLongitudinalSafeDistance(double v_rear_mps, double v_front_mps, const RssParams& p);

/// Lateral safe distance (paper eq. lateral-safety) [m], exactly as the paper writes it,
/// with v_rho = v + rho a_lat,max for BOTH vehicles:
///   delta_lat = mu + [(v_i + v_i,rho)/2 rho + v_i,rho^2 / (2 a_b,lat)
///                     - ((v_m + v_m,rho)/2 rho - v_m,rho^2 / (2 a_b,lat))]_+
/// Frame: positive = from the ego toward the other vehicle, so v_lat_ego > 0 closes the
/// gap and v_lat_other > 0 opens it (RSS's "c1 left of c2" frame with the ego as c1).
double rssLateralSafeDistance(double v_lat_ego_mps, double v_lat_other_mps, const RssParams& p);
/// The same with signed squares v|v| (RewardParams::lateral_rss_signed).
double rssLateralSafeDistanceSigned(double v_lat_ego_mps, double v_lat_other_mps, const RssParams& p);

/// One term of r_s,long / r_s,lat: min((d - delta) / delta, 0), <= 0.
/// delta = 0 (the pair is safe at any non-negative gap) would divide by zero; then the
/// term is 0 when d >= 0 (satisfied) and -1 when d < 0 (overlap: the value a positive
/// delta gives at d = 0, "all of the safe distance used up").
/// Precondition: finite d, delta >= 0.
double rssSafetyTerm(double d_m, double delta_m);

}  // namespace palcas
