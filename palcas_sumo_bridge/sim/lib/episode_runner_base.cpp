// The parts of palcas_sim/episode_runner.h that do not drive SUMO: in palcas_sim itself (the
// runner is compiled once per SUMO API, with the session).
#include "palcas_sim/episode_runner.h"

namespace palcas::sim {

metrics::KnownVehicle knownVehicle(const VehicleRecord* record, int num_lanes) {
  metrics::KnownVehicle k;
  k.num_lanes = num_lanes;
  if (!record) return k;
  k.exists = true;
  k.is_cav = record->is_cav;
  k.lane = record->lane;
  k.on_accel_lane = record->on_accel_lane;
  return k;
}

void StepTimer::add(std::size_t vehicles, double sumo_s, double bridge_s, double lockstep_s) {
  Bucket& b = buckets_[vehicles / BUCKET_WIDTH * BUCKET_WIDTH];
  ++b.steps;
  b.sumo_s += sumo_s;
  b.bridge_s += bridge_s;
  b.lockstep_s += lockstep_s;
}

}  // namespace palcas::sim
