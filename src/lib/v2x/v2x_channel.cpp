#include "palcas_core/v2x/v2x_channel.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <unordered_set>

namespace palcas::v2x {

namespace {

/// splitmix64's finaliser: a well-mixed 64-bit value from any 64-bit input.
std::uint64_t mix(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// FNV-1a over a name: the same id gives the same number on every node.
std::uint64_t hashName(std::string_view s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// A uniform draw in [0, 1) from 53 bits of a hash.
double unit(std::uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

void checkLink(const LinkModel& l, const std::string& name) {
  if (!std::isfinite(l.latency_s) || l.latency_s < 0.0)
    throw std::invalid_argument("v2x " + name + ".latency_s must be a finite value >= 0, got " +
                                std::to_string(l.latency_s));
  if (!std::isfinite(l.jitter_s) || l.jitter_s < 0.0)
    throw std::invalid_argument("v2x " + name + ".jitter_s must be a finite value >= 0, got " +
                                std::to_string(l.jitter_s));
  if (!(l.loss_probability >= 0.0 && l.loss_probability < 1.0))
    throw std::invalid_argument("v2x " + name + ".loss_probability must be in [0, 1), got " +
                                std::to_string(l.loss_probability));
}

}  // namespace

const char* messageClassName(MessageClass c) {
  switch (c) {
    case MessageClass::VEHICLE_STATE: return "vehicle_state";
    case MessageClass::ADVISORY: return "advisory";
    case MessageClass::CLUSTER_STATE: return "cluster_state";
  }
  return "unknown";
}

void ChannelParams::validate() const {
  checkLink(vehicle_state, "vehicle_state");
  checkLink(advisory, "advisory");
  checkLink(cluster_state, "cluster_state");
  if (!(rsu_range_m > 0.0)) throw std::invalid_argument("v2x rsu_range_m must be > 0 (inf = everywhere), got " +
                                                        std::to_string(rsu_range_m));
  if (!std::isfinite(max_advice_age_s) || max_advice_age_s < 0.0)
    throw std::invalid_argument("v2x max_advice_age_s must be a finite value >= 0, got " +
                                std::to_string(max_advice_age_s));
  if (!std::isfinite(keep_advice_s) || keep_advice_s < 0.0)
    throw std::invalid_argument("v2x keep_advice_s must be a finite value >= 0, got " + std::to_string(keep_advice_s));
  if (!std::isfinite(max_state_age_s) || max_state_age_s < 0.0)
    throw std::invalid_argument("v2x max_state_age_s must be a finite value >= 0, got " +
                                std::to_string(max_state_age_s));
}

Channel::Channel(const ChannelParams& params, double step_length_s) : params_(params), step_length_s_(step_length_s) {
  params_.validate();
  if (!(step_length_s > 0.0) || !std::isfinite(step_length_s))
    throw std::invalid_argument("v2x channel: step length must be > 0 s, got " + std::to_string(step_length_s));
}

Delivery Channel::transmit(MessageClass cls, std::string_view from, std::string_view to,
                           std::uint64_t sent_step) const {
  Delivery d;
  if (!params_.enabled) return d;
  const LinkModel& link = cls == MessageClass::VEHICLE_STATE ? params_.vehicle_state
                          : cls == MessageClass::ADVISORY    ? params_.advisory
                                                             : params_.cluster_state;
  std::uint64_t h = mix(params_.seed ^ mix(static_cast<std::uint64_t>(cls) + 1));
  h = mix(h ^ hashName(from));
  h = mix(h ^ (hashName(to) * 31));
  h = mix(h ^ sent_step);
  d.lost = unit(h) < link.loss_probability;
  d.delay_s = link.latency_s + link.jitter_s * unit(mix(h));
  // The first step at or after the arrival time; a hair of tolerance so that 0.1 s on
  // 0.1 s steps is one step, not two.
  d.delay_steps = static_cast<std::uint64_t>(std::ceil(d.delay_s / step_length_s_ - 1e-9));
  return d;
}

bool Channel::inRange(double rsu_x_m, double x_m) const {
  return !params_.enabled || std::abs(x_m - rsu_x_m) <= params_.rsu_range_m;
}

std::uint64_t Channel::stepsWithin(double age_s) const {
  return static_cast<std::uint64_t>(std::floor(age_s / step_length_s_ + 1e-9));
}

std::uint64_t Channel::keepAdviceSteps() const {
  return params_.enabled ? stepsWithin(params_.keep_advice_s) : 0;
}

UplinkView::UplinkView(const Channel& channel, std::string rsu_id, double rsu_x_m)
    : channel_(channel), rsu_id_(std::move(rsu_id)), rsu_x_m_(rsu_x_m) {
  if (!std::isfinite(rsu_x_m)) throw std::invalid_argument("UplinkView of " + rsu_id_ + ": RSU position is not finite");
}

RoadSnapshot UplinkView::receive(const RoadSnapshot& truth, std::uint64_t step) {
  if (started_ && step <= last_step_)
    throw std::invalid_argument("UplinkView of " + rsu_id_ + ": step " + std::to_string(step) +
                                " after step " + std::to_string(last_step_) + " (steps must increase)");
  started_ = true;
  last_step_ = step;
  if (!channel_.enabled()) {
    counts_.sent += truth.vehicles.size();
    counts_.delivered += truth.vehicles.size();
    counts_.used += truth.vehicles.size();
    return truth;
  }
  for (const VehicleSnapshot& v : truth.vehicles) {
    if (!channel_.inRange(rsu_x_m_, v.x_m)) {
      ++counts_.out_of_range;
      continue;
    }
    ++counts_.sent;
    const Delivery d = channel_.transmit(MessageClass::VEHICLE_STATE, v.id, rsu_id_, step);
    if (d.lost) {
      ++counts_.lost;
      continue;
    }
    in_flight_.push(step + d.delay_steps, Received{step, v});
  }
  for (Received& r : in_flight_.release(step)) {
    ++counts_.delivered;
    auto it = last_.find(r.state.id);
    if (it == last_.end()) last_.emplace(r.state.id, std::move(r));
    else if (it->second.sent_step < r.sent_step) it->second = std::move(r);  // jitter may reorder
  }
  const std::uint64_t max_age = channel_.stepsWithin(channel_.params().max_state_age_s);
  RoadSnapshot view;
  view.num_lanes = truth.num_lanes;
  age_in_view_s_.clear();
  // A vehicle that has left the road leaves every view at once: what else the RSU would know
  // of a departure (the bridge's removal events) races the states over ROS, and advice for
  // it could not be carried out anyway.
  std::unordered_set<std::string_view> on_road;
  for (const VehicleSnapshot& v : truth.vehicles) on_road.insert(v.id);
  for (auto it = last_.begin(); it != last_.end();) {
    const std::uint64_t age = step - it->second.sent_step;
    if (!on_road.count(it->first)) {
      it = last_.erase(it);
      continue;
    }
    if (age > max_age) {
      ++counts_.forgotten;
      it = last_.erase(it);
      continue;
    }
    const double age_s = static_cast<double>(age) * channel_.stepLengthS();
    view.vehicles.push_back(it->second.state);
    age_in_view_s_[it->first] = age_s;
    counts_.used_age_sum_s += age_s;
    ++counts_.used;
    ++it;
  }
  // The truth's order (by id here) does not matter to the RSU, but a stable one keeps runs
  // identical: unordered_map iteration is not.
  std::sort(view.vehicles.begin(), view.vehicles.end(),
            [](const VehicleSnapshot& a, const VehicleSnapshot& b) { return a.id < b.id; });
  return view;
}

double UplinkView::ageS(const std::string& id) const {
  auto it = age_in_view_s_.find(id);
  return it == age_in_view_s_.end() ? std::numeric_limits<double>::quiet_NaN() : it->second;
}

void UplinkView::clear() {
  started_ = false;
  last_step_ = 0;
  in_flight_.clear();
  last_.clear();
  age_in_view_s_.clear();
  counts_ = UplinkCounts{};
}

}  // namespace palcas::v2x
