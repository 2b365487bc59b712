#include "palcas_rsu/decision_inputs.h"

#include <stdexcept>

namespace palcas::rsu {

DecisionInputs::DecisionInputs(int own_cluster, int zone_count, bool i2i, std::uint64_t decision_period_steps,
                               bool events)
    : period_(decision_period_steps), events_(events) {
  if (own_cluster < 0 || zone_count < 1 || own_cluster >= zone_count)
    throw std::invalid_argument("DecisionInputs: cluster " + std::to_string(own_cluster) + " is not one of " +
                                std::to_string(zone_count) + " zone(s)");
  if (period_ < 1) throw std::invalid_argument("DecisionInputs: decision_period_steps must be >= 1");
  if (!i2i) return;
  for (int k : {own_cluster - 1, own_cluster + 1})
    if (k >= 0 && k < zone_count) {
      neighbours_.push_back(k);
      presumed_down_[k] = false;
    }
}

void DecisionInputs::eventsArrived(std::uint64_t step) { events_step_ = step; }

void DecisionInputs::clusterStateArrived(int cluster_index, std::uint64_t step) {
  auto down = presumed_down_.find(cluster_index);
  if (down == presumed_down_.end()) return;  // not a neighbour: its statistics are not used
  down->second = false;                      // heard again: waited for from now on
  cluster_step_[cluster_index] = step;
}

bool DecisionInputs::neighbourDue(int cluster, std::uint64_t step) const {
  // The first round has nothing before it; a presumed-down neighbour is not waited for.
  if (step < period_ || presumed_down_.at(cluster)) return false;
  auto it = cluster_step_.find(cluster);
  // Its statistics of the previous round, or of this one if it decided first; a value from
  // beyond `step` is another episode's.
  return it == cluster_step_.end() || it->second + period_ < step || it->second > step;
}

std::vector<std::string> DecisionInputs::missing(std::uint64_t step) const {
  std::vector<std::string> out;
  // The array of `step` or a later one of the same round (the bridge went on without this
  // RSU's answer); arrays arrive in order, so the earlier ones are in. A far larger step is
  // the last episode's.
  if (events_ && (!events_step_ || *events_step_ < step || *events_step_ >= step + period_))
    out.push_back("events of step " + std::to_string(step));
  for (int k : neighbours_)
    if (neighbourDue(k, step))
      out.push_back("cluster state of cluster " + std::to_string(k) + " for step " + std::to_string(step - period_));
  return out;
}

std::vector<int> DecisionInputs::gaveUp(std::uint64_t step) {
  std::vector<int> down;
  for (int k : neighbours_)
    if (neighbourDue(k, step)) {
      presumed_down_[k] = true;
      down.push_back(k);
    }
  return down;
}

std::vector<int> DecisionInputs::presumedDown() const {
  std::vector<int> out;
  for (const auto& [k, down] : presumed_down_)
    if (down) out.push_back(k);
  return out;
}

}  // namespace palcas::rsu
