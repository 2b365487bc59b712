#include "palcas_rsu/peer_states.h"

#include <cmath>
#include <limits>
#include <stdexcept>

namespace palcas::rsu {

PeerStates::PeerStates(int own_cluster, double stale_after_s)
    : own_(own_cluster), stale_after_s_(stale_after_s) {
  if (own_ < 0) throw std::invalid_argument("PeerStates: negative own cluster index");
  if (!(stale_after_s_ > 0.0))
    throw std::invalid_argument("PeerStates: stale_after_s must be > 0, got " + std::to_string(stale_after_s));
}

void PeerStates::update(int cluster_index, const std::string& rsu_id, double density, double time_s) {
  if (cluster_index < 0)
    throw std::invalid_argument("cluster state of '" + rsu_id + "': negative cluster index");
  if (!std::isfinite(density) || density < 0.0 || !std::isfinite(time_s))
    throw std::invalid_argument("cluster state of '" + rsu_id + "': density " + std::to_string(density) +
                                " at t=" + std::to_string(time_s) + " is not a finite non-negative value");
  Peer& peer = peers_[cluster_index];
  peer.rsu_id = rsu_id;
  if (!peer.recent.empty() && peer.recent.back().time_s >= time_s) return;  // out of order or repeated
  peer.recent.push_back(Sample{density, time_s});
  if (peer.recent.size() > KEPT_SAMPLES) peer.recent.erase(peer.recent.begin());
}

const PeerStates::Sample* PeerStates::before(const Peer& p, double now_s) const {
  for (auto it = p.recent.rbegin(); it != p.recent.rend(); ++it)
    if (it->time_s < now_s - 1e-9) return &*it;
  return nullptr;
}

GlobalDensities PeerStates::global(double own_density, double now_s) const {
  const double unknown = std::numeric_limits<double>::quiet_NaN();
  auto at = [&](int k) {
    auto it = peers_.find(k);
    if (it == peers_.end()) return unknown;
    const Sample* s = before(it->second, now_s);
    return s && now_s - s->time_s <= stale_after_s_ ? s->density : unknown;
  };
  return GlobalDensities{at(own_ - 1), own_density, at(own_ + 1)};
}

std::vector<std::string> PeerStates::stalePeers(double now_s) const {
  std::vector<std::string> out;
  for (const auto& [k, p] : peers_) {
    const Sample* s = before(p, now_s);
    if (!s || now_s - s->time_s > stale_after_s_) out.push_back(p.rsu_id);
  }
  return out;
}

}  // namespace palcas::rsu
