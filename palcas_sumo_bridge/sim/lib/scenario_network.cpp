// Network half of the scenario: netconvert on the plain XML sources (hand-written or generated
// from a RoadSpec), and reading the generated .net.xml back (edges with their x range, lane
// connections).
#include <array>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "palcas_sim/scenario.h"
#include "scenario_xml.h"

namespace fs = std::filesystem;

namespace palcas::sim {
namespace {

/// Single-quoted for /bin/sh: ' becomes '\''.
std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += (c == '\'') ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

/// Runs a shell command; returns its exit status and combined stdout + stderr.
std::pair<int, std::string> runCommand(const std::string& command) {
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot start: " + command);
  std::string output;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) output.append(buffer.data(), n);
  const int status = pclose(pipe);
  return {status, output};
}

/// x of the first or last point of a SUMO shape "x,y x,y ...".
double shapeX(const std::string& shape, bool last, const std::string& what) {
  std::istringstream in(shape);
  std::string point, chosen;
  while (in >> point) {
    if (chosen.empty() || last) chosen = point;
    if (!last) break;
  }
  const std::size_t comma = chosen.find(',');
  if (comma == std::string::npos) throw std::runtime_error("malformed shape of " + what);
  try {
    return std::stod(chosen.substr(0, comma));
  } catch (const std::exception&) {
    throw std::runtime_error("malformed shape of " + what + ": '" + shape + "'");
  }
}

std::string readNetText(const std::string& net_file) {
  std::string text = xml::stripComments(xml::readFile(net_file));
  if (xml::findTags(text, "net").empty())
    throw std::runtime_error("'" + net_file + "' is not a SUMO network (no <net> element)");
  return text;
}

int toInt(const std::string& s, const std::string& what) {
  try {
    std::size_t used = 0;
    const int v = std::stoi(s, &used);
    if (used == s.size()) return v;
  } catch (const std::exception&) {
  }
  throw std::runtime_error("not an integer: " + what + " = '" + s + "'");
}

}  // namespace

std::string generateNetwork(const std::string& scenario_dir, const std::string& out_dir,
                            const std::string& netconvert_binary) {
  const fs::path dir(scenario_dir);
  const std::array<std::string, 3> sources{"network.nod.xml", "network.edg.xml",
                                           "network.con.xml"};
  for (const std::string& name : sources)
    if (!fs::is_regular_file(dir / name))
      throw std::invalid_argument("scenario_dir '" + scenario_dir + "' has no " + name);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error("cannot create output folder '" + out_dir + "': " + ec.message());
  const std::string net_file = (fs::path(out_dir) / "network.net.xml").string();
  fs::remove(net_file, ec);  // never mistake a stale network for a fresh one
  // --offset.disable-normalization keeps x as written (x = mainline position);
  // --no-turnarounds: a highway has no U-turns. Junction geometry is fixed by the custom node
  // shapes in the sources (config/scenarios/README.md).
  const std::string command = shellQuote(netconvert_binary) +
                              " --node-files " + shellQuote((dir / sources[0]).string()) +
                              " --edge-files " + shellQuote((dir / sources[1]).string()) +
                              " --connection-files " + shellQuote((dir / sources[2]).string()) +
                              " --output-file " + shellQuote(net_file) +
                              " --no-turnarounds --offset.disable-normalization";
  const auto [status, output] = runCommand(command);
  if (status != 0 || !fs::is_regular_file(net_file))
    throw std::runtime_error("netconvert failed (status " + std::to_string(status) +
                             ") on scenario '" + scenario_dir + "':\n" + output);
  return net_file;
}

std::string prepareOwnNetwork(const ScenarioConfig& config, const std::string& out_dir) {
  const fs::path source = fs::path(config.scenario_dir) / config.network_file;
  if (!fs::is_regular_file(source))
    throw std::invalid_argument("network_file '" + config.network_file + "': no such file in scenario_dir '" +
                                config.scenario_dir + "'");
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) throw std::runtime_error("cannot create output folder '" + out_dir + "': " + ec.message());
  const std::string net_file = (fs::path(out_dir) / "network.net.xml").string();
  fs::remove(net_file, ec);  // never mistake a stale network for a fresh one
  const std::string name = source.filename().string();
  const auto endsWith = [&name](const std::string& suffix) {
    return name.size() > suffix.size() && name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
  };
  if (endsWith(".net.xml")) {
    fs::copy_file(source, net_file, fs::copy_options::overwrite_existing, ec);
    if (ec) throw std::runtime_error("cannot copy '" + source.string() + "' to '" + net_file + "': " + ec.message());
  } else if (endsWith(".netccfg")) {
    // netconvert reads the paths in a configuration relative to the configuration itself.
    const auto [status, output] = runCommand(shellQuote(config.netconvert_binary) + " -c " +
                                             shellQuote(fs::absolute(source).string()) +
                                             " --output-file " + shellQuote(net_file));
    if (status != 0 || !fs::is_regular_file(net_file))
      throw std::runtime_error("netconvert failed (status " + std::to_string(status) + ") on network_file '" +
                               source.string() + "':\n" + output);
  } else {
    throw std::invalid_argument("network_file '" + config.network_file +
                                "' is neither a SUMO network (*.net.xml) nor a netconvert configuration (*.netccfg)");
  }
  readNetText(net_file);  // a network at all
  return net_file;
}

std::string generateNetwork(const RoadSpec& road, const std::string& out_dir,
                            const std::string& netconvert_binary) {
  const std::string sources = (fs::path(out_dir) / "sources").string();
  writeNetworkSources(road, sources);
  return generateNetwork(sources, out_dir, netconvert_binary);
}

std::vector<EdgeInfo> readNetEdges(const std::string& net_file) {
  const std::string text = readNetText(net_file);
  const std::vector<xml::Tag> edges = xml::findTags(text, "edge");
  const std::vector<xml::Tag> lanes = xml::findTags(text, "lane");
  std::vector<EdgeInfo> out;
  std::size_t lane_at = 0;
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const std::size_t end = e + 1 < edges.size() ? edges[e + 1].offset : text.size();
    const bool internal = xml::attribute(edges[e], "function") == "internal";
    EdgeInfo info;
    info.id = xml::attribute(edges[e], "id");
    for (; lane_at < lanes.size() && lanes[lane_at].offset < end; ++lane_at) {
      if (internal || lanes[lane_at].offset < edges[e].offset) continue;
      const xml::Tag& lane = lanes[lane_at];
      const std::string what = "lane '" + xml::attribute(lane, "id") + "' in " + net_file;
      if (toInt(xml::attribute(lane, "index"), what) == 0) {
        info.x_start_m = shapeX(xml::attribute(lane, "shape"), false, what);
        info.x_end_m = shapeX(xml::attribute(lane, "shape"), true, what);
      }
      ++info.lane_count;
    }
    if (internal) continue;
    if (info.id.empty() || info.lane_count == 0)
      throw std::runtime_error("edge without id or lanes in '" + net_file + "'");
    out.push_back(info);
  }
  return out;
}

std::vector<LaneConnection> readNetConnections(const std::string& net_file) {
  const std::string text = readNetText(net_file);
  std::vector<LaneConnection> out;
  for (const xml::Tag& tag : xml::findTags(text, "connection")) {
    const std::string from = xml::attribute(tag, "from");
    if (from.empty() || from[0] == ':') continue;  // internal (junction) lanes
    const std::string what = "connection from '" + from + "' in " + net_file;
    out.push_back({from, toInt(xml::attribute(tag, "fromLane"), what), xml::attribute(tag, "to"),
                   toInt(xml::attribute(tag, "toLane"), what)});
  }
  return out;
}

}  // namespace palcas::sim
