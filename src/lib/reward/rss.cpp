#include "palcas_core/reward/rss.h"

#include <algorithm>
#include <cmath>

#include "palcas_core/common/checks.h"

namespace palcas {

void validateRssParams(const RssParams& p) {
  using common::requireNonNegative;
  using common::requirePositive;
  requireNonNegative(p.rho_s, "RSS parameter rho");
  requireNonNegative(p.a_max_mps2, "RSS parameter a_max");
  requirePositive(p.a_b_min_mps2, "RSS parameter a_b_min");
  requirePositive(p.a_b_max_mps2, "RSS parameter a_b_max");
  requireNonNegative(p.mu_m, "RSS parameter mu");
  requirePositive(p.a_b_lat_mps2, "RSS parameter a_b_lat");
  requireNonNegative(p.a_lat_max_mps2, "RSS parameter a_lat_max");
}

// delta_long = [v rho + a_max rho^2/2 + (v + rho a_max)^2/(2 a_b,min) - v_f^2/(2 a_b,max)]_+
double rssLongitudinalSafeDistance(double v_rear, double v_front, const RssParams& p) {
  const double rho = p.rho_s;
  const double v_rho = v_rear + rho * p.a_max_mps2;
  const double raw = v_rear * rho + 0.5 * p.a_max_mps2 * rho * rho +
                     v_rho * v_rho / (2.0 * p.a_b_min_mps2) -
                     v_front * v_front / (2.0 * p.a_b_max_mps2);
  return std::max(raw, 0.0);
}

// delta_lat = mu + [(v_i + v_i,rho)/2 rho + v_i,rho^2/(2 a_b,lat)
//                   - ((v_m + v_m,rho)/2 rho - v_m,rho^2/(2 a_b,lat))]_+,
// v_x,rho = v_x + rho a_lat,max (the paper's sign for both; RSS itself uses v_m - rho a).
double rssLateralSafeDistance(double v_ego, double v_other, const RssParams& p) {
  const double rho = p.rho_s;
  const double two_b = 2.0 * p.a_b_lat_mps2;
  const double v_i_rho = v_ego + rho * p.a_lat_max_mps2;
  const double v_m_rho = v_other + rho * p.a_lat_max_mps2;
  const double ego_part = 0.5 * (v_ego + v_i_rho) * rho + v_i_rho * v_i_rho / two_b;
  const double other_part = 0.5 * (v_other + v_m_rho) * rho - v_m_rho * v_m_rho / two_b;
  return p.mu_m + std::max(ego_part - other_part, 0.0);
}

double rssLateralSafeDistanceSigned(double v_ego, double v_other, const RssParams& p) {
  // As above with v|v| for the squared response speeds: the braking distance toward the
  // other counts positive, a velocity away from it negative (Shalev-Shwartz et al.).
  const double rho = p.rho_s;
  const double two_b = 2.0 * p.a_b_lat_mps2;
  const double v_i_rho = v_ego + rho * p.a_lat_max_mps2;
  const double v_m_rho = v_other + rho * p.a_lat_max_mps2;
  const double ego_part = 0.5 * (v_ego + v_i_rho) * rho + v_i_rho * std::fabs(v_i_rho) / two_b;
  const double other_part = 0.5 * (v_other + v_m_rho) * rho - v_m_rho * std::fabs(v_m_rho) / two_b;
  return p.mu_m + std::max(ego_part - other_part, 0.0);
}

double rssSafetyTerm(double d, double delta) {
  if (delta <= 0.0) return d >= 0.0 ? 0.0 : -1.0;
  return std::min((d - delta) / delta, 0.0);
}

}  // namespace palcas
