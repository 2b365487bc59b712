"""./palcas experiment: the paper's experiment, arms x PRs x evaluation seeds, each point an
independent run of ./palcas run's code (palcas_cli.run), several at a time in threads.

  ./palcas experiment --out DIR [--arms a,b] [--prs 5,10] [--demands 1000,1400] [--seeds N]
                      [--seed-set dev|test] [--duration S] [--scenario NAME]
                      [--policy ARM=DIR ...] [--jobs J]
  ./palcas experiment --plan (same options): write DIR/plan.txt (one command per point) and
                      DIR/slurm_array.sh, run nothing
  ./palcas experiment --point NAME --out DIR   run one planned point (what plan.txt calls)
  ./palcas experiment --collect --out DIR      results.csv, tables and figures from the point folders

Layout: DIR/experiment.json (the settings; a later call must agree with them), and per point
DIR/points/<arm>_pr<P>_s<seed>/ (with --demands: <arm>_pr<P>_d<D>_s<seed>/) with
<arm>/metrics.json, manifest.json, console.log, point.log (what the run said) and point.json
(status, exit code, wall time, the equivalent ./palcas run command). --demands (mainline
veh/h per lane) is a dimension beside arms, PRs and seeds; without it every point runs at the
scenario's own demand, as experiments did before it. A point is finished when its
metrics.json covers the whole duration; finished points are never run again, so an
interrupted experiment continues where it stopped.

Seeds: --seeds N takes the first N seeds of a named set of config/seeds.yaml (--seed-set,
default test): settings are chosen on dev (101-130), results are reported on test
(1001-1030), never tuned on. experiment.json records the set (seed_set); a folder is extended
only with seeds of its own set. A seed a policy trained on is refused either way.
"""
import concurrent.futures
import json
import os
import pathlib
import re
import shlex
import signal
import sys
import threading
import time
import traceback

from palcas_cli import Console, ROOT, launch, options, run
from palcas_cli.options import OptionError
import experiment_results
import policy_folder
import repo_paths
import seed_sets
from palcas_arms import ALL_ARMS, LEARNING_ARMS

PAPER_PRS = (5, 10, 20, 40, 60)
# Settings that define the experiment: a continuation must not change them.
FIXED_KEYS = ("duration_s", "scenario", "v2x", "bridge_params", "rsu_params")
# Files every point runs with: settings key, ./palcas run option.
POINT_FILES = (("v2x", "--v2x"), ("bridge_params", "--bridge-params"), ("rsu_params", "--rsu-params"))


class UsageError(OptionError):
    """A bad command line of the experiment (exit 2, nothing written)."""


def parse_list(text, what, convert):
    items = [t.strip() for t in text.split(",") if t.strip()]
    if not items:
        raise UsageError(f"--{what}: empty list")
    out = []
    for t in items:
        try:
            out.append(convert(t))
        except ValueError:
            raise UsageError(f"--{what}: '{t}' is not valid")
    if len(set(out)) != len(out):
        raise UsageError(f"--{what}: '{text}' lists a value twice")
    return out


def point_name(arm, pr, seed, demand=None):
    """<arm>_pr<P>_s<seed>; at a given demand <arm>_pr<P>_d<D>_s<seed>."""
    return f"{arm}_pr{pr:g}_s{seed}" if demand is None else f"{arm}_pr{pr:g}_d{demand:g}_s{seed}"


def training_seeds(policy_dir):
    """Seeds a policy trained on (train.json: seed, seed+1, ... one per episode)."""
    if not policy_folder.train_record_path(policy_dir).exists():
        return set()
    t = policy_folder.train_record(policy_dir)
    return set(range(int(t["seed"]), int(t["seed"]) + int(t["episodes"])))


def settings_from_args(a):
    arms = parse_list(a.arms, "arms", str)
    for arm in arms:
        if arm not in ALL_ARMS:
            raise UsageError(f"--arms: unknown arm '{arm}' (one of {', '.join(ALL_ARMS)})")
    prs = parse_list(a.prs, "prs", float)
    for pr in prs:
        if not 0.0 <= pr <= 100.0:
            raise UsageError(f"--prs: {pr:g} is outside [0, 100]")
    demands = None
    if a.demands is not None:
        demands = parse_list(a.demands, "demands", float)
        for d in demands:
            if not 0.0 < d <= options.MAX_DEMAND:
                raise UsageError(f"--demands: {d:g} is outside (0, {options.MAX_DEMAND:g}] veh/h per lane")
    if a.seeds < 1:
        raise UsageError(f"--seeds: {a.seeds} must be >= 1")
    if not a.duration > 0:
        raise UsageError(f"--duration: {a.duration} must be > 0")
    if not (options.SCENARIOS / a.scenario / "scenario.yaml").exists():
        raise UsageError(f"--scenario: no road '{a.scenario}' under config/scenarios")
    policies = {}
    for item in a.policy or []:
        arm, sep, path = item.partition("=")
        if not sep or arm not in LEARNING_ARMS:
            raise UsageError(f"--policy: '{item}' is not ARM=DIR with a learning arm")
        policies[arm] = str(pathlib.Path(path).resolve())
    seed_set = getattr(a, "seed_set", None) or seed_sets.DEFAULT
    try:
        seeds = seed_sets.seeds(seed_set, a.seeds)
    except seed_sets.SeedSetError as e:
        raise UsageError(f"--seed-set {seed_set} --seeds {a.seeds}: {e}")
    for arm in arms:
        if arm not in LEARNING_ARMS:
            continue
        policy = policies.get(arm, str(policy_folder.shipped(arm)))
        if policy_folder.why_not(policy):
            raise UsageError(f"arm '{arm}': no trained policy at {policy} (train it with "
                             f"./palcas train --arm {arm}, or pass --policy {arm}=DIR)")
        learnt_on = policy_folder.train_record(policy)["scenario"]
        have, need = options.scenario_state_size(learnt_on), options.scenario_state_size(a.scenario)
        if have != need:
            raise UsageError(f"arm '{arm}': the policy {policy} was trained on road {learnt_on} "
                             f"(state size {have}), road {a.scenario} has {need}")
        seen = training_seeds(policy) & set(seeds)
        if seen:
            raise UsageError(f"arm '{arm}': evaluation seed(s) {sorted(seen)} were training "
                             f"seeds of {policy}")
        policies[arm] = repo_paths.recorded(policy)  # experiment.json: repository-relative
    settings = {"arms": arms, "prs": prs, "seeds": seeds, "seed_set": seed_set, "duration_s": float(a.duration),
                "scenario": a.scenario, "policies": {k: v for k, v in policies.items() if k in arms},
                # A programmatic caller may leave --in-process out.
                "inprocess": bool(getattr(a, "inprocess", False))}
    if demands is not None:
        settings["demands"] = demands
    for key, option in POINT_FILES:
        path = getattr(a, key, "") or ""
        if path and not os.path.isfile(path):
            raise UsageError(f"{option} {path}: no such file")
        settings[key] = repo_paths.recorded(path) if path else ""
    return settings


def portable(settings):
    """Settings with their paths as experiment.json keeps them (repository-relative where they
    lie in the repository): a folder written before that compares equal to a new call."""
    s = dict(settings, policies={a: repo_paths.recorded(repo_paths.usable(p))
                                 for a, p in settings.get("policies", {}).items()})
    for key, _ in POINT_FILES:
        if s.get(key):
            s[key] = repo_paths.recorded(repo_paths.usable(s[key]))
    return s


def merge_settings(out, wanted):
    """The experiment's settings: new, or the stored ones extended by new arms/PRs/seeds.
    A changed duration, road or seed set is refused (it would mix two experiments in one table)."""
    f = out / "experiment.json"
    if not f.exists():
        return wanted
    have = json.loads(f.read_text())
    for key, _ in POINT_FILES:  # an experiment from before these options ran without them
        have.setdefault(key, "")
    have = portable(have)
    have_set = have.get("seed_set") or seed_sets.set_of(have["seeds"])  # a folder from before seed sets
    if have_set != wanted["seed_set"]:
        said = f"seed set '{have_set}' (seeds {seed_sets.describe(have['seeds'])})" if have_set else \
            f"seeds {seed_sets.describe(have['seeds'])} (in no one set of config/seeds.yaml)"
        raise UsageError(f"{out} holds an experiment on {said}, not on seed set "
                         f"'{wanted['seed_set']}': two seed sets do not mix in one experiment "
                         f"(choose on dev, report on test); use another --out")
    for key in FIXED_KEYS:
        if have[key] != wanted[key]:
            raise UsageError(f"{out} holds an experiment with {key} = {have[key]}, not "
                             f"{wanted[key]}: use another --out")
    for arm, policy in wanted["policies"].items():
        if have["policies"].get(arm, policy) != policy:
            raise UsageError(f"{out}: arm '{arm}' was run with the policy "
                             f"{have['policies'][arm]}, not {policy}: use another --out")
    if ("demands" in have) != ("demands" in wanted):
        said = "--demands " + ",".join(f"{d:g}" for d in have["demands"]) if "demands" in have \
            else "the scenario's own demand (no --demands)"
        raise UsageError(f"{out} holds an experiment run at {said}: give the same kind, or use another --out")
    merged = dict(have, seed_set=have_set)
    for key in ("arms", "prs", "seeds", "demands"):
        if key in have:
            merged[key] = have[key] + [v for v in wanted[key] if v not in have[key]]
    merged["policies"] = {**have["policies"], **wanted["policies"]}
    # How the points run, not what they measure (the same decisions either way: RSU nodes or
    # in process): the latest call's choice.
    merged["inprocess"] = wanted.get("inprocess", False)
    return merged


def points_of(settings):
    """Every (arm, PR, demand, seed) point; the first seed of each (arm, PR, demand) records
    trajectories for the figures (the others only metrics, to keep the folder small). A
    point's demand is None without --demands (the scenario's own)."""
    pts = []
    for demand in settings.get("demands") or [None]:
        for pr in settings["prs"]:
            for seed in settings["seeds"]:
                for arm in settings["arms"]:
                    pts.append({"name": point_name(arm, pr, seed, demand), "arm": arm, "pr": pr,
                                "seed": seed, "demand": demand,
                                "trajectories": seed == settings["seeds"][0]})
    return pts


def point_command(out, name):
    # PALCAS_NO_BUILD: the repository is built once, not by every point of an array.
    return (f"cd {shlex.quote(str(ROOT))} && PALCAS_NO_BUILD=1 ./palcas experiment --point {shlex.quote(name)} "
            f"--out {shlex.quote(str(out))}")


def point_dir(out, p):
    return out / "points" / p["name"]


def finished(out, p, duration_s):
    """Its run covered the whole duration and (where the runner recorded it) succeeded."""
    status = point_dir(out, p) / "point.json"
    try:
        if status.exists() and json.loads(status.read_text()).get("status") != "done":
            return False
    except ValueError:
        return False
    return metrics_complete(out, p, duration_s)


def metrics_complete(out, p, duration_s):
    m = point_dir(out, p) / p["arm"] / "metrics.json"
    if not m.exists():
        return False
    try:
        d = json.loads(m.read_text())
    except (OSError, ValueError):
        return False
    return float(d.get("sim_seconds", 0.0)) >= duration_s - 1e-6


def last_error(point_log, console):
    """Why a point failed, for its point.json: the command's own error line, else the last
    FATAL/ERROR line of the run's console, else the command's last line."""
    def lines(f):
        try:
            return [re.sub(r"\x1b\[[0-9;]*m", "", l).strip() for l in f.read_text(errors="replace").splitlines()]
        except OSError:
            return []
    own = lines(point_log)
    for line in reversed(own):
        if "error" in line.lower():
            return line[:300]
    for line in reversed(lines(console)):
        if re.search(r"\[(FATAL|ERROR)\]|Assertion|Segmentation", line):
            return line[:300]
    return (own[-1] if own else "no output")[:300]


def point_argv(settings, p, d):
    """./palcas run's command line (after "run") for point p of the experiment, into folder d."""
    argv = ["--arm", p["arm"], "--no-compare", "--pr", f"{p['pr']:g}", "--seed", str(p["seed"]),
            "--duration", f"{settings['duration_s']:g}", "--scenario", settings["scenario"], "--out", str(d)]
    if p["demand"] is not None:
        argv += ["--demand", f"{p['demand']:g}"]
    if p["arm"] in settings["policies"]:
        argv += ["--policy", repo_paths.usable(settings["policies"][p["arm"]])]
    if not p["trajectories"]:
        argv += ["--no-trajectories"]
    if settings.get("inprocess"):
        argv += ["--in-process"]
    for key, option in POINT_FILES:
        if settings.get(key):
            argv += [option, repo_paths.usable(settings[key])]
    return argv


def run_point(out, name):
    """Runs one point with ./palcas run's code, its output in the point's point.log, and writes
    its point.json; returns the exit code (130 / 143 if the experiment was interrupted)."""
    settings = json.loads((out / "experiment.json").read_text())
    pts = {p["name"]: p for p in points_of(settings)}
    if name not in pts:
        raise UsageError(f"{out}: no point '{name}' in this experiment")
    p = pts[name]
    d = point_dir(out, p)
    d.mkdir(parents=True, exist_ok=True)
    argv = point_argv(settings, p, d)
    start = time.time()
    with open(d / "point.log", "w") as log:
        point_console = Console(out=log, err=log)
        try:
            code = run.execute(run.check(argv), point_console, show=None)
        except OptionError as e:
            point_console.error(str(e))
            code = 2
        except Exception:  # noqa: BLE001 - one point's fault fails that point, not the experiment
            log.write(traceback.format_exc())
            code = 1
    wall = time.time() - start
    ok = code == 0 and metrics_complete(out, p, settings["duration_s"])
    record = {"name": name, "arm": p["arm"], "pr": p["pr"], "seed": p["seed"], "demand": p["demand"],
              "status": "done" if ok else "failed", "exit_code": code, "wall_s": round(wall, 1),
              # From the repository's folder; its paths repository-relative where they lie in it.
              "command": shlex.join(["./palcas", "run"] + [repo_paths.recorded(a) if os.path.isabs(a) else a
                                                           for a in argv]),
              "host": os.uname().nodename}
    if not ok:
        record["error"] = last_error(d / "point.log", d / p["arm"] / "console.log")
    tmp = d / "point.json.tmp"
    tmp.write_text(json.dumps(record, indent=1) + "\n")
    tmp.replace(d / "point.json")
    return 0 if ok else code or 1


def write_plan(out, settings):
    pts = points_of(settings)
    lines = [point_command(out, p["name"]) for p in pts]
    (out / "plan.txt").write_text("\n".join(lines) + "\n")
    slurm = out / "slurm_array.sh"
    slurm.write_text(
        "#!/bin/bash\n"
        "# One array task per experiment point: sbatch slurm_array.sh (from any folder).\n"
        "# Every task needs this repository built at the same path (./palcas build) and\n"
        "# SUMO + ROS installed; each starts its own ROS master on a free port.\n"
        f"#SBATCH --job-name=palcas-experiment\n#SBATCH --array=1-{len(lines)}\n"
        "#SBATCH --cpus-per-task=2\n#SBATCH --time=00:30:00\n"
        f"#SBATCH --output={out}/points/slurm-%A_%a.log\n"
        f"mkdir -p {shlex.quote(str(out))}/points\n"
        f"eval \"$(sed -n \"${{SLURM_ARRAY_TASK_ID}}p\" {shlex.quote(str(out / 'plan.txt'))})\"\n")
    slurm.chmod(0o755)
    return len(lines)


def save_settings(out, settings):
    out.mkdir(parents=True, exist_ok=True)
    tmp = out / "experiment.json.tmp"
    tmp.write_text(json.dumps(settings, indent=1) + "\n")
    tmp.replace(out / "experiment.json")


def fmt_time(s):
    s = int(round(s))
    return f"{s // 3600}h{s % 3600 // 60:02d}m" if s >= 3600 else f"{s // 60}m{s % 60:02d}s"


def run_all(out, settings, jobs):
    pts = points_of(settings)
    todo = [p for p in pts if not finished(out, p, settings["duration_s"])]
    done_before = len(pts) - len(todo)
    demands = f"{len(settings['demands'])} demands x " if settings.get("demands") else ""
    print(f"[experiment] {len(pts)} points ({len(settings['arms'])} arms x "
          f"{len(settings['prs'])} PRs x {demands}{len(settings['seeds'])} seeds, "
          f"{settings['duration_s']:g} s each); {done_before} finished before, {len(todo)} to run, "
          f"{jobs} at a time -> {out}", flush=True)
    lock = threading.Lock()
    state = {"done": 0, "failed": [], "running": 0, "walls": {}}
    start = time.time()

    def progress():
        left = len(todo) - state["done"] - len(state["failed"]) - state["running"]
        walls = [w for ws in state["walls"].values() for w in ws]
        per = sum(walls) / len(walls) if walls else None
        eta = f", ~{fmt_time(per * (left + state['running'] / 2) / jobs)} left" if per else ""
        kinds = ", ".join(f"{a} {sum(w) / len(w):.0f} s/point" for a, w in state["walls"].items())
        print(f"[experiment] {done_before + state['done']}/{len(pts)} done, {state['running']} running, "
              f"{left} left, {len(state['failed'])} failed{eta}; elapsed {fmt_time(time.time() - start)}"
              + (f" ({kinds})" if kinds else ""), flush=True)

    def work(p):
        with lock:
            state["running"] += 1
        t0 = time.time()
        code = run_point(out, p["name"])
        with lock:
            state["running"] -= 1
            if code == 0:
                state["done"] += 1
                state["walls"].setdefault(p["arm"], []).append(time.time() - t0)
            else:
                state["failed"].append(p["name"])
                err = json.loads((point_dir(out, p) / "point.json").read_text()).get("error", "")
                print(f"[experiment] FAILED {p['name']}: {err}", flush=True)
            progress()

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = [pool.submit(work, p) for p in todo]
        try:
            for f in futures:
                f.result()
        except (KeyboardInterrupt, SystemExit):
            for f in futures:
                f.cancel()
            launch.stop_all(grace_s=30.0)
            raise
    return state["failed"]


def common_options(p):
    D = options.with_default
    p.add_argument("--arms", default="palcas,keep,sumo_native", metavar="A,B,...",
                   help=D("arms to run (any arm of config/arms.json)", "%(default)s"))
    p.add_argument("--prs", default=",".join(str(x) for x in PAPER_PRS), metavar="P,P,...",
                   help=D("CAV penetration rates [%%]", "the paper's %(default)s"))
    p.add_argument("--demands", default=None, metavar="D,D,...",
                   help=D("mainline demands [veh/h per lane], a dimension beside arms, PRs and seeds; "
                          "--collect then also draws figures/capacity.png", "the scenario's own"))
    p.add_argument("--seeds", type=int, default=3, metavar="N",
                   help=D("the first N seeds of the seed set (a policy's training seeds are refused)",
                          "%(default)s"))
    p.add_argument("--seed-set", dest="seed_set", default=seed_sets.DEFAULT, metavar="dev|test",
                   help=D("a set of config/seeds.yaml: dev (settings are chosen on it) or test (reporting "
                          "only); an experiment folder keeps its set", "%(default)s"))
    p.add_argument("--duration", type=float, default=1800.0, metavar="SECONDS",
                   help=D("simulated time per point", "%(default)g"))
    p.add_argument("--scenario", default="paper", metavar="NAME",
                   help=D("road under config/scenarios", "%(default)s"))
    p.add_argument("--v2x", default="", metavar="FILE",
                   help=D("the V2X channel for every point (./palcas run --v2x)", "off"))
    p.add_argument("--rsu-params", dest="rsu_params", default="", metavar="FILE",
                   help=D("an RSU parameter override for every point (./palcas run --rsu-params)", "none"))
    p.add_argument("--bridge-params", dest="bridge_params", default="", metavar="FILE",
                   help=D("a bridge parameter override for every point (./palcas run --bridge-params)", "none"))
    p.add_argument("--in-process", dest="inprocess", action="store_true",
                   help=D("every point's RSUs inside its bridge process (./palcas run --in-process: the same "
                          "decisions, no wall-time deadline to miss); may change between calls", "off: RSU nodes"))
    p.add_argument("--policy", action="append", metavar="ARM=DIR",
                   help=D("a policy for a learning arm (repeatable)", "policies/<arm>/"))
    p.add_argument("--jobs", type=int, default=os.cpu_count() or 1, metavar="J",
                   help=D("points at a time", "the machine's cores, %(default)s"))


MODES = {"--plan": "plan", "--collect": "collect"}


def parse(argv):
    """./palcas experiment's command line as (mode, options): run, plan, collect or point.
    --help (any mode) lists every option with its default."""
    mode, words = "run", list(argv)
    for word in words:
        if word in MODES:
            mode = MODES[word]
        elif word == "--point" or word.startswith("--point="):
            mode = "point"
    if "-h" in words or "--help" in words:
        mode = "run"  # the whole list of options
    ap = options.Parser("experiment", description=__doc__)
    D = options.with_default
    ap.add_argument("--out", required=True, metavar="DIR",
                    help=D("the experiment folder; run the same command again to continue", "none: required"))
    ap.add_argument("--plan", action="store_true",
                    help=D("write DIR/plan.txt (a command per point) and DIR/slurm_array.sh only", "off"))
    ap.add_argument("--collect", action="store_true",
                    help=D("tables and figures from DIR's point folders, wherever they ran", "off"))
    ap.add_argument("--point", dest="name", metavar="NAME",
                    help=D("run one planned point (what plan.txt calls)", "none"))
    if mode in ("run", "plan"):
        common_options(ap)
    a, extra = ap.parse_known_args(words)
    for word in extra:
        ap.unknown(word)
    return mode, a


def check(argv):
    """The experiment's mode, options and settings, checked against DIR's (nothing written);
    raises UsageError."""
    mode, a = parse(argv)
    out = pathlib.Path(a.out).resolve()
    if mode in ("collect", "point"):
        if not (out / "experiment.json").exists():
            raise UsageError(f"{out}: no experiment.json, not an experiment folder" if mode == "collect"
                             else f"{out}: no experiment.json (run 'plan' first)")
        return mode, a, out, None
    if a.jobs < 1:
        raise UsageError(f"--jobs: {a.jobs} must be >= 1")
    return mode, a, out, merge_settings(out, settings_from_args(a))


def needs_workspace(argv):
    """Planning and collecting run nothing: no build."""
    return check(argv)[0] in ("run", "point")


def main(argv):
    try:
        return experiment(*check(argv))
    except KeyboardInterrupt:
        print("[palcas] interrupted: finished points are kept; rerun the same command to "
              "continue", file=sys.stderr)
        return 130


def experiment(mode, a, out, settings):
    if mode == "point":
        launch.handle_signals()
        code = run_point(out, a.name)
        return launch.Interrupted(launch.interrupted()).status if launch.interrupted() else code
    if mode == "collect":
        settings = json.loads((out / "experiment.json").read_text())
        return experiment_results.collect(out, settings, points_of(settings))
    save_settings(out, settings)
    n = write_plan(out, settings)
    if mode == "plan":
        print(f"[experiment] {n} point commands in {out / 'plan.txt'}; Slurm: sbatch "
              f"{out / 'slurm_array.sh'}; afterwards: ./palcas experiment --collect --out {out}")
        return 0
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # SystemExit: the points are stopped
    failed = run_all(out, settings, a.jobs)
    code = experiment_results.collect(out, settings, points_of(settings))
    if failed:
        print(f"[palcas] error: {len(failed)} point(s) failed: {', '.join(failed)} "
              f"(see their point.json; rerun the same command to retry them)", file=sys.stderr)
        return 1
    return code
