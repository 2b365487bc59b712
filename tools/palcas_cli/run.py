"""./palcas run: every arm on the same traffic, one launch each, one metric table.

check(argv) reads and checks the options (OptionError: exit 2, nothing made) into a plan;
execute(plan, console) runs it in the built, sourced workspace and returns the exit status:
1 if any arm gave no result, and an arm whose nodes died for good gives none. ./palcas
experiment calls both for each of its points."""
import os
import threading
import time
import traceback
import warnings

from palcas_cli import Console, ROOT, launch, options
from palcas_cli.options import OptionError
from palcas_cli.rviz_window import RvizWindow
import add_training_facts
import metrics_table
import palcas_arms
import policy_folder

VALUES = {"--duration": "duration", "--pr": "pr", "--demand": "demand", "--ramp-demand": "ramp_demand",
          "--seed": "seed", "--real-time-factor": "real_time_factor", "--out": "out", "--policy": "policy",
          "--scenario": "scenario", "--arm": "arm", "--bridge-params": "bridge_params", "--rsu-params": "rsu_params", "--v2x": "v2x",
          "--sumo-output": "sumo_outputs"}
FLAGS = {"--gui": ("gui", True), "--rviz": ("rviz", True), "--record": ("record", True),
         "--no-compare": ("compare", False), "--no-trajectories": ("trajectory_steps", 0),
         "--in-process": ("inprocess", True)}
DEFAULTS = {"duration": "1800", "pr": "60", "seed": "101", "gui": False, "rviz": False, "record": False,
            "compare": True, "trajectory_steps": 10, "inprocess": False}
D = options.with_default
# --help: each option's METAVAR (None for a flag) and what it does, with its default.
HELPS = {
    "--arm": ("A", D("only this arm (plus keep and sumo_native to compare); a learning arm's policy comes "
                     "from policies/<A>/ or --policy", "palcas, with the shipped policy")),
    "--policy": ("DIR", D("evaluate this trained policy (a ./palcas train folder) instead", "policies/<arm>/")),
    "--no-compare": (None, D("leave out the keep and sumo_native columns", "off: they are compared")),
    "--duration": ("SECONDS", D("simulated time per arm", DEFAULTS["duration"])),
    "--pr": ("PERCENT", D("CAV penetration rate in [0, 100]", DEFAULTS["pr"])),
    "--demand": ("VPHPL", D("mainline demand [veh/h per lane] in [0, %d]" % options.MAX_DEMAND,
                            "the scenario's mainline_flow_vphpl")),
    "--ramp-demand": ("VPH", D("on-ramp demand [veh/h per ramp] in [0, %d]" % options.MAX_DEMAND,
                               "the scenario's onramp_flow_vphpl")),
    "--seed": ("N", D("random seed; the shipped policies never trained on 101", DEFAULTS["seed"])),
    "--scenario": ("NAME", D("road under config/scenarios, or an absolute path to a folder with scenario.yaml",
                             "the policy's road, else paper")),
    "--out": ("DIR", D("run folder", "results/run-<time>-pr<P>-d<demand>-s<N>")),
    "--gui": (None, D("attach an external sumo-gui through libtraci; the last arm's window stays open on its "
                      "final state until you close it", "off")),
    "--rviz": (None, D("watch each arm in rviz, framed on its road; the last arm's window stays open until "
                       "you close it", "off")),
    "--real-time-factor": ("X", D("simulate at most X times faster than wall time (X > 0)",
                                  "1 with --rviz, else as fast as possible")),
    "--record": (None, D("record a rosbag of each run into its folder", "off")),
    "--no-trajectories": (None, D("record no trajectories.csv / decisions.csv (and draw no figures)",
                                  "off: every %d steps" % DEFAULTS["trajectory_steps"])),
    "--in-process": (None, D("run the RSUs inside the bridge process (the same decision code, a call per step "
                             "instead of ROS topics; same results; on two cores no faster, as measured)", "off: one RSU node per zone")),
    "--bridge-params": ("FILE", D("a bridge parameter override for every arm", "none")),
    "--rsu-params": ("FILE", D("an RSU parameter override for every RSU (e.g. a rules: map over "
                               "config/rules.yaml)", "none")),
    "--v2x": ("FILE", D("the V2X channel over config/v2x.yaml (e.g. config/v2x/impaired_100ms_10pct.yaml)",
                        "off")),
    "--sumo-output": ("NAMES", D("SUMO's own outputs into each arm's folder as sumo_<name>.xml, comma-separated "
                                 "(repeatable): " + " ".join(options.SUMO_OUTPUTS), "config/bridge.yaml's")),
}
DESCRIPTION = ("Every arm on the same traffic, one launch each: the shipped trained policy, keep and "
               "sumo_native;\none metric table with a column per arm. Exits non-zero if any arm wrote no "
               "metrics.json.")
# matplotlib draws one figure at a time in a process (an experiment runs points in threads).
FIGURES_LOCK = threading.Lock()


class Plan(dict):
    """The checked options of a run, and what follows from them (arms, policy, road)."""
    __getattr__ = dict.__getitem__


def check(argv):
    """The run's plan from its command line; raises OptionError naming a bad option."""
    given = options.parse("run", argv, VALUES, FLAGS, joined=("sumo_outputs",), helps=HELPS,
                          description=DESCRIPTION)
    p = Plan(DEFAULTS, **given)
    p["command_line"] = "./palcas run " + " ".join(argv)
    p["duration"] = options.number_in("--duration", p.duration, 0, None, open_low=True)
    p["pr"] = options.number_in("--pr", p.pr, 0, 100)
    for key, option in (("demand", "--demand"), ("ramp_demand", "--ramp-demand")):
        p[key] = options.number_in(option, p[key], 0, options.MAX_DEMAND) if p.get(key) else ""
    p["seed"] = options.integer_in("--seed", p.seed, 0, options.MAX_SEED)
    # The bridge's range; 0 (as fast as possible) is the default without rviz, not an option.
    if p.get("real_time_factor"):
        p["real_time_factor"] = options.number_in("--real-time-factor", p.real_time_factor, 0, 1000, open_low=True)
    else:
        p["real_time_factor"] = "1" if p.rviz else "0"  # with rviz: as fast as the traffic on the road
    if p.get("scenario"):
        options.scenario_ok("--scenario", p.scenario)
    options.out_ok(p.get("out"))
    for key, option in (("bridge_params", "--bridge-params"), ("rsu_params", "--rsu-params"), ("v2x", "--v2x")):
        p[key] = options.file_ok(option, p[key]) if p.get(key) else ""
    p["sumo_outputs"] = options.sumo_outputs_ok(p.sumo_outputs) if p.get("sumo_outputs") else ""
    arm = options.known_arm(p.arm, palcas_arms.ALL_ARMS) if p.get("arm") else ""
    p.update(choose_policy(p, arm))
    p["scenario"] = p.get("scenario") or "paper"
    # The columns, all on the same traffic: the learning arm, then keep and sumo_native.
    # A control arm (no learned policy) is its own column, like a policy's.
    arms = [p.arm] if p.policy or (arm and arm not in ("keep", "sumo_native")) else []
    arms += [a for a in ("keep", "sumo_native") if p.compare or p.arm == a]
    if not arms:
        raise OptionError("--no-compare: nothing to run, policies/palcas/ is missing (pass --arm or --policy DIR)")
    p["arms"] = arms
    return p


def choose_policy(p, arm):
    """A learning arm evaluates --policy, else its shipped policy under policies/<arm>/:
    {policy, arm, learning, paper_printed, missing, scenario} (policy "" = no learning arm)."""
    policy, label, missing = p.get("policy", ""), "--policy", ""
    if policy:
        if not palcas_arms.is_learning(arm or "palcas"):
            raise OptionError("--policy '%s': arm '%s' learns nothing (--policy goes with %s)"
                              % (policy, arm, options.arms_text(palcas_arms.LEARNING_ARMS)))
    elif not arm or palcas_arms.is_learning(arm):
        shipped, label = "policies/" + (arm or "palcas"), "shipped policy"
        if (ROOT / shipped).exists():
            policy = str(ROOT / shipped)
        elif arm:
            raise OptionError("--arm %s: no trained policy in %s/ (train one with ./palcas train --arm %s, then "
                              "--policy DIR)" % (arm, shipped, arm))
        else:
            missing = ("no palcas column: the shipped policy %s/ (train.json + checkpoints/) is missing; train "
                       "one with ./palcas train, or pass --policy DIR" % shipped)
    chosen = {"policy": "", "arm": arm, "learning": "", "paper_printed": "false", "missing": missing,
              "scenario": p.get("scenario", "")}
    if not policy:
        return chosen
    policy = options.policy_ok(label, policy)
    trained = options.train_field(policy, "arm")
    if not palcas_arms.is_learning(trained):
        raise OptionError("%s '%s': its train.json names no learning arm ('%s')" % (label, policy, trained))
    if arm and arm != trained:
        raise OptionError("%s '%s' was trained for arm %s, not --arm %s" % (label, policy, trained, arm))
    chosen.update(policy=policy, arm=trained, learning=options.policy_learning(label, policy))
    options.bridge_yaml_ok(label, policy)
    options.rsu_yaml_ok(label, policy)
    learnt_on = options.train_field(policy, "scenario")
    if not chosen["scenario"]:  # the road it learnt on
        chosen["scenario"] = options.scenario_ok("%s '%s': its train.json scenario" % (label, policy), learnt_on)
    elif chosen["scenario"] != learnt_on:
        # Another road is fine only if the networks fit it (same state size).
        need, have = state_size(chosen["scenario"]), state_size(learnt_on)
        if need != have:
            raise OptionError("--scenario %s: its state has %s features, the %s '%s' was trained on road %s with %s"
                              % (chosen["scenario"], need, label, policy, learnt_on, have))
    # A policy trained on the printed paper is evaluated, with keep beside it, the same way.
    chosen["paper_printed"] = "true" if options.trained_paper_printed(policy) else "false"
    return chosen


def state_size(scenario):
    try:
        return options.scenario_state_size(scenario)
    except (OSError, KeyError, TypeError, ValueError):
        return ""  # a road that cannot be read fits no policy


def execute(p, console=None, show=launch.SHOWN):
    """Runs the plan's arms in the sourced workspace; console lines matching SHOW (None:
    none) go to console.out. Returns the exit status."""
    console = console or Console()
    rviz = RvizWindow(console)
    try:
        status = run_arms(p, console, show, rviz)
        if launch.interrupted():  # stopped after its last launch: not a whole run either
            raise launch.Interrupted(launch.interrupted())
        return status
    except launch.Interrupted as stop:
        rviz.close()
        console.log("interrupted (%s): every node of this run stopped" % stop.signal)
        return stop.status


def run_arms(p, console, show, rviz):
    # The run folder names its demand: the one given, else the scenario's own.
    demand = p.demand or options.scenario_demand(p.scenario)
    label = demand + ("-r" + p.ramp_demand if p.ramp_demand else "")
    out = p.get("out") or os.path.join(options.results_dir(), "run-%s-pr%s-d%s-s%d" % (
        time.strftime("%Y%m%d-%H%M%S"), p.pr, label, p.seed))
    os.makedirs(out, exist_ok=True)
    out = os.path.abspath(out)
    try:
        auth_key = launch.message_key(out)
    except OSError as e:
        console.error("cannot write the message key %s/auth.key (%s)" % (out, e))
        return 1
    common = ["pr:=" + p.pr, "demand:=" + (p.demand or "scenario"), "ramp_demand:=" + (p.ramp_demand or "scenario"),
              "seed:=%d" % p.seed, "duration:=" + p.duration, "gui:=" + flag(p.gui), "rviz:=false",
              "record:=" + flag(p.record), "trajectory_period_steps:=%d" % p.trajectory_steps,
              "real_time_factor:=" + p.real_time_factor, "auth_key_file:=" + auth_key,
              "bridge_params:=" + (p.bridge_params or "none"), "rsu_params:=" + (p.rsu_params or "none"),
              "v2x_params:=" + (p.v2x or "none"), "inprocess:=" + flag(p.inprocess),
              "sumo_outputs:=" + (p.sumo_outputs or "config"), "scenario:=" + p.scenario,
              "git_commit:=" + launch.git_commit(), "command_line:=" + p.command_line]
    if p.missing:
        console.log("note: " + p.missing)
    console.log("running %s: pr=%s%% demand=%s veh/h/lane%s seed=%d duration=%ss scenario=%s -> %s/<arm>" % (
        " ".join(p.arms), p.pr, demand, " (ramps %s veh/h)" % p.ramp_demand if p.ramp_demand else "", p.seed,
        p.duration, p.scenario, out))
    tables, failed = [], []
    for arm in p.arms:
        folder = os.path.join(out, arm)
        metrics = os.path.join(folder, "metrics.json")
        os.makedirs(folder, exist_ok=True)
        remove(metrics)  # a stale file must not stand for a failed run
        args = ["palcas_launch", "system.launch", "arm:=" + arm] + common
        if p.gui:  # one window left open: the last arm's
            args.append("gui_quit_on_end:=" + flag(arm != p.arms[-1]))
        if palcas_arms.is_learning(arm):
            console.log("%s: evaluating the policy %s -> %s" % (arm, p.policy, folder))
            # A policy folder's bridge.yaml (tools/ship_policy.py) is how that policy is run.
            own_bridge = "none"
            if policy_folder.bridge_params(p.policy).is_file():
                own_bridge = str(policy_folder.bridge_params(p.policy))
                console.log("%s: under the policy's own bridge parameters %s%s" % (
                    arm, own_bridge, ", then " + p.bridge_params if p.bridge_params else ""))
            # Its rsu.yaml likewise, for its RSUs (after config/departures.yaml, before --rsu-params).
            own_rsu = "none"
            if policy_folder.rsu_params(p.policy).is_file():
                own_rsu = str(policy_folder.rsu_params(p.policy))
                console.log("%s: under the policy's own RSU parameters %s%s" % (
                    arm, own_rsu, ", then " + p.rsu_params if p.rsu_params else ""))
            args += ["mode:=eval", "policy_dir:=%s/checkpoints" % p.policy, "out_dir:=" + folder,
                     "learning_params:=" + p.learning, "paper_printed:=" + p.paper_printed,
                     "policy_bridge_params:=" + own_bridge, "policy_rsu_params:=" + own_rsu]
        else:
            console.log("%s -> %s" % (arm, folder))
            advised = palcas_arms.ARMS.get(arm, {}).get("advisory_control", False)
            args += ["out_dir:=" + folder] + (["paper_printed:=" + p.paper_printed] if advised else [])
        launch_arm(args, folder, p.rviz, rviz, console, show)
        if palcas_arms.is_learning(arm) and os.path.isfile(metrics):
            add_training_facts.main(metrics, p.policy)
        if p.record:
            report_recording(arm, folder, console)
        console_text = launch.read_text(os.path.join(folder, "console.log"))
        died = launch.node_deaths(console_text)
        if died:
            # A node that died for good leaves a run of the wrong system: not a result.
            console.error("the %s run (seed %d, PR %s%%) lost %s; last error: %s" % (
                arm, p.seed, p.pr, ", ".join(died), launch.last_fatal(console_text)))
            if os.path.isfile(metrics):
                os.replace(metrics, os.path.join(folder, "metrics.invalid.json"))
            failed.append(arm)
        elif os.path.isfile(metrics):
            tables.append(metrics)
        else:
            failed.append(arm)
    if tables:
        console.out.write(metrics_table.table(tables))
        console.out.flush()
    if p.trajectory_steps > 0 and tables:
        # The paper's figures of this run, from the files it recorded (redraw: tools/run_figures.py).
        if draw_figures(out):
            console.log("figures: %s/figures (speed over time, space-time, acceleration, lane changes, "
                        "decision times)" % out)
        else:
            console.log("warning: figures failed (see %s/figures.log)" % out)
    if p.missing:
        console.log("note: " + p.missing)
    console.log("results: %s (per arm: metrics.json, manifest.json, console.log, trajectories.csv, decisions.csv)"
                % out)
    for arm in failed:
        # The cause on the terminal (a SUMO assertion abort names its assertion), not only in the log.
        cause = launch.last_fatal(launch.read_text(os.path.join(out, arm, "console.log")))
        console.error("the %s run (seed %d, PR %s%%) gave no result%s (see %s/%s/console.log)" % (
            arm, p.seed, p.pr, ": " + cause if cause else "", out, arm))
    rviz.wait_until_closed()
    return 1 if failed else 0


def flag(value):
    return "true" if value else "false"


def remove(path):
    try:
        os.remove(path)
    except FileNotFoundError:
        pass


def launch_arm(args, folder, with_rviz, rviz, console, show):
    """One arm's launch; with --rviz its window opens on this launch's master once the bridge
    has framed the road (each arm is shown on its own master)."""
    rviz.close()
    remove(os.path.join(folder, "palcas.rviz"))  # rviz waits for this run's view, never a stale one
    for attempt in range(launch.PORT_ATTEMPTS):
        # The free port is chosen before roscore binds it: another launch (an experiment's
        # other job, a test) may take it between the two; then nothing ran, start again.
        arm_launch = launch.Launch(args, os.path.join(folder, "console.log"), os.path.join(folder, "ros_log"),
                                   append=attempt > 0, show=show, shown=console.out).start()
        if with_rviz:
            rviz.watch(folder, arm_launch.port)
        arm_launch.wait(tick=rviz.poll)
        if not arm_launch.lost_its_port():
            return
        console.log("the master's port %d was taken before roslaunch bound it: starting again" % arm_launch.port)


def draw_figures(out):
    """run_figures.py's figures of this run into <out>/figures; its warnings or error in
    <out>/figures.log. False if there was nothing to draw or drawing failed."""
    with FIGURES_LOCK, open(os.path.join(out, "figures.log"), "w") as log:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                import run_figures
                drawn = run_figures.figures_for_run(out, os.path.join(out, "figures"))
                if not drawn:
                    log.write("run_figures: %s has no <arm>/trajectories.csv or decisions.csv\n" % out)
            except Exception:  # noqa: BLE001 - a figure that fails is a warning, not a failed run
                drawn = []
                log.write(traceback.format_exc())
        for w in caught:
            log.write(warnings.formatwarning(w.message, w.category, w.filename, w.lineno))
    return bool(drawn)


def report_recording(arm, folder, console):
    """After a recorded run: how many steps' /vehicle_states the bag holds against the steps the
    bridge simulated (metrics.json "steps"), i.e. what rosbag record dropped; also written to
    <folder>/recording.json. Says so when the bag is missing or unfinished."""
    import json
    bag_path = os.path.join(folder, "episode.bag")
    if not os.path.exists(bag_path):
        active = " (only episode.bag.active: the recorder did not finish)" if os.path.exists(bag_path + ".active") else ""
        console.log("%s: no episode.bag%s" % (arm, active))
        return
    try:
        import rosbag
        try:
            with open(os.path.join(folder, "metrics.json")) as f:
                steps = json.load(f).get("steps")
        except (OSError, ValueError):
            steps = None
        first = last = None
        count = 0
        with rosbag.Bag(bag_path) as bag:
            topics = bag.get_type_and_topic_info().topics
            for _, msg, _ in bag.read_messages(topics=["/vehicle_states"]):
                count += 1
                first = msg.step if first is None else first
                last = msg.step
            advisories = topics["/advisories"].message_count if "/advisories" in topics else 0
    except Exception as e:  # noqa: BLE001 - an unreadable bag is reported, the run stands
        console.log("%s: cannot read episode.bag (%s)" % (arm, e))
        return
    span = (last - first + 1) if count else 0
    # The bridge publishes the initial state (step 0) and one after every simulated step.
    published = steps + 1 if steps is not None else None
    facts = {"bag": "episode.bag", "vehicle_states_recorded": count, "steps_simulated": steps,
             "vehicle_states_published": published,
             "dropped_vs_published": (published - count) if published is not None else None,
             "first_step": first, "last_step": last, "gaps_within_recorded_steps": span - count,
             "advisories_recorded": advisories}
    with open(os.path.join(folder, "recording.json"), "w") as f:
        json.dump(facts, f, indent=1)
    published_text = ("%d published (steps 0-%d)" % (published, steps) if published is not None
                      else "? published (no metrics.json)")
    dropped = facts["dropped_vs_published"]
    console.log("%s: episode.bag holds %d /vehicle_states of %s: %s dropped by recording "
                "(%d missing inside the recorded steps %s-%s); recording.json" % (
                    arm, count, published_text, dropped if dropped is not None else "?", span - count, first, last))


def main(argv, console=None):
    plan = check(argv)
    launch.handle_signals()
    return execute(plan, console, show=os.environ.get("PALCAS_SHOW") or launch.SHOWN)
