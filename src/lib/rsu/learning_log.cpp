#include "palcas_core/rsu/learning_log.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace palcas::rsu {
namespace fs = std::filesystem;

LearningLog::LearningLog(std::string csv_path, std::string rsu_id, std::string mode)
    : csv_path_(std::move(csv_path)), rsu_id_(std::move(rsu_id)), mode_(std::move(mode)) {}

const char* LearningLog::header() {
  return "rsu_id,mode,decisions,transitions,mean_reward,sum_reward,epsilon,gradient_steps,"
         "q_loss,param_loss,model_version,federation_round,decision_ms_mean";
}

void LearningLog::addDecision(std::uint64_t step, const RsuControllerStats& stats, double decision_ms) {
  if (active_ && step <= last_step_) endEpisode(stats);  // the bridge restarted
  active_ = true;
  last_step_ = step;
  ++decisions_;
  transitions_ += stats.transitions_closed;
  reward_sum_ += stats.sum_reward;
  decision_ms_sum_ += decision_ms;
}

void LearningLog::endEpisode(const RsuControllerStats& s) {
  if (!active_) return;
  const std::uint64_t decisions = decisions_, transitions = transitions_;
  const double reward_sum = reward_sum_, decision_ms_sum = decision_ms_sum_;
  active_ = false;
  decisions_ = transitions_ = 0;
  reward_sum_ = decision_ms_sum_ = 0.0;
  if (csv_path_.empty()) return;
  const fs::path path(csv_path_);
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  const bool fresh = !fs::exists(path);
  std::ofstream rows(path, std::ios::app);
  if (fresh) rows << header() << '\n';
  rows << rsu_id_ << ',' << mode_ << ',' << decisions << ',' << transitions << ','
       << (transitions ? reward_sum / static_cast<double>(transitions) : std::nan("")) << ','
       << reward_sum << ',' << s.epsilon << ',' << s.gradient_steps << ',' << s.q_loss << ','
       << s.param_loss << ',' << s.model_version << ',' << s.federation_round << ','
       << (decisions ? decision_ms_sum / static_cast<double>(decisions) : 0.0) << '\n';
  rows.flush();
  if (!rows) throw std::runtime_error("learning log: cannot write " + csv_path_);
}

}  // namespace palcas::rsu
