#include "palcas_sim/run_recorder.h"

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace palcas::sim {

namespace {
const char* commandName(HeldCommand c) {
  switch (c) {
    case HeldCommand::kNone: return "none";
    case HeldCommand::kKeepSpeed: return "keep_speed";
    case HeldCommand::kAccelerate: return "accelerate";
  }
  return "none";
}

std::ofstream openCsv(const std::string& path, const char* header) {
  std::ofstream out(path, std::ios::trunc);
  if (!out) throw std::runtime_error("RunRecorder: cannot create '" + path + "'");
  out << header << '\n';
  return out;
}
}  // namespace

RunRecorder::RunRecorder(const std::string& dir, int trajectory_period_steps)
    : dir_(dir), period_(trajectory_period_steps) {
  if (period_ < 1)
    throw std::invalid_argument("RunRecorder: trajectory_period_steps must be >= 1, got " +
                                std::to_string(period_));
  std::filesystem::create_directories(dir_);
  trajectories_ = openCsv(dir_ + "/trajectories.csv", kTrajectoryHeader);
  decisions_ = openCsv(dir_ + "/decisions.csv", kDecisionHeader);
  trajectories_.precision(6);
  decisions_.precision(6);
}

RunRecorder::~RunRecorder() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; close() reports the failure when called explicitly.
  }
}

void RunRecorder::addStep(std::uint64_t step, double time_s, const std::vector<VehicleRecord>& vehicles) {
  if (closed_ || step % static_cast<std::uint64_t>(period_) != 0) return;
  for (const VehicleRecord& v : vehicles) {
    trajectories_ << time_s << ',' << v.id << ',' << (v.is_cav ? 1 : 0) << ','
                  << routeKindName(v.route_kind) << ',' << v.exit_cluster << ','
                  << roadPartName(v.part) << ',' << v.x_m << ',' << v.lane << ',' << v.speed_mps
                  << ',' << v.accel_mps2 << ',' << commandName(v.command) << ','
                  << (v.command == HeldCommand::kAccelerate ? v.command_value : 0.0) << ','
                  << v.lane_change_target << '\n';
    ++trajectory_rows_;
  }
}

void RunRecorder::addDecision(double time_s, const std::string& rsu_id, double decision_ms,
                              std::size_t advisories) {
  if (closed_) return;
  decisions_ << time_s << ',' << rsu_id << ',' << decision_ms << ',' << advisories << '\n';
  ++decision_rows_;
}

void RunRecorder::close() {
  if (closed_) return;
  closed_ = true;
  trajectories_.flush();
  decisions_.flush();
  const bool ok = trajectories_.good() && decisions_.good();
  trajectories_.close();
  decisions_.close();
  if (!ok) throw std::runtime_error("RunRecorder: writing into '" + dir_ + "' failed");
}

}  // namespace palcas::sim
