#pragma once
// I2I bookkeeping of one RSU, without ROS: the recent cluster statistics each peer RSU
// shared, and the global part of the state (upstream / own / downstream densities) built
// from them. A decision at time t uses each peer's newest statistics from BEFORE t, never
// those of t itself, which may or may not have arrived yet: so decisions do not depend on
// message timing (same seed, same advisories). A peer not heard from for `stale_after_s`
// of simulation time is stale: its density is reported unknown (NaN, which the state
// encodes explicitly) and the RSU keeps working with what it has.

#include <palcas_core/common/road_snapshot.h>

#include <map>
#include <string>
#include <vector>

namespace palcas::rsu {

class PeerStates {
 public:
  /// @param own_cluster this RSU's cluster index; @param stale_after_s > 0 [s]
  /// @throws std::invalid_argument for a negative index or a non-positive timeout.
  PeerStates(int own_cluster, double stale_after_s);

  /// A peer's statistics at simulation time `time_s`. Older than what is held: ignored.
  /// @throws std::invalid_argument for a negative cluster index or a non-finite value.
  void update(int cluster_index, const std::string& rsu_id, double density_veh_per_km, double time_s);

  /// Upstream (own - 1), own (`own_density`), downstream (own + 1) for a decision at
  /// `now_s`, from statistics stamped before `now_s`; a missing or stale neighbour is NaN.
  GlobalDensities global(double own_density_veh_per_km, double now_s) const;

  /// Peers heard from at least once whose statistics are stale at `now_s` (for warnings).
  std::vector<std::string> stalePeers(double now_s) const;

 private:
  struct Sample {
    double density = 0.0;
    double time_s = 0.0;
  };
  struct Peer {
    std::string rsu_id;
    std::vector<Sample> recent;  ///< newest last, a few decisions deep
  };
  /// The newest sample of `p` stamped before now_s, or nullptr.
  const Sample* before(const Peer& p, double now_s) const;
  static constexpr std::size_t KEPT_SAMPLES = 4;
  int own_;
  double stale_after_s_;
  std::map<int, Peer> peers_;
};

}  // namespace palcas::rsu
