"""./palcas train: the training record, resume, the launch loop that survives SUMO's own
crashes, progress and learning curves.

check(argv) reads and checks the options (OptionError: exit 2, nothing made or started), a
resumed training's record included; main(argv) then trains in the built, sourced workspace.

Demand: --demand sets the mainline demand [veh/h per lane] and --ramp-demand the on-ramp
demand [veh/h per ramp] of every episode (the launch's demand / ramp_demand; absent = the
scenario's own). --demand-range and --pr-range draw each episode's demand / PR uniformly
from [MIN, MAX]: episode k's draw comes from its own generator seeded with (seed, k), so it
is the same whatever ran before it (a resumed or extended training draws the episodes it
adds as a fresh one would). The bridge writes one generated scenario per launch (demand and
PR are in its routes file), so with a range every episode is its own roslaunch (episodes:=1,
first_episode:=k, its demand and PR); the RSUs and the server resume from their checkpoints
(weights, optimiser, replay, epsilon, RNG: the same path as a crashed episode takes), which
costs a few seconds of start-up per episode and changes nothing else. Without a range the
episodes share one launch, as before. The ranges and every episode's draw are in train.json
(episode_draws), and the bridge writes each episode's demand and PR into episodes.csv.

Several simulations (--simulations K, K > 1) train one federation at once: one federation
server (launch/federation.launch, rounds on wall time) and K simulations (launch/
simulation.launch), each its own roslaunch against the server's ROS master, in the namespace
sim<k> with its own clock, its RSUs inside its bridge (ids rsu_<z> in simulation 0,
rsu_<z>_s<k> in the others) and its own traffic: simulation k's episode e runs seed
+ 1000 k + e (SIMULATION_SEED_STRIDE). --episodes counts per simulation. Each simulation
writes into <out>/sim<k>/ (episodes.csv, metrics, console.log); <out>/episodes.csv is their
union with a leading `simulation` column, rewritten when the simulations end; the
checkpoints (the server's global model: the shipped policy) are shared in <out>/checkpoints/.
A simulation whose SUMO crashed loses that episode and goes on with its next one (as one
simulation does); a node lost for good stops the others and fails the command (exit 1);
--resume continues each simulation from its own episodes.csv.

Exit status: 0 done; 1 a node died for good or nothing was trained; 2 a bad option;
130 / 143 interrupted (SIGINT / SIGTERM: every process stopped and checkpointed)."""
import datetime
import json
import os
import random
import re
import socket
import subprocess
import sys
import time

from palcas_cli import Console, launch, options
from palcas_cli.options import OptionError
import palcas_arms
import policy_folder
import repo_paths

# What an option means when a new training leaves it out.
DEFAULTS = {"arm": "palcas", "episodes": 5, "duration": 3600.0, "pr": 60.0, "seed": 1,
            "scenario": "paper", "explore_fraction": 0.5, "demand": None, "ramp_demand": None,
            "demand_range": None, "pr_range": None}
# Options a resumed training takes from its record (record key per option).
RESUMED = {"arm": "arm", "scenario": "scenario", "pr": "pr", "seed": "seed", "duration": "duration_s"}
# The same for the demand options; a record without them (older trainings) had none (None).
RESUMED_DEMAND = {"demand": "demand_vphpl", "ramp_demand": "ramp_demand_vph",
                  "demand_range": "demand_range", "pr_range": "pr_range"}
ALL_GIVEN = ("arm", "episodes", "duration", "pr", "seed", "scenario", "explore_fraction", "demand",
             "ramp_demand", "demand_range", "pr_range")
# --simulations: at most this many at once (each is a SUMO, a bridge and its RSUs).
MAX_SIMULATIONS = 64
# Simulation k's traffic seed is seed + k * this (episode e: + e), so its episodes never
# repeat another simulation's traffic while a simulation runs fewer episodes than this.
SIMULATION_SEED_STRIDE = 1000


VALUES = {"--explore-fraction": "explore_fraction", "--episodes": "episodes", "--duration": "duration",
          "--pr": "pr", "--pr-range": "pr_range", "--demand": "demand", "--demand-range": "demand_range",
          "--ramp-demand": "ramp_demand", "--seed": "seed", "--arm": "arm", "--out": "out", "--scenario": "scenario",
          "--learning": "learning", "--rsu-params": "rsu_params", "--bridge-params": "bridge_params",
          "--v2x": "v2x_params", "--simulations": "simulations"}
FLAGS = {"--paper-printed": ("paper_printed", True), "--resume": ("resume", True),
         "--in-process": ("inprocess", True), "--rsu-nodes": ("rsu_nodes", True),
         "--record-decisions": ("record_decisions", True),
         "--plan": ("plan", True)}
# A new training's defaults as typed (DEFAULTS's values, 3600.0 as 3600).
TYPED_DEFAULTS = {k: v if isinstance(v, str) else "%g" % v for k, v in DEFAULTS.items()
                  if k in ("episodes", "duration", "pr", "seed", "explore_fraction", "arm", "scenario")}
D = options.with_default
# --help: each option's METAVAR (None for a flag) and what it does, with its default.
HELPS = {
    "--arm": ("A", D("a learning arm of config/arms.json", TYPED_DEFAULTS["arm"])),
    "--episodes": ("N", D("episodes (--resume: may raise the count)", TYPED_DEFAULTS["episodes"])),
    "--duration": ("SECONDS", D("simulated time per episode", TYPED_DEFAULTS["duration"])),
    "--pr": ("PERCENT", D("CAV penetration rate in [0, 100]", TYPED_DEFAULTS["pr"])),
    "--pr-range": ("MIN,MAX", D("each episode draws its PR uniformly from [MIN, MAX] (instead of --pr); the "
                                "draws follow from --seed and are recorded in train.json", "none")),
    "--demand": ("VPHPL", D("mainline demand [veh/h per lane] of every episode, in [0, %d]" % options.MAX_DEMAND,
                            "the scenario's")),
    "--demand-range": ("MIN,MAX", D("each episode draws its mainline demand uniformly from [MIN, MAX] "
                                    "(instead of --demand)", "none")),
    "--ramp-demand": ("VPH", D("on-ramp demand [veh/h per ramp] of every episode", "the scenario's")),
    "--seed": ("N", D("random seed of the first episode (episode k: seed + k)", TYPED_DEFAULTS["seed"])),
    "--scenario": ("NAME", D("road under config/scenarios, or an absolute path to a folder with scenario.yaml",
                             TYPED_DEFAULTS["scenario"])),
    "--explore-fraction": ("F", D("share of the training over which exploration decays, in (0, 1]",
                                  TYPED_DEFAULTS["explore_fraction"])),
    "--out": ("DIR", D("training folder", "results/train-<arm>-<time>")),
    "--paper-printed": (None, D("every constant as the paper prints it", "off")),
    "--learning": ("FILE", D("a \"learning:\" YAML override for RSUs and server alike "
                             "(e.g. config/training/short_learning.yaml)", "none")),
    "--rsu-params": ("FILE", D("an RSU parameter override (e.g. config/training/short_rsu.yaml)", "none")),
    "--bridge-params": ("FILE", D("a bridge parameter override (e.g. config/training/unclipped_advisories.yaml)",
                                  "none")),
    "--v2x": ("FILE", D("train with the V2X channel on (as for run)", "off")),
    "--simulations": ("K", D("simulations training one federation at once, at most %d: each with its own SUMO, "
                             "bridge, RSUs (in-process) and traffic (simulation k: seed + %d k), all submitting "
                             "to one federation server; --episodes counts per simulation; <out>/sim<k>/ holds "
                             "each one's episodes (--resume: the training's own)" % (MAX_SIMULATIONS, SIMULATION_SEED_STRIDE),
                             "1")),
    "--in-process": (None, D("run the RSUs inside the bridge process (the RSU node's own decision code, a call "
                             "per step instead of ROS topics; federation still over the server's services)",
                             "on")),
    "--rsu-nodes": (None, D("run one RSU node per zone instead, their advice over ROS topics (the deployment "
                            "path: the same decisions, slower when the learners leave SUMO a core)", "off")),
    "--record-decisions": (None, D("record trajectories.csv and decisions.csv of every episode (every 10 steps), "
                                   "as ./palcas run does", "off")),
    "--plan": (None, D("with --simulations K: write the training record and <out>/slurm_train.sh (one Slurm job: "
                       "the server on the batch host, the K simulations as its tasks on any hosts, over one ROS "
                       "master) and run nothing", "off")),
    "--resume": (None, D("continue the training in --out from its checkpoints; road, arm, PR, seed, duration "
                         "and overrides come from its train.json (a contradicting option is refused)", "off")),
}
DESCRIPTION = ("Train an arm: progress on the terminal, learning curves, resumable (--resume). Exit status: "
               "0 done,\n1 a node died for good or nothing was trained, 2 a bad option, 130 / 143 "
               "interrupted.")
console = Console()


def log(text):
    console.log(text)


def number_text(value):
    """A number as a user wrote it: 60, 0.5, 1200."""
    return "%g" % value if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)


def same_value(a, b):
    if isinstance(a, (list, tuple)) or isinstance(b, (list, tuple)):
        return (isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)) and len(a) == len(b)
                and all(same_value(x, y) for x, y in zip(a, b)))
    if a is None or b is None:
        return a is None and b is None
    try:
        return float(a) == float(b)
    except (TypeError, ValueError):
        return str(a) == str(b)


def value_text(value):
    """A recorded option as the user would write it: 60, 1000,2000, or (the scenario's)."""
    if value is None:
        return "(the scenario's)"
    if isinstance(value, (list, tuple)):
        return ",".join(number_text(v) for v in value)
    return number_text(value)


def episode_draw(opts, episode):
    """Demand [veh/h per lane] (None = the scenario's) and PR [%] of episode k: drawn from
    the ranges with a generator of its own, seeded by the training seed and k."""
    rng = random.Random("palcas-train:%d:%d" % (int(opts["seed"]), episode))
    demand, pr = opts.get("demand"), opts["pr"]
    if opts.get("demand_range"):
        lo, hi = opts["demand_range"]
        demand = round(rng.uniform(lo, hi), 1)
    if opts.get("pr_range"):
        lo, hi = opts["pr_range"]
        pr = round(rng.uniform(lo, hi), 2)
    return {"episode": episode, "seed": int(opts["seed"]) + episode,
            "demand_vphpl": as_number(demand) if demand is not None else None, "pr": as_number(pr)}


def sampled(opts):
    return bool(opts.get("demand_range") or opts.get("pr_range"))


def read_record(out):
    path = str(policy_folder.train_record_path(out))
    try:
        with open(path) as f:
            record = json.load(f)
    except (OSError, ValueError) as e:
        raise OptionError("--resume: '%s' holds no readable training record (%s)" % (out, e))
    for key in ("arm", "scenario", "pr", "seed", "episodes", "duration_s", "explore_fraction"):
        if key not in record:
            raise OptionError("--resume: %s has no field '%s' (not a ./palcas train record?)" % (path, key))
    return record


def settle_options(given, out, resume):
    """The training's options: what was given, defaults for the rest; a resumed training
    takes road, arm, PR, seed, duration, schedule and overrides from its record and refuses
    a given option that contradicts it (--episodes may grow). Raises OptionError."""
    opts = dict(DEFAULTS)
    opts.update({k: v for k, v in given.items() if v is not None})
    record_path = str(policy_folder.train_record_path(out)) if out else ""
    if not resume:
        if record_path and os.path.isfile(record_path):
            raise OptionError("--out '%s' already holds a training: use --resume, or another --out" % out)
        return opts, None
    if not record_path or not os.path.isfile(record_path):
        raise OptionError("--resume: '%s' holds no training to resume (--out DIR of an earlier ./palcas train)"
                          % (out or "(no --out)"))
    record = read_record(out)
    for option, key in RESUMED.items():
        recorded = record[key]
        if given.get(option) is not None and not same_value(given[option], recorded):
            flag = "--" + option.replace("_", "-")
            raise OptionError("--resume: '%s' trained with %s %s, not %s %s (leave %s out to continue it)"
                              % (out, flag, number_text(recorded), flag, number_text(given[option]), flag))
        opts[option] = recorded
    for option, key in RESUMED_DEMAND.items():
        recorded = record.get(key)
        if given.get(option) is not None and not same_value(given[option], recorded):
            flag = "--" + option.replace("_", "-")
            raise OptionError("--resume: '%s' trained with %s %s, not %s %s (leave %s out to continue it)"
                              % (out, flag, value_text(recorded), flag, value_text(given[option]), flag))
        opts[option] = recorded
    if given.get("episodes") is None:
        opts["episodes"] = record["episodes"]
    if given.get("explore_fraction") is not None:
        raise OptionError("--resume: the exploration schedule is the training's own (%s/learning_schedule.yaml); "
                          "leave --explore-fraction out" % out)
    opts["explore_fraction"] = record["explore_fraction"]
    for key in ("learning", "rsu_params", "bridge_params", "v2x_params"):
        opts[key] = repo_paths.usable(record.get(key, ""))  # recorded relative to the repository
    opts["paper_printed"] = bool(record.get("paper_printed", False))
    return opts, record


def as_number(value):
    """60.0 -> 60 (as the user wrote it); other values unchanged."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


def write_record(out, opts, git_commit, command_line="", resume=False):
    """train.json, written whole (a path with a quote or a backslash stays valid JSON). It
    keeps the command that started the training (`command_line`) and lists every later
    `--resume` in `resumed_with`, so a shipped policy names how it was trained, not only how
    it was last continued. Its file paths are repository-relative where they lie in the
    repository (tools/repo_paths.py): a committed record names no folder of this machine."""
    earlier = {}
    if resume:
        try:
            with open(policy_folder.train_record_path(out)) as f:
                earlier = json.load(f)
        except (OSError, ValueError):
            earlier = {}
    record = {"arm": opts["arm"], "scenario": opts["scenario"], "pr": as_number(opts["pr"]), "seed": opts["seed"],
              "episodes": opts["episodes"], "duration_s": as_number(opts["duration"]),
              "learning": repo_paths.recorded(opts.get("learning")) or "",
              "rsu_params": repo_paths.recorded(opts.get("rsu_params")) or "",
              "bridge_params": repo_paths.recorded(opts.get("bridge_params")) or "",
              "v2x_params": repo_paths.recorded(opts.get("v2x_params")) or "",
              "paper_printed": bool(opts.get("paper_printed")), "explore_fraction": opts["explore_fraction"],
              "demand_vphpl": as_number(opts["demand"]) if opts.get("demand") is not None else None,
              "ramp_demand_vph": as_number(opts["ramp_demand"]) if opts.get("ramp_demand") is not None else None,
              "demand_range": opts.get("demand_range"), "pr_range": opts.get("pr_range"),
              "git_commit": git_commit,
              "command_line": earlier.get("command_line", "") if resume else command_line,
              "resumed_with": earlier.get("resumed_with", []) + ([command_line] if resume else [])}
    if sampled(opts):
        record["episode_draws"] = [episode_draw(opts, k) for k in range(int(opts["episodes"]))]
    if simulation_count(opts) > 1:  # a one-simulation record stays as it always was
        record["simulations"] = simulation_count(opts)
        record["simulation_seed_stride"] = SIMULATION_SEED_STRIDE
    tmp = os.path.join(out, ".train.json.tmp")
    with open(tmp, "w") as f:
        json.dump(record, f)
        f.write("\n")
    os.replace(tmp, str(policy_folder.train_record_path(out)))
    return record


def simulation_count(opts):
    return int(opts.get("simulations") or 1)


def simulation_dir(out, k):
    """Simulation k's own folder (--simulations K > 1): its bridge's out_dir."""
    return os.path.join(out, "sim%d" % k)


def simulation_seed(seed, k):
    """Simulation k's traffic seed (its episode e runs this + e)."""
    return int(seed) + SIMULATION_SEED_STRIDE * k


def simulation_rsu_ids(arm, clusters, k):
    """Simulation k's RSU ids, unique across the federation (launch/simulation.launch names
    them so): rsu_<z> in simulation 0, rsu_<z>_s<k> in the others."""
    return [rsu if k == 0 else "%s_s%d" % (rsu, k) for rsu in palcas_arms.rsu_ids(arm, clusters)]


def training_episodes_done(out, opts):
    """Episodes every simulation has finished (one simulation: rows of <out>/episodes.csv)."""
    if simulation_count(opts) == 1:
        return episodes_done(out)
    return min(episodes_done(simulation_dir(out, k)) for k in range(simulation_count(opts)))


def merge_simulation_episodes(out, count):
    """<out>/episodes.csv of a training of several simulations: every simulation's rows
    (<out>/sim<k>/episodes.csv) with a leading `simulation` column, by episode, then simulation."""
    header, rows = None, []
    for k in range(count):
        try:
            with open(os.path.join(simulation_dir(out, k), "episodes.csv")) as f:
                lines = f.read().splitlines()
        except OSError:
            continue
        if not lines:
            continue
        header = header or lines[0]
        rows += [(int(line.split(",", 1)[0]), k, line) for line in lines[1:] if line.strip()]
    if header is None:
        return
    tmp = os.path.join(out, ".episodes.csv.tmp")
    with open(tmp, "w") as f:
        f.write("simulation," + header + "\n")
        f.writelines("%d,%s\n" % (k, line) for _, k, line in sorted(rows))
    os.replace(tmp, os.path.join(out, "episodes.csv"))


def episodes_done(out):
    """Rows of episodes.csv (the bridge writes one per finished episode)."""
    try:
        with open(os.path.join(out, "episodes.csv")) as f:
            return max(0, sum(1 for _ in f) - 1)
    except OSError:
        return 0


def scenario_clusters(scenario):
    """road/clusters of the road's scenario.yaml (the launch files read the same line)."""
    text = launch.read_text(options.scenario_yaml(scenario))
    m = re.search(r"^\s*clusters:\s*(\d+)", text, re.M)
    if not m:
        raise OptionError("--scenario %s: its scenario.yaml has no road/clusters" % scenario)
    return int(m.group(1))


def keep_episode_metrics(out, episode):
    """A launch of episode 0 alone writes only <out>/metrics.json (the bridge keeps
    episode_<k>/ for launches of several episodes or later ones): copied to episode_0/, as
    every other episode of a training has its own."""
    src, dest = os.path.join(out, "metrics.json"), os.path.join(out, "episode_%d" % episode, "metrics.json")
    try:
        with open(src) as f:
            text = f.read()
        if os.path.exists(dest) or json.loads(text).get("episode") != episode:
            return
    except (OSError, ValueError):
        return
    os.makedirs(os.path.dirname(dest), exist_ok=True)
    with open(dest, "w") as f:
        f.write(text)


def system_launch_args(opts, record, command_line, draw, seed, clusters, count, first, resume_nodes, out, run_dir,
                       auth_key):
    """system.launch's arguments for `count` training episodes from `first` of traffic `seed`
    (and the episode's draw), the bridge writing into run_dir, the checkpoints in out's."""
    return [
        "arm:=%s" % opts["arm"], "mode:=train", "pr:=%s" % number_text(draw["pr"]), "seed:=%d" % seed,
        "demand:=%s" % ("scenario" if draw["demand_vphpl"] is None else number_text(draw["demand_vphpl"])),
        "ramp_demand:=%s" % ("scenario" if opts.get("ramp_demand") is None else number_text(opts["ramp_demand"])),
        "scenario:=%s" % opts["scenario"], "clusters:=%d" % clusters, "episodes:=%d" % count,
        "first_episode:=%d" % first, "duration:=%s" % number_text(opts["duration"]),
        "checkpoint_dir:=%s" % policy_folder.checkpoints(out), "resume:=%s" % resume_nodes,
        "out_dir:=%s" % run_dir, "learning_params:=%s" % (opts.get("learning") or "none"),
        "rsu_params:=%s" % (opts.get("rsu_params") or "none"),
        "bridge_params:=%s" % (opts.get("bridge_params") or "none"),
        "v2x_params:=%s" % (opts.get("v2x_params") or "none"),
        "paper_printed:=%s" % str(bool(opts.get("paper_printed"))).lower(), "auth_key_file:=%s" % auth_key,
        "inprocess:=%s" % str(bool(opts.get("inprocess"))).lower(),
        "trajectory_period_steps:=%d" % (10 if opts.get("record_decisions") else 0),
        "git_commit:=%s" % record["git_commit"], "command_line:=%s" % command_line]


def federation_launch_args(opts, out, clusters, auth_key):
    """federation.launch's arguments: one server for every simulation's RSUs."""
    rsus = [rsu for k in range(simulation_count(opts)) for rsu in simulation_rsu_ids(opts["arm"], clusters, k)]
    return ["palcas_launch", "federation.launch", "expected_rsus:=[%s]" % ", ".join(rsus),
            "seed:=%d" % int(opts["seed"]), "learning_params:=%s" % (opts.get("learning") or "none"),
            "checkpoint_dir:=%s" % policy_folder.checkpoints(out), "resume:=true", "auth_key_file:=%s" % auth_key]


def master_up(port, wait_s=30.0):
    """Waits (at most wait_s) until the ROS master on this host's PORT takes connections."""
    end = time.time() + wait_s
    while time.time() < end and not launch.interrupted():
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return
        except OSError:
            time.sleep(launch.POLL_S)


def run_simulations(out, opts, record, resume, command_line):
    """K simulations training one federation (--simulations K > 1): the server's launch
    (it starts the ROS master), then one launch per simulation with episodes left, against
    that master. A simulation whose SUMO crashed loses that episode only and goes on with its
    next one in a new launch (as a single simulation does), the others running on; an RSU
    or server lost for good, a simulation out of relaunches or a server launch that ended
    stops every simulation and fails (exit 1, naming it). The server stops last. Returns the
    exit status; raises launch.Interrupted (every node stopped and checkpointed)."""
    count, episodes, seed = simulation_count(opts), int(opts["episodes"]), int(opts["seed"])
    clusters = scenario_clusters(opts["scenario"])
    auth_key = launch.message_key(out)
    nxt = [episodes_done(simulation_dir(out, k)) for k in range(count)]
    log("training %s: %d simulations (seeds %s), episodes %s..%d each x %ss, pr=%s%% demand=%s -> %s"
        % (opts["arm"], count, ", ".join(str(simulation_seed(seed, k)) for k in range(count)),
           "/".join(str(d + 1) for d in nxt), episodes, number_text(opts["duration"]), value_text(opts["pr"]),
           value_text(opts["demand"]) + (" veh/h/lane" if opts["demand"] is not None else ""), out))
    log_dir = os.path.join(out, "ros_log")
    server = launch.Launch(federation_launch_args(opts, out, clusters, auth_key), os.path.join(out, "console.log"),
                           log_dir, append=True).start()
    sims, rows_before, asked, launches, monitor, lost = {}, {}, {}, [0] * count, None, []
    budget = episodes + 3 + episodes // 4  # launches per simulation, as a single one has

    def start(k):
        os.makedirs(simulation_dir(out, k), exist_ok=True)
        rows_before[k], asked[k] = episodes_done(simulation_dir(out, k)), episodes - nxt[k]
        launches[k] += 1
        args = system_launch_args(opts, record, command_line, episode_draw(opts, nxt[k]), simulation_seed(seed, k),
                                  clusters, episodes - nxt[k], nxt[k], "true", out, simulation_dir(out, k), auth_key)
        sims[k] = launch.Launch(["palcas_launch", "simulation.launch", "simulation:=%d" % k] + args,
                                os.path.join(simulation_dir(out, k), "console.log"), log_dir, append=True,
                                master_port=server.port).start()

    def ended(k):
        """Simulation k's launch ended: go on with its next episode, or say why it cannot."""
        sims.pop(k).wait()  # at once; raises Interrupted if the command was stopped
        console_log = os.path.join(simulation_dir(out, k), "console.log")
        text = launch.read_text(console_log)
        bridge = "sim%d/palcas_sumo_bridge" % k
        deaths = [d for d in launch.node_deaths(text, crashed_by=bridge) if not d.startswith(bridge)]
        deaths += ["%s (in process, refused at start)" % r for r in launch.inprocess_refusals(text)]
        if deaths:
            lost.append("simulation %d lost %s; last error: %s" % (k, ", ".join(deaths), launch.last_fatal(text)))
            return
        finished = episodes_done(simulation_dir(out, k)) - rows_before[k]
        nxt[k] += finished
        if finished < asked[k]:
            # Its SUMO crashed (or its bridge failed): that episode only is lost.
            why = launch.crash_reason(text) or "ended early, no reason in the log"
            log("simulation %d: episode %d ended early (%s); it goes on with its next episode" % (k, nxt[k] + 1, why))
            with open(os.path.join(out, "aborted_episodes.txt"), "a") as f:
                f.write("simulation %d episode %d (seed %d): %s\n"
                        % (k, nxt[k], simulation_seed(seed, k) + nxt[k], why))
            os.replace(console_log, os.path.join(simulation_dir(out, k), "console-aborted-%d.log" % nxt[k]))
            nxt[k] += 1
        if nxt[k] < episodes:
            if launches[k] >= budget:
                lost.append("simulation %d: %d launches and still %d episodes to go" % (k, launches[k], episodes - nxt[k]))
            else:
                start(k)

    try:
        for k in range(count):
            if nxt[k] < episodes:
                start(k)
        # The progress line follows the first simulation (the others run the same episodes on
        # other traffic); its topics are in its namespace.
        master_up(server.port)  # else the monitor's first line is rospy's complaint
        watched = min(sims) if sims else 0
        ns = "/sim%d" % watched
        rsus = simulation_rsu_ids(opts["arm"], clusters, watched)
        monitor = None if not sims else subprocess.Popen(
            ["setpriv", "--pdeathsig", "TERM", sys.executable,
             os.path.join(str(options.ROOT), "tools", "train_monitor.py"), "--rsus"] + rsus
            + ["--episodes", str(episodes - nxt[watched]), "--first-episode", str(nxt[watched]),
               "--total-episodes", str(episodes), "--duration", number_text(opts["duration"]), "--period", "15",
               "--episodes-csv", os.path.join(simulation_dir(out, watched), "episodes.csv"),
               "/episode_metrics:=%s/episode_metrics" % ns]
            + ["/%s/rsu_status:=%s/%s/rsu_status" % (rsu, ns, rsu) for rsu in rsus],
            stderr=subprocess.DEVNULL, env=launch.ros_env(server.port, log_dir))
        while sims and not lost:
            if launch.interrupted():
                raise launch.Interrupted(launch.interrupted())
            for k in [k for k, sim in sims.items() if not sim.running()]:
                ended(k)
            if not server.running():
                lost.append("the federation server's launch ended before the simulations")
            time.sleep(launch.POLL_S)
    finally:
        if monitor:
            monitor.terminate()
            monitor.wait()
        # Stopped or failed: every simulation checkpoints and ends before the master goes.
        for sim in sims.values():
            sim.interrupt()
        deadline = time.time() + 120
        for sim in sims.values():
            sim.kill_after(deadline)
        server.interrupt()
        server.kill_after(time.time() + 60)
        merge_simulation_episodes(out, count)
    server_text = launch.read_text(os.path.join(out, "console.log"))
    lost += ["federation server lost: %s" % d for d in launch.node_deaths(server_text)]
    if lost:
        console.error("training of %d simulations failed: %s" % (count, "; ".join(lost)))
        with open(os.path.join(out, "aborted_episodes.txt"), "a") as f:
            f.write("".join(line + "\n" for line in lost))
        return 1
    return 0


SLURM_SCRIPT = "slurm_train.sh"


def write_slurm_script(out, opts, record, command_line):
    """<out>/slurm_train.sh: the training of K simulations as one Slurm job. The batch
    script's host runs the ROS master and the federation server (federation.launch); `srun`
    starts the K simulations as the job's tasks (simulation.launch, task k = simulation k),
    on whichever hosts Slurm gives, against that master: ROS_MASTER_URI names the batch
    host, ROS_IP each host's own address (ROS 1 connects nodes peer to peer, so every host
    must reach every other). Every host needs this repository built at the same path and
    <out> on a shared file system. When the tasks end the server is stopped (SIGINT: it
    checkpoints) and <out>/episodes.csv is merged, as ./palcas train does."""
    import shlex
    count, seed = simulation_count(opts), int(opts["seed"])
    clusters = scenario_clusters(opts["scenario"])
    auth_key = launch.message_key(out)
    root = str(options.ROOT)
    q = shlex.quote
    server = " ".join(q(a) for a in federation_launch_args(opts, out, clusters, auth_key))
    cases = []
    for k in range(count):
        args = system_launch_args(opts, record, command_line, episode_draw(opts, 0), simulation_seed(seed, k), clusters,
                                  int(opts["episodes"]), 0, "true", out, simulation_dir(out, k), auth_key)
        cases.append("    %d) mkdir -p %s; exec roslaunch --wait palcas_launch simulation.launch simulation:=%d %s \\\n"
                     "         >>%s 2>&1 ;;\n"
                     % (k, q(simulation_dir(out, k)), k, " ".join(q(a) for a in args),
                        q(os.path.join(simulation_dir(out, k), "console.log"))))
    text = (
        "#!/bin/bash\n"
        "# ./palcas train with %d simulations as one Slurm job (written by ./palcas train --plan):\n"
        "#   sbatch %s\n"
        "# The batch host runs the ROS master and the federation server; the %d tasks are the\n"
        "# simulations (task k = simulation k, traffic seed %d + %d k), on any hosts, each with its\n"
        "# RSUs in its bridge, all submitting to that one server. Every host needs this repository\n"
        "# built at %s, ROS and SUMO installed, this folder on a shared file system, and\n"
        "# network reach to every other host (ROS 1 links nodes peer to peer).\n"
        "# Afterwards: ./palcas run --policy %s; an interrupted job continues on one machine\n"
        "# with ./palcas train --resume --out %s.\n"
        "#SBATCH --job-name=palcas-train\n#SBATCH --ntasks=%d\n#SBATCH --cpus-per-task=2\n"
        "#SBATCH --time=72:00:00\n#SBATCH --output=%s/slurm-%%j.log\n"
        "set -uo pipefail\n"
        "source %s/devel/setup.bash\n"
        "export SUMO_HOME=\"${SUMO_HOME:-/usr/share/sumo}\" ROS_LOG_DIR=%s\n"
        "unset ROS_HOSTNAME  # ROS_IP below names each host\n"
        "# A master port of this job's own: several jobs may share a host.\n"
        "port=$((20000 + ${SLURM_JOB_ID:-0} %% 20000))\n"
        "master_ip=$(hostname -I | awk '{print $1}')\n"
        "export ROS_MASTER_URI=\"http://$master_ip:$port\" ROS_IP=\"$master_ip\"\n"
        "roslaunch -p \"$port\" %s >>%s 2>&1 &\n"
        "server=$!\n"
        "# Each task: its host's own address, then its simulation.\n"
        "srun --kill-on-bad-exit=1 bash -c '\n"
        "  export ROS_IP=$(hostname -I | awk \"{print \\$1}\")\n"
        "  case \"$SLURM_PROCID\" in\n"
        "%s"
        "  esac'\n"
        "status=$?\n"
        "kill -INT \"$server\"; wait \"$server\"\n"
        "cd %s && /usr/bin/python3 -c 'import sys; sys.path[:0] = [\"tools\"]; from palcas_cli import train; "
        "train.merge_simulation_episodes(sys.argv[1], int(sys.argv[2]))' %s %d\n"
        "exit $status\n"
        % (count, q(os.path.join(out, SLURM_SCRIPT)), count, seed, SIMULATION_SEED_STRIDE, root, out, out, count, out,
           q(root), q(os.path.join(out, "ros_log")), server, q(os.path.join(out, "console.log")),
           "".join(cases).replace("'", "'\\''"), q(root), q(out), count))
    path = os.path.join(out, SLURM_SCRIPT)
    with open(path, "w") as f:
        f.write(text)
    os.chmod(path, 0o755)
    return path


def run_launches(out, opts, record, resume, command_line):
    """The launch loop: one roslaunch for the episodes left (one per episode when demand or
    PR is drawn per episode); a simulation that died ends that episode only (the nodes
    checkpointed) and the next launch goes on with the next episode. Returns the exit status;
    raises launch.Interrupted (every node stopped and checkpointed)."""
    episodes, seed = int(opts["episodes"]), int(opts["seed"])
    clusters = scenario_clusters(opts["scenario"])
    auth_key = launch.message_key(out)
    done = episodes_done(out)
    log("training %s: episodes %d..%d x %ss, pr=%s%% demand=%s seed=%d -> %s"
        % (opts["arm"], done + 1, episodes, number_text(opts["duration"]),
           value_text(opts["pr_range"] or opts["pr"]) + (" (drawn per episode)" if opts["pr_range"] else ""),
           value_text(opts["demand_range"] or opts["demand"])
           + (" veh/h/lane" if opts["demand_range"] or opts["demand"] is not None else "")
           + (" (drawn per episode)" if opts["demand_range"] else ""), seed, out))
    nxt, launches, status = done, 0, 0
    while nxt < episodes and launches < episodes + 3 + episodes // 4:
        launches += 1
        rows_before = episodes_done(out)
        resume_nodes = "true" if (nxt > 0 or resume) else "false"
        draw = episode_draw(opts, nxt)
        count = 1 if sampled(opts) else episodes - nxt
        if sampled(opts):
            log("episode %d: demand %s, pr %s%%" % (nxt + 1, value_text(draw["demand_vphpl"]), number_text(draw["pr"])))
        launch_args = system_launch_args(opts, record, command_line, draw, seed, clusters, count, nxt, resume_nodes,
                                         out, out, auth_key)
        train_launch = launch.Launch(["palcas_launch", "system.launch"] + launch_args, os.path.join(out, "console.log"),
                                     os.path.join(out, "ros_log"), append=True).start()
        monitor = subprocess.Popen(
            ["setpriv", "--pdeathsig", "TERM", sys.executable, os.path.join(str(options.ROOT), "tools", "train_monitor.py"),
             "--rsus"] + palcas_arms.rsu_ids(opts["arm"], clusters)
            + ["--episodes", str(count), "--first-episode", str(nxt), "--total-episodes", str(episodes),
               "--duration", number_text(opts["duration"]), "--period", "15",
               "--episodes-csv", os.path.join(out, "episodes.csv")],
            stderr=subprocess.DEVNULL, env=launch.ros_env(train_launch.port, os.path.join(out, "ros_log")))
        try:
            status = train_launch.wait()
        finally:
            monitor.terminate()
            monitor.wait()
        rows_after = episodes_done(out)
        console_text = launch.read_text(os.path.join(out, "console.log"))
        # An RSU or the server that died leaves episodes trained without it: not a training
        # of this arm. Say which node and why, and stop (the simulation's crashes are below).
        # A node whose restart was still pending when the simulation crashed is not lost: the
        # next launch starts it afresh (launch.node_deaths' crashed_by).
        lost = [d for d in launch.node_deaths(console_text, crashed_by="palcas_sumo_bridge")
                if not d.startswith("palcas_sumo_bridge")]
        # An in-process RSU the bridge refused at start would refuse again in every episode.
        lost += ["%s (in process, refused at start)" % r for r in launch.inprocess_refusals(console_text)]
        if lost:
            console.error("training lost node(s) %s; last error: %s"
                          % (", ".join(lost), launch.last_fatal(console_text)))
            with open(os.path.join(out, "aborted_episodes.txt"), "a") as f:
                f.write("launch %d: lost %s; episodes.csv rows %d..%d were run without it\n"
                        % (launches, ", ".join(lost), rows_before + 1, rows_after))
            return 1
        if sampled(opts) and rows_after > rows_before:
            keep_episode_metrics(out, nxt)
        nxt += rows_after - rows_before
        short = rows_after - rows_before < count  # this launch did not finish its episodes
        if short and status in (130, 143):  # roslaunch itself was interrupted
            log("interrupted")
            break
        if short:
            # The simulation died (SUMO assertion, signal, or a fatal error of the bridge):
            # that episode only is lost; the training goes on with the next one (its own seed).
            why = launch.crash_reason(console_text)
            log("episode %d ended early (%s); resuming from the checkpoints with the next episode"
                % (nxt + 1, why or "no reason in the log"))
            with open(os.path.join(out, "aborted_episodes.txt"), "a") as f:
                f.write("episode %d (seed %d): %s\n" % (nxt, seed + nxt, why or "ended early, no reason in the log"))
            os.replace(os.path.join(out, "console.log"), os.path.join(out, "console-aborted-%d.log" % nxt))
            nxt += 1
    return 0 if status in (0, None) else status


def check(argv):
    """The training's options from its command line: (opts, record, out, resume); a resumed
    training takes what was not given from its record (record: None for a new one). Raises
    OptionError naming a bad option, before anything is made or started."""
    given = options.parse("train", argv, VALUES, FLAGS, helps=HELPS, description=DESCRIPTION)
    value = dict(TYPED_DEFAULTS, **given)
    settled = {"episodes": options.integer_in("--episodes", value["episodes"], 1),
               "duration": float(options.number_in("--duration", value["duration"], 0, None, open_low=True)),
               "pr": float(options.number_in("--pr", value["pr"], 0, 100)),
               "seed": options.integer_in("--seed", value["seed"], 0, options.MAX_SEED),
               "explore_fraction": float(options.number_in("--explore-fraction", value["explore_fraction"], 0, 1,
                                                           open_low=True))}
    for key, option in (("demand", "--demand"), ("ramp_demand", "--ramp-demand")):
        if given.get(key):
            settled[key] = float(options.number_in(option, given[key], 0, options.MAX_DEMAND))
    for key, option, high in (("demand_range", "--demand-range", options.MAX_DEMAND), ("pr_range", "--pr-range", 100)):
        if given.get(key):
            settled[key] = [as_number(float(v)) for v in options.range_in(option, given[key], 0, high).split(",")]
    if settled.get("demand") is not None and settled.get("demand_range"):
        raise OptionError("--demand and --demand-range: give one of them")
    if "pr" in given and settled.get("pr_range"):
        raise OptionError("--pr and --pr-range: give one of them")
    settled["scenario"] = options.scenario_ok("--scenario", value["scenario"])
    settled["arm"] = options.known_arm(value["arm"], palcas_arms.LEARNING_ARMS)
    if not palcas_arms.is_learning(settled["arm"]):
        raise OptionError("--arm %s: evaluation only, it learns nothing (run it with ./palcas run --arm %s)"
                          % (settled["arm"], settled["arm"]))
    overrides = {key: options.file_ok("--" + option, given[key]) if given.get(key) else ""
                 for key, option in (("learning", "learning"), ("rsu_params", "rsu-params"),
                                     ("bridge_params", "bridge-params"), ("v2x_params", "v2x"))}
    out = options.out_ok(given.get("out", ""))
    resume = bool(given.get("resume"))
    # What the user set (the rest is a default, or a resumed training's record).
    chosen = {k: settled.get(k) if k in given else None for k in ALL_GIVEN}
    opts, record = settle_options(chosen, out, resume)
    if not resume:
        opts.update(overrides, paper_printed=bool(given.get("paper_printed")))
    # How it runs and what it records, not what it learns: any launch may choose.
    # In process by default: the same decisions as RSU nodes (test/cli/inprocess_parity_test.sh)
    # without a ROS round trip per step, which costs most when the learners leave SUMO a core.
    if given.get("inprocess") and given.get("rsu_nodes"):
        raise OptionError("--in-process and --rsu-nodes: give one of them")
    opts["inprocess"] = not given.get("rsu_nodes")
    opts["record_decisions"] = bool(given.get("record_decisions"))
    opts["simulations"] = settle_simulations(given, record, out, opts)
    opts["plan"] = bool(given.get("plan"))
    if opts["plan"] and (opts["simulations"] == 1 or resume):
        raise OptionError("--plan: writes the Slurm job of a new training of several simulations (give "
                          "--simulations K with K > 1, without --resume)")
    return opts, record, out, resume


def settle_simulations(given, record, out, opts):
    """--simulations K: given, or a resumed training's own (1 for a record without it); K > 1
    needs a federated arm, one demand and PR for every episode (the simulations' launches run
    many episodes each) and at most SIMULATION_SEED_STRIDE episodes. Runs the RSUs in
    process. Raises OptionError."""
    count = (options.integer_in("--simulations", given["simulations"], 1, MAX_SIMULATIONS)
             if given.get("simulations") is not None else None)
    if record is not None:
        recorded = int(record.get("simulations", 1))
        if count is not None and count != recorded:
            raise OptionError("--resume: '%s' trained with --simulations %d, not --simulations %d (leave "
                              "--simulations out to continue it)" % (out, recorded, count))
        count = recorded
    count = count or 1
    if count == 1:
        return 1
    if not palcas_arms.ARMS[opts["arm"]].get("federation"):
        raise OptionError("--simulations %d: arm %s has no federation to share (a federated arm, e.g. palcas)"
                          % (count, opts["arm"]))
    if sampled(opts):
        raise OptionError("--simulations %d: not with --demand-range or --pr-range (give --demand / --pr)" % count)
    if int(opts["episodes"]) > SIMULATION_SEED_STRIDE:
        raise OptionError("--simulations %d: at most %d --episodes per simulation (simulation k's episodes run "
                          "seeds seed + %d k + e)" % (count, SIMULATION_SEED_STRIDE, SIMULATION_SEED_STRIDE))
    if given.get("rsu_nodes"):
        raise OptionError("--rsu-nodes: not with --simulations %d (each simulation's RSUs live in its bridge, "
                          "on its clock)" % count)
    opts["inprocess"] = True  # each simulation's RSUs live in its bridge, on its clock
    return count


def main(argv):
    opts, _, out, resume = check(argv)
    launch.handle_signals()
    out = out or os.path.join(options.results_dir(), "train-%s-%s" % (
        opts["arm"], datetime.datetime.now().strftime("%Y%m%d-%H%M%S")))
    os.makedirs(policy_folder.checkpoints(out), exist_ok=True)
    out = os.path.abspath(out)
    if resume and training_episodes_done(out, opts) >= int(opts["episodes"]):
        log("all %d episodes done in %s" % (int(opts["episodes"]), out))
        return 0
    if not resume:
        # The exploration schedule is a share of this training's budget, not of a 72-hour run.
        schedule = os.path.join(out, "learning_schedule.yaml")
        try:
            import train_schedule  # PyYAML: installed by then
            train_schedule.write(schedule, opts["episodes"], opts["duration"], opts["explore_fraction"],
                                 base=opts["learning"])
        except Exception as e:  # noqa: BLE001 - a bad base file, named with its fault
            console.error(str(e))
            return 1
        opts["learning"] = schedule
    command_line = "./palcas train " + " ".join(argv)
    record = write_record(out, opts, launch.git_commit(), command_line, resume)
    if opts.get("plan"):
        log("Slurm job of %d simulations: sbatch %s; then ./palcas run --policy %s"
            % (simulation_count(opts), write_slurm_script(out, opts, record, command_line), out))
        return 0
    try:
        run = run_simulations if simulation_count(opts) > 1 else run_launches
        status = run(out, opts, record, resume, command_line)
    except launch.Interrupted as stop:
        log("interrupted (%s): every node stopped and checkpointed; continue with "
            "./palcas train --resume --out %s" % (stop.signal, out))
        return stop.status
    if not os.path.isfile(os.path.join(out, "episodes.csv")):
        console.error("training wrote no episodes.csv (see %s/console.log)" % out)
        return 1
    try:
        import learning_curves  # matplotlib: only once there is something to draw
        learning_curves.main(out)
    except Exception as e:  # noqa: BLE001 - the training stands without its curves
        log("warning: no learning curves (%s)" % e)
    log("training folder: %s (evaluate with: ./palcas run --policy %s)" % (out, out))
    return status
