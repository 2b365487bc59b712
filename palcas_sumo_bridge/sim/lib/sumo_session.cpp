// SumoSession: start and stop SUMO, read the network, advance one step. The other concerns
// are in sumo_session_vehicles.cpp (vehicle table), sumo_session_guard.cpp (the advice
// guard's decisions, palcas_sim/advice_guard.h, carried out), sumo_session_routes.cpp (exit routing), sumo_session_actuation.cpp (advice
// carried out); sumo_session_api.h: the SUMO API they share (libsumo or libtraci).

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <stdexcept>

#ifdef PALCAS_USE_LIBTRACI
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>
#endif

#include "palcas_sim/sumo_session.h"

#include "sumo_session_api.h"

namespace palcas::sim {

using namespace session_detail;

#ifdef PALCAS_USE_LIBTRACI
namespace {

/// A TCP port free on this host now (the kernel's pick for port 0).
int freeTcpPort() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("no socket to find a free TraCI port");
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  const bool ok = ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0;
  ::close(fd);
  if (!ok) throw std::runtime_error("cannot find a free TraCI port");
  return ntohs(a.sin_port);
}

/// Starts `cmd` in a session of its own, output to /dev/null, not waited for.
void spawnDetached(const std::vector<std::string>& cmd) {
  std::vector<char*> argv;
  for (const std::string& a : cmd) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error("cannot start " + cmd[0] + ": fork failed");
  if (pid == 0) {
    ::setsid();
    const int null = ::open("/dev/null", O_RDWR);
    if (null >= 0) {
      ::dup2(null, 0);
      ::dup2(null, 1);
      ::dup2(null, 2);
    }
    ::execvp(argv[0], argv.data());
    ::_exit(127);
  }
}

}  // namespace
#endif

const char* SumoSession::apiName() {
#ifdef PALCAS_USE_LIBTRACI
  return "libtraci";
#else
  return "libsumo";
#endif
}

SumoSession::SumoSession(const SessionOptions& options) : options_(options), guard_(options.guard) {
  std::vector<std::string> cmd{options_.sumo_binary};
#ifndef PALCAS_USE_LIBTRACI
  cmd[0] = "sumo";  // in-process: the binary name is only argv[0]
#endif
  cmd.insert(cmd.end(), options_.sumo_args.begin(), options_.sumo_args.end());
  // SUMO only reports collisions; step() removes the colliding vehicles (remove_collided).
  if (options_.remove_collided) cmd.insert(cmd.end(), {"--collision.action", "warn"});
  try {
#ifdef PALCAS_USE_LIBTRACI
    if (options_.detach_sumo) {
      const int port = options_.traci_port > 0 ? options_.traci_port : freeTcpPort();
      cmd.insert(cmd.end(), {"--remote-port", std::to_string(port)});
      spawnDetached(cmd);
      api::Simulation::init(port, 600);  // up to a minute for a GUI to come up
    } else {
      api::Simulation::start(cmd, options_.traci_port);
    }
#else
    api::Simulation::load(std::vector<std::string>(cmd.begin() + 1, cmd.end()));
#endif
  } catch (const std::exception& e) {
    throw std::runtime_error(std::string("SUMO did not start (") + apiName() + "): " + e.what());
  }
  open_ = true;
  step_length_s_ = api::Simulation::getDeltaT();
  time_s_ = api::Simulation::getTime();
  const std::vector<int> sim_vars{
      libsumo::VAR_DEPARTED_VEHICLES_IDS, libsumo::VAR_ARRIVED_VEHICLES_IDS,
      libsumo::VAR_COLLIDING_VEHICLES_IDS, libsumo::VAR_TELEPORT_STARTING_VEHICLES_IDS,
      libsumo::VAR_LOADED_VEHICLES_NUMBER};
  api::Simulation::subscribe(sim_vars);
  readNetwork();
  placeRsus();
}

void SumoSession::placeRsus() {
  const std::vector<std::string>& main = road_->mainline();
  for (const ClusterInfo& zone : road_->clusters()) {
    const double centre_m = 0.5 * (zone.x_start_m + zone.x_end_m);
    // The mainline edge at the centre (the last one past the road's end).
    const EdgeInfo* at = &road_->edge(main.back());
    for (const std::string& id : main) {
      const EdgeInfo& e = road_->edge(id);
      if (centre_m >= e.x_start_m && centre_m < e.x_end_m) {
        at = &e;
        break;
      }
    }
    const std::string lane = at->id + "_" + std::to_string(std::max(road_->sumoLaneIndex(at->id, 1), 0));
    std::vector<std::pair<double, double>> line;
    for (const auto& p : api::Lane::getShape(lane).value) line.emplace_back(p.x, p.y);
    rsu_poses_.push_back(poseAlong(line, centre_m - at->x_start_m, 0.5 * api::Lane::getWidth(lane) + RSU_SHOULDER_M));
  }
}

SumoSession::~SumoSession() {
  if (!open_) return;
  try {
    api::Simulation::close();
  } catch (...) {
    // Closing a simulation that already ended must not throw from a destructor.
  }
}

void SumoSession::readOwnRoad() {
  road_ = std::make_unique<RoadLayout>(discoverOwnRoad(readNetTopology(options_.own_road_net_file), options_.own_road));
  for (const std::string& id : api::Edge::getIDList()) {
    if (id.empty() || id[0] == ':') continue;  // junction-internal edges
    for (int lane = 0; lane < api::Edge::getLaneNumber(id); ++lane) {
      std::vector<std::pair<double, double>> line;
      for (const auto& p : api::Lane::getShape(id + "_" + std::to_string(lane)).value)
        line.emplace_back(p.x, p.y);
      lane_shapes_.push_back(std::move(line));
    }
  }
  options_.cluster_length_m = road_->clusterLengthM();  // the zones are the road's
  const std::vector<std::string>& main = road_->mainline();
  insertion_edge_ = main.front();
  end_edge_ = main.back();
  for (const ClusterInfo& c : road_->clusters())
    if (!c.exit_from_edge.empty()) pre_exit_edge_[c.index] = c.exit_from_edge;
  const EdgeInfo& first = road_->edge(main.front());
  lane_width_m_ = api::Lane::getWidth(first.id + "_" + std::to_string(first.has_accel_lane ? 1 : 0));
  // A SUMO lane index means another lane on the next edge when the lane count or the
  // acceleration lane changes there (a merge edge, a lane drop).
  for (std::size_t i = 0; i + 1 < main.size(); ++i) {
    const EdgeInfo& e = road_->edge(main[i]);
    const EdgeInfo& next = road_->edge(main[i + 1]);
    if (e.lane_count != next.lane_count || e.has_accel_lane != next.has_accel_lane)
      index_shift_ahead_.insert(e.id);
  }
}

void SumoSession::readNetwork() {
  if (!options_.own_road_net_file.empty()) {
    readOwnRoad();
    return;
  }
  std::vector<EdgeInfo> edges;
  int main_lanes = 0;
  for (const std::string& id : api::Edge::getIDList()) {
    if (id.empty() || id[0] == ':') continue;  // junction-internal edges
    EdgeInfo e;
    e.id = id;
    e.lane_count = api::Edge::getLaneNumber(id);
    const auto shape = api::Lane::getShape(id + "_" + std::to_string(e.lane_count - 1)).value;
    e.x_start_m = shape.front().x;
    e.x_end_m = shape.back().x;
    edges.push_back(e);
    for (int lane = 0; lane < e.lane_count; ++lane) {
      std::vector<std::pair<double, double>> line;
      for (const auto& p : api::Lane::getShape(id + "_" + std::to_string(lane)).value)
        line.emplace_back(p.x, p.y);
      lane_shapes_.push_back(std::move(line));
    }
    if (id.compare(0, 5, "main_") == 0 && id.find("_merge") == std::string::npos)
      main_lanes = std::max(main_lanes, e.lane_count);
  }
  road_ = std::make_unique<RoadLayout>(edges, main_lanes, options_.cluster_length_m);
  double end_x = -INF, start_x = INF;
  for (const EdgeInfo& e : edges) {
    if (e.id.compare(0, 5, "main_") != 0) continue;
    if (e.x_end_m > end_x) {
      end_x = e.x_end_m;
      end_edge_ = e.id;
    }
    if (e.x_start_m < start_x) {
      start_x = e.x_start_m;
      insertion_edge_ = e.id;
    }
  }
  // The mainline edge feeding an off-ramp: the one whose end is where the ramp starts.
  for (const ClusterInfo& c : road_->clusters()) {
    if (c.off_ramp_edge.empty()) continue;
    for (const EdgeInfo& e : edges)
      if (e.id.compare(0, 5, "main_") == 0 && std::abs(e.x_end_m - c.exit_x_m) < 1.0)
        pre_exit_edge_[c.index] = e.id;
  }
  for (const EdgeInfo& e : edges)
    if (e.id.compare(0, 5, "main_") == 0 && !e.has_accel_lane) {
      lane_width_m_ = api::Lane::getWidth(e.id + "_0");
      break;
    }
  // Mainline edges whose successor has another lane count (into or out of a merge edge):
  // a SUMO lane index means another lane there.
  for (const EdgeInfo& e : edges)
    for (const EdgeInfo& f : edges)
      if (e.id.compare(0, 5, "main_") == 0 && f.id.compare(0, 5, "main_") == 0 &&
          std::abs(f.x_start_m - e.x_end_m) < 1.0 && f.lane_count != e.lane_count)
        index_shift_ahead_.insert(e.id);
}

int SumoSession::minExpectedVehicles() const { return api::Simulation::getMinExpectedNumber(); }

std::uint64_t SumoSession::insertionDropped() const {
  // SUMO 1.15 has no count of its own (MSVehicleControl's discarded count is not in the
  // API): every vehicle it built from a flow (loaded) either departed, still waits in the
  // insertion queue (pending), or was dropped after waiting max-depart-delay.
  const std::uint64_t waiting = api::Simulation::getPendingVehicles().size();
  const std::uint64_t accounted = departed_vehicles_ + waiting;
  return loaded_vehicles_ > accounted ? loaded_vehicles_ - accounted : 0;
}

std::string SumoSession::sumoVersion() const { return api::Simulation::getVersion().second; }

const VehicleRecord* SumoSession::find(const std::string& id) const {
  auto it = index_.find(id);
  return it == index_.end() ? nullptr : &vehicles_[it->second];
}

const StepEvents& SumoSession::step() {
  std::vector<std::string> vanished;
  for (VehicleRecord& v : vehicles_) {
    try {
      applyHeldCommand(v);
    } catch (const libsumo::TraCIException& e) {
      // SUMO no longer knows it (removed without a report we read): forget it instead of
      // ending the simulation. Counted; the reason goes to stderr once per vehicle.
      std::fprintf(stderr, "[palcas sumo t=%.1f] %s vanished from SUMO (edge %s, x %.1f): %s\n",
                   time_s_, v.id.c_str(), v.edge.c_str(), v.x_m, e.what());
      vanished.push_back(v.id);
    }
  }
  for (const std::string& id : vanished) removeVehicle(id, nullptr);
  vanished_vehicles_ += vanished.size();
  api::Simulation::step();
  ++step_count_;
  const double before_s = time_s_;
  time_s_ = api::Simulation::getTime();
  // The queue after a step waited the whole step (a vehicle due within it: at most a step).
  insertion_waiting_ = api::Simulation::getPendingVehicles().size();
  insertion_wait_veh_s_ += static_cast<double>(insertion_waiting_) * (time_s_ - before_s);

  events_ = StepEvents{};
  const libsumo::TraCIResults sim = api::Simulation::getSubscriptionResults();
  events_.departed = asStringList(sim, libsumo::VAR_DEPARTED_VEHICLES_IDS);
  events_.arrived = asStringList(sim, libsumo::VAR_ARRIVED_VEHICLES_IDS);
  events_.collided = asStringList(sim, libsumo::VAR_COLLIDING_VEHICLES_IDS);
  events_.teleported = asStringList(sim, libsumo::VAR_TELEPORT_STARTING_VEHICLES_IDS);
  const double loaded = asDouble(sim, libsumo::VAR_LOADED_VEHICLES_NUMBER);
  if (loaded > 0.0) loaded_vehicles_ += static_cast<std::uint64_t>(loaded);
  departed_vehicles_ += events_.departed.size();
  // A vehicle colliding on two lanes at once is listed twice.
  std::sort(events_.collided.begin(), events_.collided.end());
  events_.collided.erase(std::unique(events_.collided.begin(), events_.collided.end()),
                         events_.collided.end());
  if (options_.remove_collided) {
    for (const std::string& id : events_.collided) {
      try {
        // Its subscription first: libsumo would otherwise still serve it at the next
        // step and fail there on a vehicle it no longer knows.
        if (index_.count(id)) api::Vehicle::unsubscribe(id);
        api::Vehicle::remove(id, libsumo::REMOVE_VAPORIZED);
      } catch (const std::exception&) {
        // Already gone (e.g. it arrived in the same step): nothing to remove.
      }
    }
  }
  for (const std::string& id : events_.collided)
    if (const VehicleRecord* v = find(id)) countCollidedUnderGuard(*v, &guard_.counters());
  // Colliding vehicles are removed (by SUMO or above) and may also be listed as arrived,
  // now or in the next step; each leaves once, and only vehicles still tracked arrive.
  for (const std::string& id : events_.collided) removeVehicle(id, &events_.removed);
  for (const std::string& id : events_.teleported) removeVehicle(id, &events_.removed);
  events_.arrived.erase(std::remove_if(events_.arrived.begin(), events_.arrived.end(),
                                       [this](const std::string& id) { return !index_.count(id); }),
                        events_.arrived.end());
  for (const std::string& id : events_.arrived) removeVehicle(id, &events_.removed);
  for (const std::string& id : events_.departed) {
    // A vehicle that collided in the step it departed in was removed above.
    if (options_.remove_collided &&
        std::binary_search(events_.collided.begin(), events_.collided.end(), id))
      continue;
    onDeparted(id);
  }
  readVehicles();
  updateZones();
  return events_;
}

}  // namespace palcas::sim
