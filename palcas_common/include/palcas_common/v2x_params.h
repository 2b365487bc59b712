#pragma once
// ~v2x/* (config/v2x.yaml, loaded by bridge.launch and rsu.launch under each node): the V2X
// channel both sides of a link apply (palcas_core/v2x/v2x_channel.h). The bridge applies the
// downlink (advisories), each RSU the uplink (vehicle states) and I2I (cluster states); the
// seed is the run's, so they draw the same channel. Header-only.

#include <palcas_common/param_reader.h>
#include <palcas_core/v2x/v2x_channel.h>

#include <limits>
#include <string>

namespace palcas::params {

inline v2x::LinkModel loadLinkModel(common::ParamReader& p, const std::string& ns, const v2x::LinkModel& d) {
  v2x::LinkModel l;
  l.latency_s = p.number(ns + "/latency_s", d.latency_s, 0.0, 3600.0);
  l.jitter_s = p.number(ns + "/jitter_s", d.jitter_s, 0.0, 3600.0);
  l.loss_probability = p.number(ns + "/loss_probability", d.loss_probability, 0.0, 0.999999);
  return l;
}

/// Every key optional (absent = the struct's default, channel off). ~v2x/seed is the run's
/// seed, set by the launch files (the same for the bridge and every RSU).
/// @throws std::invalid_argument naming the key.
inline v2x::ChannelParams loadChannelParams(common::ParamReader& p, const std::string& ns = "v2x") {
  const v2x::ChannelParams d;
  v2x::ChannelParams c;
  c.enabled = p.get<bool>(ns + "/enabled", d.enabled);
  c.vehicle_state = loadLinkModel(p, ns + "/vehicle_state", d.vehicle_state);
  c.advisory = loadLinkModel(p, ns + "/advisory", d.advisory);
  c.cluster_state = loadLinkModel(p, ns + "/cluster_state", d.cluster_state);
  c.rsu_range_m = p.number(ns + "/rsu_range_m", d.rsu_range_m, 1e-3, std::numeric_limits<double>::infinity());
  c.max_advice_age_s = p.number(ns + "/max_advice_age_s", d.max_advice_age_s, 0.0, 3600.0);
  c.keep_advice_s = p.number(ns + "/keep_advice_s", d.keep_advice_s, 0.0, 3600.0);
  c.keep_slowing_advice = p.get<bool>(ns + "/keep_slowing_advice", d.keep_slowing_advice);
  c.max_state_age_s = p.number(ns + "/max_state_age_s", d.max_state_age_s, 0.0, 3600.0);
  c.seed = p.count(ns + "/seed", d.seed, 0);
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("parameters ~" + ns + "/*: " + e.what());
  }
  return c;
}

}  // namespace palcas::params
