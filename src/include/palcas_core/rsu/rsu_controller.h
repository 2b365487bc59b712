#pragma once
// One RSU's decisions and learning, without ROS (paper "Design of PALCAS").
// The palcas_rsu node is a thin shell around RsuController: it converts messages to a
// RoadSnapshot, decides WHEN to call decide(), publishes the result, and runs the
// federation exchange. Behaviour, choices and their reasons: src/doc/rsu.md.
//
// Conventions: lanes 1 = rightmost (exit) .. L = leftmost, 0 = off the mainline;
// x = metres along the mainline; SI units; time is an argument, never read inside.

#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "palcas_core/common/action.h"
#include "palcas_core/common/road_snapshot.h"
#include "palcas_core/learning/model_blob.h"
#include "palcas_core/learning/pdqn_agent.h"
#include "palcas_core/learning/pdqn_config.h"
#include "palcas_core/reward/reward.h"
#include "palcas_core/reward/terminal_rewards.h"
#include "palcas_core/rsu/cluster_stats.h"
#include "palcas_core/rsu/rule_advisor.h"
#include "palcas_core/rsu/transition_book.h"
#include "palcas_core/state/state_builder.h"

namespace palcas::rsu {

/// Where an RSU's advice comes from.
enum class AdviceSource {
  kNetwork,  ///< the PDQN policy (the learning arms)
  kRules,    ///< the documented rule of rule_advisor.h (the `rules` control arm; never learns)
};

/// The advice a rule_residual network departs from (RsuControllerOptions::residual_default).
enum class ResidualDefault { kRule, kKeep };

/// Every knob of one RSU controller (config/rsu.yaml, config/reward.yaml, config/learning.yaml).
struct RsuControllerOptions {
  std::string rsu_id = "rsu_0";  ///< non-empty; names this RSU in checkpoints and messages
  int cluster_index = 0;         ///< 0-based, upstream to downstream
  double x_start_m = 0.0;        ///< zone [x_start_m, x_end_m) along the mainline [m]
  double x_end_m = 800.0;
  int num_lanes = 5;  ///< mainline lanes L >= 1; pdqn.state_size must be 40 + L
  bool train = true;  ///< true: explore, remember, update; false: greedy evaluation only
  /// kRules: the advice comes from ruleDecision() with `rules` (train must be false; the
  /// network is built but never asked).
  AdviceSource advice_source = AdviceSource::kNetwork;
  RuleAdvisorOptions rules;  ///< the rule's thresholds (used with kRules and rule_residual)
  /// kNetwork on top of the rule: the network's greedy advice replaces the rule's only where
  /// its Q value exceeds that of the rule's action by more than residual_margin (>= 0, Q
  /// units), so the policy starts from the rule and learns where to depart from it.
  bool rule_residual = false;
  double residual_margin = 0.0;
  /// What the network departs from with rule_residual: kRule, the rule's advice; kKeep, KEEP
  /// for every member (in assist mode: no advice, the CAV's own driving), so the network
  /// speaks only where it is sure that advice beats none.
  ResidualDefault residual_default = ResidualDefault::kRule;
  /// An exit-bound CAV (finite distance_to_exit_m) closer than this to its off-ramp is never
  /// advised to change left, away from the exit side: such advice becomes KEEP, and in train
  /// mode the action is left out of its state's valid actions. >= 0 [m]; 0 (paper) = off.
  double no_left_for_exit_within_m = 0.0;
  /// A CAV whose lane changed less than this long ago is not advised another lane change,
  /// except towards its exit (right, when exit-bound) and the merge from the acceleration
  /// lane: such advice becomes KEEP, and in train mode the action is left out of its state's
  /// valid actions. The lane is seen at this RSU's decisions. >= 0 [s]; 0 (paper) = off.
  double lane_change_dwell_s = 0.0;
  /// true: an exit-bound CAV that the rule (`rules`, rule 2 of rule_advisor.h) would advise
  /// right towards its exit is advised right, whatever the network or adviseWith() chose: the
  /// `rules` control arm's exit service under the learned advice, so a CAV the network leaves
  /// in its lane too long still reaches its off-ramp. Not learned; false (paper) = off.
  bool exit_rule_override = false;
  /// With exit_rule_override: the override acts only while this zone's mainline density,
  /// averaged over its lanes, is below this [veh/km per lane], so it serves exits at light
  /// traffic and leaves a busy road's right lanes alone. >= 0; 0 = at any density.
  double exit_rule_below_density_veh_per_km = 0.0;
  /// With exit_rule_below_density_veh_per_km: the density read against that limit is the mean
  /// over this zone's decisions of the last this-many seconds, and the override waits until the
  /// zone has held traffic for that long (an empty zone starts the wait again). An empty road
  /// fills at light density at every demand; without the wait the override acts during the
  /// fill of a road about to be busy. >= 0 [s]; 0 = the density at the decision alone.
  double exit_rule_density_window_s = 0.0;
  /// With exit_rule_override: the override acts only while the zone's inflow, the vehicles that
  /// appeared on its mainline lanes over the last exit_rule_inflow_window_s seconds, per lane
  /// and hour, is below this, and not before the zone has held traffic for that window (an
  /// empty zone starts the wait again). A busy road's demand reaches a zone at close to its full
  /// rate well before the zone's density rises.
  /// >= 0 [veh/h per lane]; 0 = any inflow.
  double exit_rule_below_inflow_veh_per_h_per_lane = 0.0;
  /// The window the inflow is counted over (> 0 [s]; read only with an inflow limit).
  double exit_rule_inflow_window_s = 120.0;
  /// Subtracted from the reward of a transition whose advice was a lane change that does not
  /// serve the CAV's route (anything but an exit-bound CAV's change right and the merge off
  /// the acceleration lane): the speed-gain changes a policy makes too many of cost something,
  /// so it learns which are worth it. Training only. >= 0, reward units; 0 (paper) = off.
  double lane_change_cost = 0.0;
  /// Gradient steps per decide() call once the replay holds a batch (>= 0, finite);
  /// fractional credit accumulates (0.25 = one step every 4 calls).
  double gradient_steps_per_decision = 1.0;
  /// Local gradient steps between federation rounds (paper E = 2500); 0 = never due
  /// (independent baseline).
  uint64_t federation_interval_steps = 2500;
  /// Personalised federation: the last this-many Linear layers of each network (with what
  /// follows them) stay the RSU's own when a global model is loaded; the rest (the shared
  /// body) is the federation's. 0 (paper): the whole global model is loaded.
  size_t personal_head_layers = 0;
  /// Rewards of collisions, exits taken or missed and failed merges (the paper defines
  /// none: all 0 / false by default; reward/terminal_rewards.h).
  TerminalRewards terminal;
  /// true: a transition's reward is the mean of the per-step rewards over the period the
  /// decision held (every bridge step up to the next decision, fed by observeStep()).
  /// false (paper): the reward of the one snapshot at the next decision.
  bool reward_over_period = false;
  RewardParams reward;  ///< paper reward constants
  StateScales scales;   ///< state normalisation
  PdqnConfig pdqn;      ///< agent hyper-parameters (seed included)

  /// Throws std::invalid_argument naming the first bad field ("x_end_m", "pdqn.state_size",
  /// "reward: rho", "terminal: collision_penalty", ...) and its value.
  void validate() const;
};

/// The advisory for one member CAV.
struct CavAdvisory {
  std::string vehicle_id;
  Decision decision;  ///< action and acceleration parameter [m/s^2]
};

/// Everything one decide() call produces for the node to publish.
struct DecisionOutput {
  uint64_t step = 0;     ///< as passed in
  double time_s = 0.0;   ///< as passed in [s]
  uint32_t model_version = 0;
  std::vector<CavAdvisory> advisories;  ///< one per member, in snapshot order
  ClusterSummary cluster;               ///< this zone's statistics, for I2I (ClusterState)
};

/// What a decision would see, before anything changes (preview()): the members in the
/// order advise() decides them, their states (state_size x members, one column each), their
/// lanes, and in train mode the transitions the decision would close (each CAV's reward
/// and whether its transition ends there).
struct DecisionView {
  std::vector<std::string> member_ids;
  nn::Matrix states;
  std::vector<int> member_lanes;
  std::vector<Closure> closures;  ///< empty in eval mode and when the step starts an episode
};

/// Counters and figures for the node's status topics.
struct RsuControllerStats {
  uint64_t decisions = 0;     ///< decide() calls since construction
  uint32_t member_count = 0;  ///< members at the last decision
  /// Advisories per action code (Action order) at the last decision.
  std::array<uint32_t, ACTION_COUNT> action_counts{};
  uint32_t transitions_closed = 0;  ///< transitions closed at the last decision (train mode)
  /// Mean per-CAV reward of the transitions closed at the last decision; NaN when none.
  double mean_reward = std::numeric_limits<double>::quiet_NaN();
  /// R_k: sum of the per-CAV rewards of those transitions (paper's sum over CAVs).
  double sum_reward = 0.0;
  /// Losses of the last gradient step; NaN before the first one.
  double q_loss = std::numeric_limits<double>::quiet_NaN();
  double param_loss = std::numeric_limits<double>::quiet_NaN();
  double epsilon = 0.0;
  uint64_t gradient_steps = 0;            ///< agent's total gradient steps
  uint64_t samples_since_federation = 0;  ///< n_k
  uint64_t transitions_stored = 0;        ///< total remembered since construction / checkpoint
  uint64_t pending_dropped = 0;           ///< pending transitions dropped by new episodes
  uint32_t model_version = 0;
  uint32_t federation_round = 0;  ///< global models loaded so far
};

/// The actions a CAV in `lane` may take: all but a lane change that leaves the mainline
/// lanes (left from lane L; right from lane 1 or from the acceleration lane, lane 0). The
/// one rule behind both the advisories (maskImpossibleLaneChange) and the valid-action
/// mask stored with each transition's next state.
ActionMask possibleActions(int lane, int num_lanes);

/// A decision outside possibleActions(lane, num_lanes) becomes KEEP: the bridge would refuse
/// it, and the replay should hold the action that was executed. Other decisions are
/// returned unchanged.
Decision maskImpossibleLaneChange(Decision decision, int lane, int num_lanes);

/// possibleActions() of the vehicle's lane, less a left change when it is exit-bound, on a
/// mainline lane (the merge from the acceleration lane stays allowed) and closer than
/// no_left_for_exit_within_m (> 0) to its off-ramp.
ActionMask allowedActions(const VehicleSnapshot& vehicle, int num_lanes, double no_left_for_exit_within_m);

/// The actions the dwell leaves a vehicle whose lane changed since_lane_change_s ago: all
/// when dwell_s is 0 (off), the change is not that recent, or the vehicle is on the
/// acceleration lane (lane 0: its left change is the merge); otherwise no lane change but
/// a right one of an exit-bound vehicle (finite distance_to_exit_m), towards its exit.
ActionMask dwellAllowedActions(const VehicleSnapshot& vehicle, double since_lane_change_s, double dwell_s);

/// Whether advising `action` to the vehicle serves its route: a change right of an exit-bound
/// vehicle (finite distance_to_exit_m), the merge from the acceleration lane (a left change
/// from lane 0), and every action that is not a lane change. lane_change_cost charges the
/// rest, as the bridge's guard refuses them in a busy zone.
bool servesRoute(const VehicleSnapshot& vehicle, Action action);

/// The controller's counters that a checkpoint carries beside the agent: one key of
/// controller.txt each (the one list of the keys: rsu_controller_io.cpp; src/doc/rsu.md,
/// "Checkpoints").
struct ControllerCounters {
  uint64_t samples_since_federation = 0;  ///< n_k
  double gradient_credit = 0.0;           ///< gradient steps earned but not made, in [0, 1)
  uint64_t grad_steps_at_round = 0;       ///< the agent's gradient steps at the last global model
  uint32_t model_version = 0;
  uint32_t federation_round = 0;          ///< global models loaded so far
  uint64_t transitions_stored = 0;
  uint64_t decisions = 0;                 ///< decide() / advise() calls
};

/// One RSU k: membership, batched PDQN decisions, transitions (stored as its TransitionBook
/// closes them), gradient steps, federation bookkeeping and checkpoints for zone
/// [x_start_m, x_end_m). Deterministic for a seed
/// (one Eigen thread). Not thread-safe: call from one thread. Movable, not copyable.
class RsuController {
 public:
  /// Validates the options (RsuControllerOptions::validate) and builds the agent.
  /// Throws std::invalid_argument naming the bad field.
  explicit RsuController(const RsuControllerOptions& options);

  /// One decision round. `snapshot`: the whole road (num_lanes must equal the options');
  /// `step`: bridge step; `time_s`: simulation time [s], finite and >= 0; `global`: I2I
  /// densities [veh/km], NaN = unknown; `outcomes`: events since the previous call.
  /// Closes the pending transitions (train mode), decides for every member in ONE batched
  /// act() (impossible lane changes masked to KEEP), runs the due gradient steps (train mode). A step not greater than the previous
  /// call's starts a new episode (see endEpisode()).
  /// Throws std::invalid_argument naming the vehicle and field (NaN, lane outside 0..L,
  /// duplicate id, ...), a wrong num_lanes, or a bad time; the controller is then untouched.
  /// decide() = advise() then learn(); a node that must answer fast calls advise(),
  /// publishes, then learn(), so the advisories do not wait for the gradient steps.
  DecisionOutput decide(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                        const GlobalDensities& global, const VehicleOutcomes& outcomes);
  /// decide() without the gradient steps (same preconditions and exceptions).
  DecisionOutput advise(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                        const GlobalDensities& global, const VehicleOutcomes& outcomes);
  /// What advise() on the same arguments would see, without changing anything (an outside
  /// learner, palcas_env, chooses the decisions from it and passes them to adviseWith()).
  /// Throws like advise().
  DecisionView preview(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                       const GlobalDensities& global, const VehicleOutcomes& outcomes) const;
  /// advise() with the members' decisions given from outside (in preview()'s member order)
  /// instead of the network's or the rule's: the same masking of impossible lane changes and,
  /// in train mode, the same transitions closed and stored. The agent's act() is not called,
  /// so exploration and its random numbers are untouched. Throws like advise(), and
  /// std::invalid_argument when `decisions` has another size than the members (nothing
  /// changed then).
  DecisionOutput adviseWith(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                            const GlobalDensities& global, const VehicleOutcomes& outcomes,
                            const std::vector<Decision>& decisions);
  /// The gradient steps due after one decision (train mode; nothing in eval mode).
  /// Touches only the agent: a node may run it on another thread while it calls
  /// observeStep(), and must join it before the next advise()/decide() or any other call.
  void learn();
  /// A bridge step between two decisions (train mode, reward_over_period): adds every
  /// pending CAV's reward at this step to its period mean. Never touches the agent.
  /// Throws std::invalid_argument like advise() on a malformed snapshot (nothing changed).
  void observeStep(const RoadSnapshot& snapshot);

  /// Drops the pending transitions without storing them (an episode cut by the simulation
  /// end is not a terminal state) and forgets the previous step.
  void endEpisode();

  /// True when a member: a CAV with x_m in [x_start_m, x_end_m) on a mainline lane
  /// (lane >= 1) or on the acceleration lane.
  bool isMember(const VehicleSnapshot& vehicle) const;

  /// True once federation_interval_steps local gradient steps were made since the last
  /// loadGlobalModel() (or construction); stays true until the next loadGlobalModel().
  bool federationDue() const;
  /// The local model to submit (online networks).
  ModelBlob exportModel() const { return agent_.exportModel(); }
  /// n_k: transitions stored since the last loadGlobalModel() (or construction).
  uint64_t samplesSinceFederation() const { return counters_.samples_since_federation; }
  /// Imports the global model (with personal_head_layers, all but this RSU's own head)
  /// and starts a new round: clears the due flag and n_k, sets the model version, counts
  /// the round. Throws std::invalid_argument (local model
  /// and counters kept) on another layout, a bad checksum, wrong size, non-finite value,
  /// or a version older than the current one.
  void loadGlobalModel(const ModelBlob& blob, uint32_t version);
  /// Loads a model file written by PdqnAgent::saveModel / saveModelBlob (for eval).
  /// Throws std::runtime_error (model untouched) if the file fails a check. The model
  /// version is left as it is.
  void loadPolicy(const std::string& path);

  /// Writes <dir>/agent.ckpt (PdqnAgent checkpoint: networks, optimisers, replay, epsilon,
  /// RNG) and <dir>/controller.txt (this controller's counters), each atomically (temp
  /// file + rename); creates `dir` if needed. Pending transitions are not saved.
  /// Throws std::runtime_error on an I/O error, and (writing nothing) when `dir` already
  /// holds a checkpoint this controller neither loaded nor wrote last: another process owns
  /// it, e.g. a newer launch of the same training, and an older one must not overwrite it.
  void saveCheckpoint(const std::string& dir) const;
  /// Reads what saveCheckpoint wrote. Throws std::runtime_error (controller untouched) if
  /// a file is missing, not ours, of another rsu_id or layout, or malformed. On success
  /// the pending transitions are dropped and the previous step forgotten. An agent.ckpt
  /// from before the masks were stored gets each transition's mask from the lane of its s'.
  void loadCheckpoint(const std::string& dir);

  RsuControllerStats stats() const;
  const RsuControllerOptions& options() const { return options_; }
  const PdqnAgent& agent() const { return agent_; }
  uint32_t modelVersion() const { return counters_.model_version; }
  uint32_t federationRound() const { return counters_.federation_round; }
  /// Members whose last decision waits for its outcome (train mode).
  size_t pendingCount() const { return book_.pendingCount(); }

 private:
  struct Observation;  // everything decide() computes before changing any state

  Observation observe(const RoadSnapshot& snapshot, double time_s, const GlobalDensities& global,
                      const VehicleOutcomes& outcomes) const;
  /// allowedActions() less what the dwell forbids at time_s.
  ActionMask allowedFor(const VehicleSnapshot& vehicle, double time_s) const;
  /// Seconds since the vehicle's lane was seen to change (0 when it differs from the lane
  /// seen at the last decision; +inf when never seen to change or the dwell is off).
  double sinceLaneChange(const VehicleSnapshot& vehicle, double time_s) const;
  /// Remembers every vehicle's lane and when it last changed (only with the dwell on).
  void rememberLanes(const RoadSnapshot& snapshot, double time_s);
  /// Adds this decision's lane density to the exit rule's window; whether the zone counts as
  /// light traffic for the exit rule override now.
  bool exitRuleLightTraffic(double lane_density_veh_per_km, double time_s);
  /// Forgets the window and the time traffic arrived (a new episode, an empty zone).
  void resetDensityWindow();
  /// Counts the vehicles new on the zone's mainline lanes since the last decision; whether the
  /// zone's inflow over the window is below the exit rule's limit now (true without a limit).
  bool exitRuleLowInflow(const RoadSnapshot& snapshot, double time_s);
  /// Forgets the inflow count and the time traffic arrived (a new episode, an empty zone).
  void resetInflowWindow();
  std::unordered_map<std::string, StateNow> statesNow(const Observation& obs,
                                                      const MemberColumns& columns,
                                                      const PendingFates& fates,
                                                      const RoadIndex& road,
                                                      const NeighbourFinder& finder,
                                                      const ClusterStats& stats,
                                                      const GlobalDensities& global,
                                                      double time_s) const;
  /// Remembers the closed transitions (id order) and counts them for the stats and n_k.
  void storeClosures(const std::vector<Closure>& closures);
  void runGradientSteps();

  DecisionOutput adviseImpl(const RoadSnapshot& snapshot, uint64_t step, double time_s,
                            const GlobalDensities& global, const VehicleOutcomes& outcomes,
                            const std::vector<Decision>* given);

  RsuControllerOptions options_;
  StateBuilder builder_;
  PdqnAgent agent_;
  std::vector<nn::Network::StateSpan> personal_head_;  ///< kept from the local model on loadGlobalModel
  TransitionBook book_;  // pending decisions and limbo
  /// The exit rule's density window: (decision time [s], lane density [veh/km]) of the zone's
  /// decisions since traffic_since_s_, the last exit_rule_density_window_s seconds of them.
  std::deque<std::pair<double, double>> density_window_;
  double traffic_since_s_ = std::numeric_limits<double>::quiet_NaN();
  /// The exit rule's inflow count: the zone's mainline vehicles at the last decision, and
  /// (decision time [s], vehicles new since the decision before) since inflow_since_s_.
  std::unordered_set<std::string> inflow_members_;
  std::deque<std::pair<double, uint32_t>> inflow_window_;
  double inflow_since_s_ = std::numeric_limits<double>::quiet_NaN();
  bool have_last_step_ = false;
  uint64_t last_step_ = 0;
  struct LaneSeen {
    int lane = 0;
    double changed_s = -std::numeric_limits<double>::infinity();  // -inf: never seen to change
  };
  std::unordered_map<std::string, LaneSeen> lanes_seen_;  // lane_change_dwell_s > 0 only
  ControllerCounters counters_;  // what a checkpoint carries besides the agent
  RsuControllerStats stats_;      // of the last decision (counters_ and the agent's aside)
  // The checkpoint this controller continues (loaded or last wrote): saveCheckpoint only
  // replaces a file with this id (mutable: saving does not change what the controller does).
  mutable bool checkpoint_owned_ = false;
  mutable uint64_t checkpoint_seen_id_ = 0;
};

}  // namespace palcas::rsu
