#include "palcas_sim/advisory_holds.h"

#include <algorithm>
#include <stdexcept>

namespace palcas::sim {

AdvisoryHolds::AdvisoryHolds(std::uint64_t hold_steps, std::uint64_t keep_steps)
    : hold_steps_(hold_steps), keep_steps_(keep_steps) {
  if (hold_steps < 1) throw std::invalid_argument("advisory holds: hold_steps must be >= 1, got 0");
}

void AdvisoryHolds::advised(const std::string& vehicle_id, const std::string& rsu_id, std::uint64_t step,
                            int action, bool keepable) {
  holds_[vehicle_id] = Hold{rsu_id, step, action, keepable};
}

std::vector<std::pair<std::string, int>> AdvisoryHolds::inForce() const {
  std::vector<std::pair<std::string, int>> out;
  for (const auto& [id, hold] : holds_)
    if (hold.action >= 0) out.emplace_back(id, hold.action);
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> AdvisoryHolds::ending(std::uint64_t step, const std::unordered_set<std::string>& late_rsus,
                                               const std::function<bool(const std::string&)>& on_road) {
  std::vector<std::string> out;
  for (auto it = holds_.begin(); it != holds_.end();) {
    if (!on_road(it->first)) {
      it = holds_.erase(it);
      continue;
    }
    Hold& h = it->second;
    const std::uint64_t length = hold_steps_ + (h.keepable ? keep_steps_ : 0);
    if (h.step != step && (late_rsus.count(h.rsu_id) || step >= h.step + length)) {
      out.push_back(it->first);
      h.action = -1;
    }
    ++it;
  }
  std::sort(out.begin(), out.end());  // a stable order for callers and tests
  return out;
}

}  // namespace palcas::sim
