// RunRecorder: what a run leaves behind for figures drawn later without simulating again.
// trajectories.csv samples every vehicle every `trajectory_period_steps` steps; decisions.csv
// has one row per RSU decision that advised at least one CAV. Both are plain CSV with a
// header, flushed on close (and by the destructor).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "palcas_sim/sumo_session.h"

namespace palcas::sim {

class RunRecorder {
 public:
  static constexpr const char* kTrajectoryHeader =
      "time_s,vehicle,cav,route,exit_cluster,part,x_m,lane,speed_mps,accel_mps2,command,"
      "command_accel_mps2,lane_change_target";
  static constexpr const char* kDecisionHeader = "time_s,rsu,decision_ms,advisories";

  /// Creates `dir` and both files. trajectory_period_steps: sample every N steps (>= 1).
  /// @throws std::invalid_argument for a period < 1, std::runtime_error when a file cannot
  /// be created (naming it).
  RunRecorder(const std::string& dir, int trajectory_period_steps);
  ~RunRecorder();
  RunRecorder(const RunRecorder&) = delete;
  RunRecorder& operator=(const RunRecorder&) = delete;

  /// After step `step` (1-based count) at `time_s`: every vehicle, if the step is sampled.
  void addStep(std::uint64_t step, double time_s, const std::vector<VehicleRecord>& vehicles);
  /// One RSU decision applied at `time_s`.
  void addDecision(double time_s, const std::string& rsu_id, double decision_ms, std::size_t advisories);
  /// Flushes both files; @throws std::runtime_error if a write failed (disk full).
  void close();

  std::uint64_t trajectoryRows() const { return trajectory_rows_; }
  std::uint64_t decisionRows() const { return decision_rows_; }

 private:
  std::string dir_;
  int period_;
  std::ofstream trajectories_;
  std::ofstream decisions_;
  std::uint64_t trajectory_rows_ = 0;
  std::uint64_t decision_rows_ = 0;
  bool closed_ = false;
};

}  // namespace palcas::sim
