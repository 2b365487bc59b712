#pragma once
// The run folder of one episode: the generated scenario, manifest.json (what ran: config
// snapshot and hash, seeds, SUMO version, git commit, command line) and metrics.json.

#include <nlohmann/json.hpp>
#include <palcas_core/metrics/episode_metrics.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "palcas_sim/episode_runner.h"
#include "palcas_sim/scenario.h"
#include "palcas_sim/sumo_session.h"
#include "palcas_sumo_bridge/bridge_options.h"
#include "palcas_sumo_bridge/episode_measure.h"
#include "palcas_sumo_bridge/rviz_view.h"

namespace palcas::bridge {

using StepTimer = sim::StepTimer;

struct RunSummary {
  int episode = 0;
  metrics::EpisodeMetrics metrics;
  std::vector<metrics::ExitTally> exits;  ///< per cluster: which zone's exits were served
  double wall_seconds = 0.0;
  std::uint64_t steps = 0;
  std::map<std::string, std::uint64_t> late_by_rsu;
  std::map<std::string, std::uint64_t> rejections_by_reason;
  StepTimer timing;
  /// RSU decision latencies (AdvisoryArray.decision_ms of answers that advised) [ms].
  std::vector<float> decision_ms;
  /// Advised lane changes finished / dropped for want of a safe gap within their time.
  std::uint64_t lane_changes_done = 0, lane_changes_dropped = 0;
  std::uint64_t vanished_vehicles = 0;  ///< tracked vehicles SUMO no longer knew
  std::uint64_t route_changes_failed = 0;  ///< exit route changes SUMO refused
  sim::GuardCounters guard;  ///< how often the advice guard acted
  std::uint64_t insertion_dropped = 0;  ///< vehicles SUMO dropped at insertion (max_depart_delay_s)
  std::uint64_t insertion_waiting_end = 0;  ///< vehicles still waiting to enter at the end
  double insertion_wait_veh_s = 0.0;  ///< vehicle-seconds spent waiting to enter (dropped ones too)
  v2x::DownlinkCounts downlink;  ///< the advisories' way through the V2X channel
};

/// Generates the scenario into <out_dir>/scenario and writes manifest.json.
/// @return the .sumocfg path. @throws std::exception naming what failed.
std::string prepareScenario(const BridgeOptions& options);

/// Where episode k's own files go: the run folder, or <out_dir>/episode_<k> when the run has
/// several episodes (or continues a training), so each keeps its own.
std::string episodeDir(const BridgeOptions& options, int episode);

/// The episode loop's options from the bridge's (duration, lockstep, holds, V2X, recording,
/// episodeDir): one mapping for the bridge node and the Python environment, which run the
/// same loop.
sim::RunnerOptions runnerOptions(const BridgeOptions& options);

/// SUMO session options for a generated scenario; episode k runs with SUMO seed + k and
/// writes the SUMO outputs named in options.sumo_outputs into episodeDir (created here).
sim::SessionOptions sessionOptionsFor(const BridgeOptions& options, const std::string& sumocfg,
                                      int episode = 0);

/// Adds the SUMO version, API and the measuring rules (exit positions, thresholds, which
/// metrics_from_bag needs) to <out_dir>/manifest.json once SUMO runs.
void completeManifest(const BridgeOptions& options, const std::string& sumo_version,
                      const std::string& api_name, const MeasureRules& rules);

/// The measuring rules stored in a manifest.json. @throws std::runtime_error naming what
/// is missing when the file is not a PALCAS manifest.
MeasureRules readMeasureRules(const std::string& manifest_path);

/// metrics.json's `exits_by_cluster`: per cluster its exit-bound CAVs by outcome and the share
/// served (null without any), for the bridge and metrics_from_bag alike.
nlohmann::json exitsJson(const std::vector<metrics::ExitTally>& exits);

/// Writes the episode's metrics atomically (NaN as null) to <out_dir>/metrics.json, a row of
/// <out_dir>/episodes.csv, and with several episodes <out_dir>/episode_<k>/metrics.json.
void writeMetricsJson(const BridgeOptions& options, const RunSummary& summary, int episode);

/// The view that frames the road in the window of ~rviz_template (rviz_view.h); with a
/// template, also writes it with that view as <out_dir>/palcas.rviz (atomically: rviz
/// may be waiting for the file). Without one, framed for rviz's default 1400x860 window.
/// @throws std::runtime_error naming the template when it cannot be read or lacks a view.
RoadView prepareRvizView(const BridgeOptions& options,
                         const std::vector<std::vector<std::pair<double, double>>>& lane_shapes);

}  // namespace palcas::bridge
