#pragma once
// A V2X channel between the vehicles and the RSUs and between RSUs, as the paper simulated it
// with Eclipse MOSAIC: per message class a latency (fixed + uniform jitter), a loss
// probability, and an RSU radio range. Everything a message meets is drawn from a hash of
// (seed, class, sender, receiver, step), so a run is the same for the same seed whatever order
// the nodes send in, and the bridge and the RSUs can each apply their side of the channel
// without talking to each other. ROS-free; the nodes wire it (README "V2X channel").
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "palcas_core/common/road_snapshot.h"

namespace palcas::v2x {

/// The three message classes of the paper's system.
enum class MessageClass : std::uint8_t {
  VEHICLE_STATE = 0,  ///< CAV/CHV -> RSU (uplink): its position, speed, lane …
  ADVISORY = 1,       ///< RSU -> CAV (downlink): a lane change or an acceleration
  CLUSTER_STATE = 2,  ///< RSU -> RSU (I2I): the zone's statistics
};
const char* messageClassName(MessageClass c);

/// One message class's link: latency = latency_s + U(0, jitter_s); lost with loss_probability.
struct LinkModel {
  double latency_s = 0.0;         ///< fixed part [s]
  double jitter_s = 0.0;          ///< uniform extra delay, 0 .. jitter_s [s]
  double loss_probability = 0.0;  ///< a message is lost with this probability [0, 1)
};

struct ChannelParams {
  bool enabled = false;                 ///< off: every message arrives at once, always, everywhere
  LinkModel vehicle_state;              ///< uplink
  LinkModel advisory;                   ///< downlink
  LinkModel cluster_state;              ///< I2I
  /// An RSU hears and reaches a vehicle within this distance along the road of its position
  /// (its zone's centre) [m]; +inf = everywhere. 509.4 m: Eclipse MOSAIC SNS's default
  /// singlehopRadius (a paper-road zone is 800 m: its RSU covers it and ~109 m either side).
  double rsu_range_m = 509.4;
  double max_advice_age_s = 0.5;  ///< a CAV drops an advisory older than this when it arrives [s]
  /// A CAV keeps its last advisory this long past the bridge's hold (advisory_hold_steps)
  /// while no newer one gets through [s]: a lost advisory leaves the last one in force instead
  /// of handing the CAV to its own driving until the next decision. 0 = the hold ends on time.
  double keep_advice_s = 1.0;
  /// Whether keep_advice_s also keeps an ACCELERATE below 0. false: only advice that does not
  /// slow the CAV is kept; a lost one after a slowing advisory hands it to its own driving on
  /// time (a kept guess must not cost speed: keeping every advisory 1 s cost 1.2 % of speed
  /// at 300 ms / 30 %, keeping only these did not).
  bool keep_slowing_advice = false;
  double max_state_age_s = 1.0;   ///< an RSU forgets a vehicle whose last state is older [s]
  std::uint64_t seed = 0;         ///< the run's seed: same seed, same losses and delays

  /// Throws std::invalid_argument naming the field when a value is out of range (negative or
  /// non-finite latency, a probability outside [0, 1), a range <= 0, an age < 0).
  void validate() const;
};

/// What became of one message.
struct Delivery {
  bool lost = false;
  std::uint64_t delay_steps = 0;  ///< arrives this many simulation steps after it was sent
  double delay_s = 0.0;           ///< the drawn delay before rounding up to steps [s]
};

class Channel {
 public:
  /// Throws std::invalid_argument for bad params or a step length <= 0.
  Channel(const ChannelParams& params, double step_length_s);

  const ChannelParams& params() const { return params_; }
  bool enabled() const { return params_.enabled; }
  double stepLengthS() const { return step_length_s_; }

  /// The fate of the message of `cls` that `from` sends to `to` at `sent_step`. Disabled:
  /// never lost, no delay. A message is delivered at the first step whose time is at or
  /// after its send time plus its delay (lockstep: a step is the finest time there is).
  Delivery transmit(MessageClass cls, std::string_view from, std::string_view to, std::uint64_t sent_step) const;
  /// True when a vehicle at x_m is within the range of an RSU at rsu_x_m.
  bool inRange(double rsu_x_m, double x_m) const;
  /// Age in steps past which a message of max age `age_s` is too old.
  std::uint64_t stepsWithin(double age_s) const;
  /// Steps a CAV keeps its last advisory past its hold while no newer one gets through
  /// (keep_advice_s); 0 with the channel off.
  std::uint64_t keepAdviceSteps() const;

 private:
  ChannelParams params_;
  double step_length_s_;
};

/// Messages held until the step they arrive at.
template <class T>
class DelayLine {
 public:
  void push(std::uint64_t arrival_step, T message) { held_.emplace(arrival_step, std::move(message)); }
  /// Every message due at or before `step`, in arrival order (FIFO within a step).
  std::vector<T> release(std::uint64_t step) {
    std::vector<T> out;
    auto end = held_.upper_bound(step);
    for (auto it = held_.begin(); it != end; ++it) out.push_back(std::move(it->second));
    held_.erase(held_.begin(), end);
    return out;
  }
  std::size_t size() const { return held_.size(); }
  void clear() { held_.clear(); }

 private:
  std::multimap<std::uint64_t, T> held_;
};

/// Uplink counts of one RSU.
struct UplinkCounts {
  std::uint64_t sent = 0;          ///< states vehicles in range sent to it
  std::uint64_t out_of_range = 0;  ///< states of vehicles beyond its range (never heard)
  std::uint64_t lost = 0;
  std::uint64_t delivered = 0;
  std::uint64_t forgotten = 0;     ///< vehicles dropped from its view, last state too old
  double used_age_sum_s = 0.0;     ///< sum over vehicles in the views it returned of their age
  std::uint64_t used = 0;          ///< vehicles in the views it returned
};

/// What one RSU knows of the road through the uplink: the last state each vehicle got through
/// to it, used as received (stale, not extrapolated) up to max_state_age_s, then forgotten.
/// A vehicle no longer on the road (absent from the truth) leaves the view at once.
class UplinkView {
 public:
  /// `rsu_x_m`: where the RSU stands along the road (its zone's centre) [m].
  UplinkView(const Channel& channel, std::string rsu_id, double rsu_x_m);

  /// Sends `truth` (every vehicle's state at `step`) through the channel and returns the road
  /// as this RSU holds it at `step`. Call every step, in order; a repeated or earlier step
  /// throws std::invalid_argument.
  RoadSnapshot receive(const RoadSnapshot& truth, std::uint64_t step);
  /// Age of vehicle `id`'s state in the last returned view [s]; NaN when it is not in it.
  double ageS(const std::string& id) const;
  const UplinkCounts& counts() const { return counts_; }
  void clear();

 private:
  struct Received {
    std::uint64_t sent_step = 0;
    VehicleSnapshot state;
  };
  const Channel& channel_;
  std::string rsu_id_;
  double rsu_x_m_;
  bool started_ = false;
  std::uint64_t last_step_ = 0;
  DelayLine<Received> in_flight_;
  std::unordered_map<std::string, Received> last_;
  std::unordered_map<std::string, double> age_in_view_s_;
  UplinkCounts counts_;
};

/// Downlink counts (the bridge: advisories on their way to the CAVs).
struct DownlinkCounts {
  std::uint64_t sent = 0;          ///< advisories the RSUs sent
  std::uint64_t out_of_range = 0;  ///< the CAV was beyond the RSU's range when it would arrive
  std::uint64_t lost = 0;
  std::uint64_t too_old = 0;       ///< arrived older than max_advice_age_s: dropped by the CAV
  std::uint64_t delivered = 0;     ///< arrived in time and in range (then applied or rejected)
  std::uint64_t late = 0;          ///< of those, arrived at a later step than it was decided for
  double delivered_age_sum_s = 0.0;
  double meanAgeS() const { return delivered ? delivered_age_sum_s / static_cast<double>(delivered) : 0.0; }
};

}  // namespace palcas::v2x
