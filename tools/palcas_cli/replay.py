"""./palcas replay: a policy's RSUs open loop on a recorded episode (palcas_rsu's
replay_policy), or the recorded episode played into rviz (--rviz).

The RSU parameters are read from a parameter server as the node reads them, so a private
master on a free port holds them for the replay's lifetime only."""
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

from palcas_cli import Console, ROOT, launch, options
from palcas_cli.options import OptionError

VALUES = {"--rate": "rate", "--policy": "policy", "--csv": "csv", "--learning": "learning",
          "--rsu-params": "rsu_params", "--accel-tolerance": "tolerance"}
FLAGS = {"--rviz": ("rviz", True), "--paper-printed": ("paper_printed", True)}
D = options.with_default
# --help: each option's METAVAR (None for a flag) and what it does, with its default.
HELPS = {
    "BAG": (None, "the recorded episode (./palcas run --record: <run>/<arm>/episode.bag)"),
    "--policy": ("DIR", D("a training's checkpoints/ folder, a policy folder holding one, or a ./palcas train "
                          "folder (its learning override comes along); required without --rviz", "none")),
    "--csv": ("FILE", D("the disagreements", "BAG's name with .replay.csv")),
    "--learning": ("FILE", D("the \"learning:\" override the policy was trained with",
                             "the train folder's, else none")),
    "--rsu-params": ("FILE", D("an RSU parameter override the recorded run used", "none")),
    "--paper-printed": (None, D("the recorded run used paper_printed:=true", "off, or the train folder's")),
    "--accel-tolerance": ("X", D("ACCELERATE advisories agree within X m/s^2", "0.001")),
    "--rviz": (None, D("play the bag (and episode_view.bag beside it) into rviz instead; takes only --rate",
                       "off")),
    "--rate": ("X", D("with --rviz: X times as fast as simulated time", "1")),
}
DESCRIPTION = ("replay BAG --policy DIR: the policy's RSUs decide open loop on the vehicle and cluster states "
               "recorded\nin BAG, and their advisories are compared with the recorded ones (exits 0 whenever "
               "it ran).\nreplay BAG --rviz [--rate X]: the bag played into rviz on the run's framed view.")
# Per RSU or per run, set again by the replay itself or meaningless in it.
NOT_REPLAYED = ("checkpoint_dir", "resume", "policy_dir", "auth_key_file")
NS = "/replay_policy/"


def check(argv):
    """The replay's options, checked; raises OptionError."""
    bags = []

    def bag_word(word):
        if bags:
            raise OptionError("replay: one bag only ('%s', then '%s')" % (bags[0], word))
        bags.append(word)

    o = options.parse("replay", argv, VALUES, FLAGS, positional=bag_word, helps=HELPS, description=DESCRIPTION,
                      positional_name="BAG")
    if not bags:
        raise OptionError("replay: no bag given (./palcas replay BAG --policy DIR)")
    o["bag"] = bags[0]
    if not os.path.isfile(o["bag"]):
        raise OptionError("replay: bag '%s': no such file" % o["bag"])
    if o.get("rate"):
        o["rate"] = options.number_in("--rate", o["rate"], 0, 1000, open_low=True)
        if not o.get("rviz"):
            raise OptionError("--rate goes with --rviz")
    if o.get("rviz"):
        if any(o.get(k) for k in ("policy", "csv", "learning", "rsu_params", "paper_printed", "tolerance")):
            raise OptionError("replay --rviz shows the bag; it takes only --rate (replay with --policy separately)")
        return o
    policy = o.get("policy")
    if not policy:
        raise OptionError("replay: --policy DIR is required (a training's checkpoints/ folder or a policy folder)")
    if not os.path.isdir(policy):
        raise OptionError("--policy '%s': no such folder" % policy)
    if o.get("tolerance"):
        o["tolerance"] = options.number_in("--accel-tolerance", o["tolerance"], 0, None)
    for key, option in (("learning", "--learning"), ("rsu_params", "--rsu-params")):
        o[key] = options.file_ok(option, o[key]) if o.get(key) else ""
    csv_folder = os.path.dirname(o.get("csv") or "x") or "."
    if o.get("csv") and not os.path.isdir(csv_folder):
        raise OptionError("--csv '%s': no folder %s" % (o["csv"], csv_folder))
    # A ./palcas train folder says how its networks were built and which constants it ran with.
    if os.path.isfile(os.path.join(policy, "train.json")):
        o["learning"] = o["learning"] or options.policy_learning("--policy", policy)
        o["paper_printed"] = o.get("paper_printed") or options.trained_paper_printed(policy)
    return o


def main(argv, console=None):
    o = check(argv)
    console = console or Console()
    if o.get("rviz"):
        replay_rviz(o["bag"], o.get("rate") or "1", console)
    # The RSU parameters: those the bag recorded (/rsu_params), else the shipped files in
    # rsu.launch's order; --learning and --rsu-params go on top of either.
    cfg = ROOT / "config"
    files = [str(cfg / f) for f in ("rsu.yaml", "reward.yaml", "learning.yaml")]
    if not o.get("paper_printed"):
        files.append(str(cfg / "departures.yaml"))
    overlays = [f for f in (o["learning"], o["rsu_params"]) if f]
    port = launch.free_port()
    master_log = tempfile.mkdtemp(prefix="palcas_replay.")
    os.environ.update(launch.ros_env(port, master_log))  # the master this process and replay_policy use
    # SIGTERM ends the replay like Ctrl-C: replay_policy stopped, the master and its logs removed.
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    with open(os.path.join(master_log, "rosmaster.log"), "w") as log:
        master = subprocess.Popen(["setpriv", "--pdeathsig", "TERM", "rosmaster", "--core", "-p", str(port)],
                                  stdout=log, stderr=subprocess.STDOUT)
    try:
        try:
            load_rsu_params(o["bag"], files, overlays, console)
        except Exception as e:  # noqa: BLE001 - any failure to load is the same failed replay
            console.error("could not load the RSU parameters into the replay's master (%s)" % e)
            return 1
        args = [o["bag"], "--policy", o["policy"]]
        if o.get("csv"):
            args += ["--csv", o["csv"]]
        if o.get("tolerance"):
            args += ["--accel-tolerance", o["tolerance"]]
        return subprocess.run([str(ROOT / "devel" / "lib" / "palcas_rsu" / "replay_policy")] + args
                              + ["__name:=replay_policy"]).returncode
    finally:
        master.terminate()
        master.wait()
        shutil.rmtree(master_log, ignore_errors=True)


def load_rsu_params(bag_path, files, overlays, console):
    """The RSU parameters into the master, under replay_policy's namespace: as the bag recorded
    them (/rsu_params, its first RSU's), else the config FILES; OVERLAYS on top of either."""
    import rosgraph
    import rosparam
    recorded = None
    try:
        import rosbag
        with rosbag.Bag(bag_path) as bag:
            for _, msg, _ in bag.read_messages(topics=["/rsu_params"]):
                recorded = json.loads(msg.data)
                break
    except Exception:  # noqa: BLE001 - not a bag, or an older one: replay_policy says what is wrong
        pass
    deadline = time.time() + 30
    while not rosgraph.is_master_online():
        if time.time() > deadline:
            raise RuntimeError("no master after 30 s")
        time.sleep(0.1)
    if recorded:
        rsu_id = sorted(recorded)[0]
        params = {k: v for k, v in recorded[rsu_id].items() if k not in NOT_REPLAYED}
        rosparam.upload_params(NS, params, verbose=False)
        console.log("RSU parameters: as recorded in the bag (/rsu_params, %s's)%s" % (
            rsu_id, ", then " + ", ".join(overlays) if overlays else ""))
    else:
        console.log("RSU parameters: the bag has no /rsu_params; config files %s" % " ".join(files + overlays))
    for f in ([] if recorded else files) + overlays:
        for params, ns in rosparam.load_file(f, default_namespace=NS):
            rosparam.upload_params(ns, params, verbose=False)


def replay_rviz(bag, rate, console):
    """The bag (and episode_view.bag beside it) played into rviz on the view the bridge framed
    for that run, on a private master; ends when the bag does (this process becomes roslaunch)."""
    bag = os.path.abspath(bag)
    run = os.path.dirname(bag)
    view, config = "none", str(ROOT / "config" / "rviz" / "palcas.rviz")
    if os.path.isfile(os.path.join(run, "episode_view.bag")):
        view = os.path.join(run, "episode_view.bag")
    else:
        console.log("note: no episode_view.bag beside %s: the markers are in the bag itself if it was recorded "
                    "with them, else rviz stays empty" % bag)
    if os.path.isfile(os.path.join(run, "palcas.rviz")):
        config = os.path.join(run, "palcas.rviz")  # framed on that run's road
    port = launch.free_port()
    env = launch.ros_env(port)
    os.execvpe("setpriv", ["setpriv", "--pdeathsig", "INT", "roslaunch", "-p", str(port), "palcas_launch",
                           "replay.launch", "bag:=" + bag, "view_bag:=" + view, "config:=" + config,
                           "rate:=" + rate], env)
