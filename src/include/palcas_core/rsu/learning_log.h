#pragma once
// The per-episode learning record of one RSU: <checkpoint_dir>/<rsu_id>/learning.csv, a
// row per episode (decisions, transitions, mean reward, epsilon, gradient steps, losses,
// model version, federation round, mean decision time). tools/learning_curves.py and
// tools/ship_policy.py read it. ROS-free: the node feeds it once per decision.

#include <cstdint>
#include <string>

#include "palcas_core/rsu/rsu_controller.h"

namespace palcas::rsu {

class LearningLog {
 public:
  /// csv_path "" keeps the figures but writes nothing. mode: "train" or "eval" (a column).
  LearningLog(std::string csv_path, std::string rsu_id, std::string mode);

  /// One decision made at bridge step `step`; `stats` is the controller's right after it
  /// (its transitions_closed and sum_reward are this decision's). A step not after the
  /// last one means the bridge began a new episode: the finished episode's row is written
  /// first (its epsilon, steps and losses as `stats` has them).
  void addDecision(std::uint64_t step, const RsuControllerStats& stats, double decision_ms);

  /// Writes the open episode's row with `stats` (nothing if no decision since the last
  /// row). Throws std::runtime_error naming the file if it cannot be written.
  void endEpisode(const RsuControllerStats& stats);

  /// Decisions in the open episode.
  std::uint64_t decisions() const { return decisions_; }
  static const char* header();

 private:
  std::string csv_path_, rsu_id_, mode_;
  bool active_ = false;
  std::uint64_t last_step_ = 0, decisions_ = 0, transitions_ = 0;
  double reward_sum_ = 0.0, decision_ms_sum_ = 0.0;
};

}  // namespace palcas::rsu
