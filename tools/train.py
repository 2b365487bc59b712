#!/usr/bin/env python3
"""Training orchestration behind `./palcas train`: the training record, resume, the launch
loop that survives SUMO's own crashes, progress and learning curves.

`./palcas` checks every option's value and builds the workspace, then runs this tool with
the checked values; options the user did not give are absent. What is left to check here
(a resumed training's record) is checked before any folder is made or process started.

usage: train.py --root REPO --out DIR [--resume] [--arm A] [--episodes N] [--duration S]
                [--pr P | --pr-range MIN,MAX] [--demand VPHPL | --demand-range MIN,MAX]
                [--ramp-demand VPH] [--seed N] [--scenario NAME] [--explore-fraction F]
                [--learning FILE] [--rsu-params FILE] [--bridge-params FILE] [--v2x FILE]
                [--paper-printed] --command-line TEXT [--check-only]

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

Exit status: 0 done; 1 a node died for good or nothing was trained; 2 a bad option;
130 / 143 interrupted (SIGINT / SIGTERM: every process stopped and checkpointed)."""
import argparse
import datetime
import json
import os
import random
import re
import signal
import socket
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import palcas_arms  # noqa: E402
import policy_folder  # noqa: E402

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
ANSI = re.compile(r"\x1b\[[0-9;]*m")
MAX_DEMAND = 100000  # veh/h per lane: what the bridge accepts


class OptionError(Exception):
    """A bad command line (exit 2, nothing started)."""


def log(text):
    print("[palcas] %s" % text, file=sys.stderr, flush=True)


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


def parse_range(text, option, low, high):
    """'MIN,MAX' -> [MIN, MAX] within [low, high], MIN <= MAX. Raises OptionError naming the option."""
    parts = text.split(",")
    try:
        lo, hi = (float(p) for p in parts) if len(parts) == 2 else (None, None)
    except ValueError:
        lo = hi = None
    if lo is None or not (low <= lo <= high and low <= hi <= high):
        raise OptionError("%s '%s': expected MIN,MAX, two numbers in [%s, %s]"
                          % (option, text, number_text(low), number_text(high)))
    if lo > hi:
        raise OptionError("%s '%s': MIN %s is greater than MAX %s" % (option, text, number_text(lo), number_text(hi)))
    return [as_number(lo), as_number(hi)]


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
        opts[key] = record.get(key, "")
    opts["paper_printed"] = bool(record.get("paper_printed", False))
    return opts, record


def as_number(value):
    """60.0 -> 60 (as the user wrote it); other values unchanged."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


def write_record(out, opts, git_commit, command_line="", resume=False):
    """train.json, written whole (a path with a quote or a backslash stays valid JSON). It
    keeps the command that started the training (`command_line`) and lists every later
    `--resume` in `resumed_with`, so a shipped policy names how it was trained, not only how
    it was last continued."""
    earlier = {}
    if resume:
        try:
            with open(policy_folder.train_record_path(out)) as f:
                earlier = json.load(f)
        except (OSError, ValueError):
            earlier = {}
    record = {"arm": opts["arm"], "scenario": opts["scenario"], "pr": as_number(opts["pr"]), "seed": opts["seed"],
              "episodes": opts["episodes"], "duration_s": as_number(opts["duration"]), "learning": opts.get("learning") or "",
              "rsu_params": opts.get("rsu_params") or "", "bridge_params": opts.get("bridge_params") or "",
              "v2x_params": opts.get("v2x_params") or "",
              "paper_printed": bool(opts.get("paper_printed")), "explore_fraction": opts["explore_fraction"],
              "demand_vphpl": as_number(opts["demand"]) if opts.get("demand") is not None else None,
              "ramp_demand_vph": as_number(opts["ramp_demand"]) if opts.get("ramp_demand") is not None else None,
              "demand_range": opts.get("demand_range"), "pr_range": opts.get("pr_range"),
              "git_commit": git_commit,
              "command_line": earlier.get("command_line", "") if resume else command_line,
              "resumed_with": earlier.get("resumed_with", []) + ([command_line] if resume else [])}
    if sampled(opts):
        record["episode_draws"] = [episode_draw(opts, k) for k in range(int(opts["episodes"]))]
    tmp = os.path.join(out, ".train.json.tmp")
    with open(tmp, "w") as f:
        json.dump(record, f)
        f.write("\n")
    os.replace(tmp, str(policy_folder.train_record_path(out)))
    return record


def episodes_done(out):
    """Rows of episodes.csv (the bridge writes one per finished episode)."""
    try:
        with open(os.path.join(out, "episodes.csv")) as f:
            return max(0, sum(1 for _ in f) - 1)
    except OSError:
        return 0


def node_deaths(console_text):
    """Nodes of a roslaunch console that died for good: a non-zero exit not followed by a
    restart (respawn), or three deaths (a crash loop). 'name (exit code N[, died k times])'."""
    text = ANSI.sub("", console_text)
    deaths, restarts, codes = {}, {}, {}
    for m in re.finditer(r"\[([^\[\]\s]+)\] process has died \[pid \d+, exit code (-?\d+)", text):
        if m.group(2) != "0":
            deaths[m.group(1)] = deaths.get(m.group(1), 0) + 1
            codes[m.group(1)] = m.group(2)
    for m in re.finditer(r"\[([^\[\]\s]+)\] restarting process", text):
        restarts[m.group(1)] = restarts.get(m.group(1), 0) + 1
    lost = []
    for node in sorted(deaths):
        d, r = deaths[node], restarts.get(node, 0)
        if d > r or d >= 3:
            lost.append("%s (exit code %s%s)" % (node, codes[node], ", died %d times" % d if d > 1 else ""))
    return lost


def last_fatal(console_text):
    """The last FATAL/ERROR line or SUMO assertion, shortened."""
    lines = [l for l in ANSI.sub("", console_text).splitlines()
             if re.search(r"\[(FATAL|ERROR)\]|Assertion .* failed|Segmentation fault", l)]
    return lines[-1][:400] if lines else ""


def crash_reason(console_text):
    """Why the simulation ended early: its own error first (an RSU killed on the way is not why)."""
    text = ANSI.sub("", console_text)
    found = re.findall(r"(?:Assertion.*|Segmentation fault.*|\[FATAL\].*)", text)
    if found:
        return found[-1][:200]
    died = re.search(r"process has died.*", text)
    return died.group(0)[:200] if died else ""


def read_text(path):
    try:
        with open(path, errors="replace") as f:
            return f.read()
    except OSError:
        return ""


def message_key(out):
    """<out>/auth.key: the training's random message key (hex, owner-only), made on first use."""
    key = os.path.join(out, "auth.key")
    if not (os.path.isfile(key) and os.path.getsize(key) > 0):
        tmp = key + ".tmp"
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
        with os.fdopen(fd, "w") as f:
            f.write(os.urandom(32).hex())
        os.replace(tmp, key)
    return key


def free_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def scenario_clusters(root, scenario):
    """road/clusters of config/scenarios/<name>/scenario.yaml (the launch files read the same line)."""
    text = read_text(os.path.join(root, "config", "scenarios", scenario, "scenario.yaml"))
    m = re.search(r"^\s*clusters:\s*(\d+)", text, re.M)
    if not m:
        raise OptionError("--scenario %s: its scenario.yaml has no road/clusters" % scenario)
    return int(m.group(1))


def git_commit(root):
    try:
        return subprocess.run(["git", "-C", root, "rev-parse", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


class Interrupt:
    """SIGINT (Ctrl-C reaches roslaunch too: same process group) or SIGTERM (passed on to
    roslaunch as SIGINT): remembered, and the launch is waited for while it shuts down."""

    def __init__(self):
        self.signal = None
        self.launch = None
        signal.signal(signal.SIGINT, self._on_int)
        signal.signal(signal.SIGTERM, self._on_term)

    def _on_int(self, *_):
        self.signal = "INT"

    def _on_term(self, *_):
        self.signal = "TERM"
        if self.launch and self.launch.poll() is None:
            self.launch.send_signal(signal.SIGINT)


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


def run_launches(root, out, opts, record, args, interrupt):
    """The launch loop: one roslaunch for the episodes left (one per episode when demand or
    PR is drawn per episode); a simulation that died ends that episode only (the nodes
    checkpointed) and the next launch goes on with the next episode. Returns the exit status."""
    episodes, seed = int(opts["episodes"]), int(opts["seed"])
    clusters = scenario_clusters(root, opts["scenario"])
    auth_key = message_key(out)
    done = episodes_done(out)
    log("training %s: episodes %d..%d x %ss, pr=%s%% demand=%s seed=%d -> %s"
        % (opts["arm"], done + 1, episodes, number_text(opts["duration"]),
           value_text(opts["pr_range"] or opts["pr"]) + (" (drawn per episode)" if opts["pr_range"] else ""),
           value_text(opts["demand_range"] or opts["demand"])
           + (" veh/h/lane" if opts["demand_range"] or opts["demand"] is not None else "")
           + (" (drawn per episode)" if opts["demand_range"] else ""), seed, out))
    nxt, launches, status = done, 0, 0
    env = dict(os.environ, ROS_HOSTNAME="127.0.0.1", ROS_LOG_DIR=os.path.join(out, "ros_log"))
    while nxt < episodes and launches < episodes + 3 + episodes // 4:
        launches += 1
        rows_before = episodes_done(out)
        port = free_port()
        env["ROS_MASTER_URI"] = "http://127.0.0.1:%d" % port
        resume_nodes = "true" if (nxt > 0 or args.resume) else "false"
        draw = episode_draw(opts, nxt)
        count = 1 if sampled(opts) else episodes - nxt
        if sampled(opts):
            log("episode %d: demand %s, pr %s%%" % (nxt + 1, value_text(draw["demand_vphpl"]), number_text(draw["pr"])))
        launch_args = [
            "arm:=%s" % opts["arm"], "mode:=train", "pr:=%s" % number_text(draw["pr"]), "seed:=%d" % seed,
            "demand:=%s" % ("scenario" if draw["demand_vphpl"] is None else number_text(draw["demand_vphpl"])),
            "ramp_demand:=%s" % ("scenario" if opts.get("ramp_demand") is None else number_text(opts["ramp_demand"])),
            "scenario:=%s" % opts["scenario"], "clusters:=%d" % clusters, "episodes:=%d" % count,
            "first_episode:=%d" % nxt, "duration:=%s" % number_text(opts["duration"]),
            "checkpoint_dir:=%s" % policy_folder.checkpoints(out), "resume:=%s" % resume_nodes,
            "out_dir:=%s" % out, "learning_params:=%s" % (opts.get("learning") or "none"),
            "rsu_params:=%s" % (opts.get("rsu_params") or "none"),
            "bridge_params:=%s" % (opts.get("bridge_params") or "none"),
            "v2x_params:=%s" % (opts.get("v2x_params") or "none"),
            "paper_printed:=%s" % str(bool(opts.get("paper_printed"))).lower(), "auth_key_file:=%s" % auth_key,
            "git_commit:=%s" % record["git_commit"], "command_line:=%s" % args.command_line]
        with open(os.path.join(out, "console.log"), "a") as console:
            # --pdeathsig: if this process is killed outright (SIGKILL, no handler runs),
            # roslaunch still gets SIGINT and shuts its nodes down cleanly (they checkpoint).
            interrupt.launch = subprocess.Popen(
                ["setpriv", "--pdeathsig", "INT", "roslaunch", "-p", str(port), "palcas_launch", "system.launch"]
                + launch_args, stdout=console, stderr=subprocess.STDOUT, env=env)
            monitor = subprocess.Popen(
                ["setpriv", "--pdeathsig", "TERM", sys.executable, os.path.join(root, "tools", "train_monitor.py"),
                 "--rsus"] + palcas_arms.rsu_ids(opts["arm"], clusters)
                + ["--episodes", str(count), "--first-episode", str(nxt), "--total-episodes", str(episodes),
                   "--duration", number_text(opts["duration"]), "--period", "15"],
                stderr=subprocess.DEVNULL, env=env)
            while True:
                try:
                    status = interrupt.launch.wait()
                    break
                except InterruptedError:
                    continue
            monitor.terminate()
            monitor.wait()
        if interrupt.signal:
            log("interrupted (%s): every node stopped and checkpointed; continue with "
                "./palcas train --resume --out %s" % (interrupt.signal, out))
            return 130 if interrupt.signal == "INT" else 143
        rows_after = episodes_done(out)
        console_text = read_text(os.path.join(out, "console.log"))
        # An RSU or the server that died leaves episodes trained without it: not a training
        # of this arm. Say which node and why, and stop (the simulation's crashes are below).
        lost = [d for d in node_deaths(console_text) if not d.startswith("palcas_sumo_bridge")]
        if lost:
            print("[palcas] error: training lost node(s) %s; last error: %s"
                  % (", ".join(lost), last_fatal(console_text)), file=sys.stderr, flush=True)
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
            why = crash_reason(console_text)
            log("episode %d ended early (%s); resuming from the checkpoints with the next episode"
                % (nxt + 1, why or "no reason in the log"))
            with open(os.path.join(out, "aborted_episodes.txt"), "a") as f:
                f.write("episode %d (seed %d): %s\n" % (nxt, seed + nxt, why or "ended early, no reason in the log"))
            os.replace(os.path.join(out, "console.log"), os.path.join(out, "console-aborted-%d.log" % nxt))
            nxt += 1
    return 0 if status in (0, None) else status


def parse(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--root", required=True, help="the repository")
    ap.add_argument("--out", default="")
    ap.add_argument("--results-dir", default="", help="where a training without --out goes")
    ap.add_argument("--resume", action="store_true")
    ap.add_argument("--arm")
    ap.add_argument("--episodes", type=int)
    ap.add_argument("--duration", type=float)
    ap.add_argument("--pr", type=float)
    ap.add_argument("--pr-range", help="MIN,MAX [%%]: each episode draws its PR from it")
    ap.add_argument("--demand", type=float, help="mainline demand [veh/h per lane]")
    ap.add_argument("--ramp-demand", type=float, help="on-ramp demand [veh/h per ramp]")
    ap.add_argument("--demand-range", help="MIN,MAX [veh/h per lane]: each episode draws its demand from it")
    ap.add_argument("--seed", type=int)
    ap.add_argument("--scenario")
    ap.add_argument("--explore-fraction", type=float)
    ap.add_argument("--learning", default="")
    ap.add_argument("--rsu-params", default="")
    ap.add_argument("--bridge-params", default="")
    ap.add_argument("--v2x", default="", help="a YAML over config/v2x.yaml: train with the V2X channel on")
    ap.add_argument("--paper-printed", action="store_true")
    ap.add_argument("--command-line", default="./palcas train")
    ap.add_argument("--check-only", action="store_true", help="check the options against the record, start nothing")
    return ap.parse_args(argv)


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    given = {k: getattr(args, k) for k in ALL_GIVEN}
    try:
        if given["arm"] is not None and not palcas_arms.is_learning(given["arm"]):
            raise OptionError("--arm '%s': not a learning arm (%s)" % (given["arm"], ", ".join(palcas_arms.LEARNING_ARMS)))
        for option, low, high in (("demand_range", 0, MAX_DEMAND), ("pr_range", 0, 100)):
            if given[option] is not None:
                given[option] = parse_range(given[option], "--" + option.replace("_", "-"), low, high)
        if given["demand"] is not None and given["demand_range"] is not None:
            raise OptionError("--demand and --demand-range: give one of them")
        if given["pr"] is not None and given["pr_range"] is not None:
            raise OptionError("--pr and --pr-range: give one of them")
        opts, record = settle_options(given, args.out, args.resume)
    except OptionError as e:
        print("[palcas] error: %s" % e, file=sys.stderr)
        return 2
    if args.check_only:
        return 0
    if not args.resume:
        opts.update(learning=args.learning, rsu_params=args.rsu_params, bridge_params=args.bridge_params,
                    v2x_params=args.v2x,
                    paper_printed=args.paper_printed)
    out = args.out or os.path.join(args.results_dir or os.path.join(args.root, "results"), "train-%s-%s" % (
        opts["arm"], datetime.datetime.now().strftime("%Y%m%d-%H%M%S")))
    os.makedirs(policy_folder.checkpoints(out), exist_ok=True)
    out = os.path.abspath(out)
    if args.resume and episodes_done(out) >= int(opts["episodes"]):
        log("all %d episodes done in %s" % (int(opts["episodes"]), out))
        return 0
    if not args.resume:
        # The exploration schedule is a share of this training's budget, not of a 72-hour run.
        schedule = os.path.join(out, "learning_schedule.yaml")
        cmd = [sys.executable, os.path.join(args.root, "tools", "train_schedule.py"), schedule,
               "--episodes", str(opts["episodes"]), "--duration", number_text(opts["duration"]),
               "--fraction", number_text(opts["explore_fraction"])]
        if opts["learning"]:
            cmd += ["--base", opts["learning"]]
        if subprocess.run(cmd).returncode != 0:
            print("[palcas] error: bad --explore-fraction", file=sys.stderr)
            return 1
        opts["learning"] = schedule
    record = write_record(out, opts, git_commit(args.root), args.command_line, bool(args.resume))
    interrupt = Interrupt()
    status = run_launches(args.root, out, opts, record, args, interrupt)
    if status in (130, 143):
        return status
    if not os.path.isfile(os.path.join(out, "episodes.csv")):
        print("[palcas] error: training wrote no episodes.csv (see %s/console.log)" % out, file=sys.stderr)
        return 1
    subprocess.run([sys.executable, os.path.join(args.root, "tools", "learning_curves.py"), out])
    log("training folder: %s (evaluate with: ./palcas run --policy %s)" % (out, out))
    return status


if __name__ == "__main__":
    sys.exit(main())
