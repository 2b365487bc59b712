#!/usr/bin/env python3
"""Training orchestration behind `./palcas train`: the training record, resume, the launch
loop that survives SUMO's own crashes, progress and learning curves.

`./palcas` checks every option's value and builds the workspace, then runs this tool with
the checked values; options the user did not give are absent. What is left to check here
(a resumed training's record) is checked before any folder is made or process started.

usage: train.py --root REPO --out DIR [--resume] [--arm A] [--episodes N] [--duration S]
                [--pr P] [--seed N] [--scenario NAME] [--explore-fraction F]
                [--learning FILE] [--rsu-params FILE] [--bridge-params FILE]
                [--paper-printed] --command-line TEXT [--check-only]

Exit status: 0 done; 1 a node died for good or nothing was trained; 2 a bad option;
130 / 143 interrupted (SIGINT / SIGTERM: every process stopped and checkpointed)."""
import argparse
import datetime
import json
import os
import re
import signal
import socket
import subprocess
import sys

# What an option means when a new training leaves it out.
DEFAULTS = {"arm": "palcas", "episodes": 5, "duration": 3600.0, "pr": 60.0, "seed": 1,
            "scenario": "paper", "explore_fraction": 0.5}
# Options a resumed training takes from its record (record key per option).
RESUMED = {"arm": "arm", "scenario": "scenario", "pr": "pr", "seed": "seed", "duration": "duration_s"}
ANSI = re.compile(r"\x1b\[[0-9;]*m")


class OptionError(Exception):
    """A bad command line (exit 2, nothing started)."""


def log(text):
    print("[palcas] %s" % text, file=sys.stderr, flush=True)


def number_text(value):
    """A number as a user wrote it: 60, 0.5, 1200."""
    return "%g" % value if isinstance(value, (int, float)) and not isinstance(value, bool) else str(value)


def same_value(a, b):
    try:
        return float(a) == float(b)
    except (TypeError, ValueError):
        return str(a) == str(b)


def read_record(out):
    path = os.path.join(out, "train.json")
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
    record_path = os.path.join(out, "train.json") if out else ""
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
    if given.get("episodes") is None:
        opts["episodes"] = record["episodes"]
    if given.get("explore_fraction") is not None:
        raise OptionError("--resume: the exploration schedule is the training's own (%s/learning_schedule.yaml); "
                          "leave --explore-fraction out" % out)
    opts["explore_fraction"] = record["explore_fraction"]
    for key in ("learning", "rsu_params", "bridge_params"):
        opts[key] = record.get(key, "")
    opts["paper_printed"] = bool(record.get("paper_printed", False))
    return opts, record


def as_number(value):
    """60.0 -> 60 (as the user wrote it); other values unchanged."""
    return int(value) if isinstance(value, float) and value.is_integer() else value


def write_record(out, opts, git_commit):
    """train.json, written whole (a path with a quote or a backslash stays valid JSON)."""
    record = {"arm": opts["arm"], "scenario": opts["scenario"], "pr": as_number(opts["pr"]), "seed": opts["seed"],
              "episodes": opts["episodes"], "duration_s": as_number(opts["duration"]), "learning": opts.get("learning") or "",
              "rsu_params": opts.get("rsu_params") or "", "bridge_params": opts.get("bridge_params") or "",
              "paper_printed": bool(opts.get("paper_printed")), "explore_fraction": opts["explore_fraction"],
              "git_commit": git_commit}
    tmp = os.path.join(out, ".train.json.tmp")
    with open(tmp, "w") as f:
        json.dump(record, f)
        f.write("\n")
    os.replace(tmp, os.path.join(out, "train.json"))
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


def rsu_ids(arm, clusters):
    return ["central"] if arm == "centralized" else ["rsu_%d" % k for k in range(clusters)]


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


def run_launches(root, out, opts, record, args, interrupt):
    """The launch loop: one roslaunch for the episodes left; a simulation that died ends
    that episode only (the nodes checkpointed) and the next launch goes on with the next
    episode. Returns the exit status."""
    episodes, seed = int(opts["episodes"]), int(opts["seed"])
    clusters = scenario_clusters(root, opts["scenario"])
    auth_key = message_key(out)
    done = episodes_done(out)
    log("training %s: episodes %d..%d x %ss, pr=%s%% seed=%d -> %s"
        % (opts["arm"], done + 1, episodes, number_text(opts["duration"]), number_text(opts["pr"]), seed, out))
    nxt, launches, status = done, 0, 0
    env = dict(os.environ, ROS_HOSTNAME="127.0.0.1", ROS_LOG_DIR=os.path.join(out, "ros_log"))
    while nxt < episodes and launches < episodes + 3 + episodes // 4:
        launches += 1
        rows_before = episodes_done(out)
        port = free_port()
        env["ROS_MASTER_URI"] = "http://127.0.0.1:%d" % port
        resume_nodes = "true" if (nxt > 0 or args.resume) else "false"
        launch_args = [
            "arm:=%s" % opts["arm"], "mode:=train", "pr:=%s" % number_text(opts["pr"]), "seed:=%d" % seed,
            "scenario:=%s" % opts["scenario"], "clusters:=%d" % clusters, "episodes:=%d" % (episodes - nxt),
            "first_episode:=%d" % nxt, "duration:=%s" % number_text(opts["duration"]),
            "checkpoint_dir:=%s" % os.path.join(out, "checkpoints"), "resume:=%s" % resume_nodes,
            "out_dir:=%s" % out, "learning_params:=%s" % (opts.get("learning") or "none"),
            "rsu_params:=%s" % (opts.get("rsu_params") or "none"),
            "bridge_params:=%s" % (opts.get("bridge_params") or "none"),
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
                 "--rsus"] + rsu_ids(opts["arm"], clusters)
                + ["--episodes", str(episodes - nxt), "--first-episode", str(nxt),
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
        nxt += rows_after - rows_before
        if nxt < episodes and status in (130, 143):  # roslaunch itself was interrupted
            log("interrupted")
            break
        if nxt < episodes:
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
    ap.add_argument("--seed", type=int)
    ap.add_argument("--scenario")
    ap.add_argument("--explore-fraction", type=float)
    ap.add_argument("--learning", default="")
    ap.add_argument("--rsu-params", default="")
    ap.add_argument("--bridge-params", default="")
    ap.add_argument("--paper-printed", action="store_true")
    ap.add_argument("--command-line", default="./palcas train")
    ap.add_argument("--check-only", action="store_true", help="check the options against the record, start nothing")
    return ap.parse_args(argv)


def main(argv=None):
    args = parse(sys.argv[1:] if argv is None else argv)
    given = {k: getattr(args, k) for k in ("arm", "episodes", "duration", "pr", "seed", "scenario", "explore_fraction")}
    try:
        opts, record = settle_options(given, args.out, args.resume)
    except OptionError as e:
        print("[palcas] error: %s" % e, file=sys.stderr)
        return 2
    if args.check_only:
        return 0
    if not args.resume:
        opts.update(learning=args.learning, rsu_params=args.rsu_params, bridge_params=args.bridge_params,
                    paper_printed=args.paper_printed)
    out = args.out or os.path.join(args.results_dir or os.path.join(args.root, "results"), "train-%s-%s" % (
        opts["arm"], datetime.datetime.now().strftime("%Y%m%d-%H%M%S")))
    os.makedirs(os.path.join(out, "checkpoints"), exist_ok=True)
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
    record = write_record(out, opts, git_commit(args.root))
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
