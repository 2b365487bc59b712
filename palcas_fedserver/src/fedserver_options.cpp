#include "palcas_fedserver/fedserver_options.h"

#include <palcas_common/param_reader.h>
#include <palcas_common/core_params.h>

#include <limits>
#include <stdexcept>

namespace palcas::fedserver {

FedServerOptions loadFedServerOptions(const ros::NodeHandle& private_nh, common::ParamDefaults* defaults) {
  palcas::common::ParamReader p(private_nh, defaults);
  FedServerOptions o;
  // The same loader as the RSUs': both build the same network from the same files.
  o.learning = params::loadPdqnConfig(p);
  FederationOptions& f = o.federation;
  f.expected_rsus = p.require<std::vector<std::string>>("expected_rsus");
  f.quorum = static_cast<size_t>(p.integer("quorum", 0, 0, std::numeric_limits<int>::max()));
  f.round_deadline_s = p.number("round_deadline_s", f.round_deadline_s, 1e-3, 1e9);
  f.liveness_timeout_s =
      p.number("liveness_timeout_s", f.liveness_timeout_s, 1e-3, std::numeric_limits<double>::infinity());
  f.max_samples = p.count("max_samples", f.max_samples, 1);
  f.max_update_norm_ratio = p.number("max_update_norm_ratio", f.max_update_norm_ratio, 0.0, 1e12);
  const std::string aggregation = p.get<std::string>("aggregation", "fedavg");
  if (aggregation == "fedavg") f.aggregation = FederationOptions::Aggregation::kFedAvg;
  else if (aggregation == "median") f.aggregation = FederationOptions::Aggregation::kMedian;
  else if (aggregation == "trimmed_mean") f.aggregation = FederationOptions::Aggregation::kTrimmedMean;
  else
    throw std::invalid_argument("parameter '" + p.fullName("aggregation") + "' is '" + aggregation +
                                "': one of fedavg, median, trimmed_mean");
  f.trim_fraction = p.number("trim_fraction", f.trim_fraction, 0.0, 0.4999);
  o.checkpoint_dir = p.get<std::string>("checkpoint_dir", o.checkpoint_dir);
  o.resume = p.get<bool>("resume", o.resume);
  if (o.resume && o.checkpoint_dir.empty())
    throw std::invalid_argument("parameter '" + p.fullName("resume") + "' is true but '" +
                                p.fullName("checkpoint_dir") + "' is empty: nothing to resume from");
  o.auth_key_file = p.get<std::string>("auth_key_file", o.auth_key_file);
  if (o.auth_key_file == "none") o.auth_key_file.clear();  // the launch files' "not set"
  o.poll_period_s = p.number("poll_period_s", o.poll_period_s, 1e-3, 3600.0);
  o.road_wait_s = p.number("road_wait_s", o.road_wait_s, 0.0, 3600.0);
  try {
    f.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string("federation parameters: ") + e.what());
  }
  p.rejectUnknownKeys("palcas_fedserver/README.md");
  return o;
}

}  // namespace palcas::fedserver
