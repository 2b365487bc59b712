"""The parameter tree of one palcas_env environment, assembled as system.launch assembles it
for the bridge (launch/bridge.launch) and each RSU (launch/rsu.launch): the same YAML files
in the same order, then the same single parameters. The C++ side reads it with the nodes'
own loaders (loadBridgeOptions, loadRsuNodeOptions), so a key, default or range is checked
exactly as in `./palcas run`."""
import json
import os

import yaml

BRIDGE_NS = "/palcas_sumo_bridge"


def _package_dir(name, fallback):
    """A catkin package's folder: through rospkg (the sourced workspace), else the source
    tree this module was built from."""
    try:
        import rospkg
        return rospkg.RosPack().get_path(name)
    except Exception:  # rospkg missing or the workspace not sourced
        return fallback


_HERE_SOURCE = os.environ.get("PALCAS_SOURCE_DIR", "")


def repo_root():
    """The repository (the catkin source space): PALCAS_SOURCE_DIR, else palcas_config's parent."""
    if _HERE_SOURCE:
        return _HERE_SOURCE
    return os.path.dirname(_package_dir("palcas_config", ""))


def config_dir():
    return _package_dir("palcas_config", os.path.join(repo_root(), "config"))


def policies_dir():
    return _package_dir("palcas_policies", os.path.join(repo_root(), "policies"))


def _load_yaml(path):
    with open(path) as f:
        data = yaml.safe_load(f)
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ValueError("%s: not a mapping of parameters" % path)
    return data


def _put(tree, ns, data):
    """rosparam load: every leaf of `data` under `ns`, later loads overriding leaves."""
    for key, value in data.items():
        name = ns.rstrip("/") + "/" + str(key)
        if isinstance(value, dict):
            _put(tree, name, value)
        else:
            tree[name] = value


def _overrides(value, what):
    """A dict of parameters, or a YAML file of them, or None."""
    if value is None:
        return {}
    if isinstance(value, dict):
        return value
    if isinstance(value, (str, os.PathLike)):
        return _load_yaml(value)
    raise TypeError("config[%r] must be a dict of parameters or a YAML file, not %r" % (what, type(value).__name__))


def scenario_folder(scenario):
    """A road under config/scenarios/ by name, or a folder with a scenario.yaml."""
    folder = scenario if os.path.isabs(str(scenario)) else os.path.join(config_dir(), "scenarios", str(scenario))
    if not os.path.isfile(os.path.join(folder, "scenario.yaml")):
        known = sorted(d for d in os.listdir(os.path.join(config_dir(), "scenarios"))
                       if os.path.isfile(os.path.join(config_dir(), "scenarios", d, "scenario.yaml")))
        raise ValueError("scenario %r: no scenario.yaml there (roads: %s, or an absolute folder)" % (scenario, ", ".join(known)))
    return folder


def arm_entry(arm):
    with open(os.path.join(config_dir(), "arms.json")) as f:
        arms = json.load(f)
    if arm not in arms:
        raise ValueError("arm %r is not in config/arms.json (%s)" % (arm, ", ".join(sorted(arms))))
    return arms[arm]


def policy_folder(policy, arm):
    """'shipped' = policies/<arm>/; else the folder as given (None = no policy)."""
    if policy is None:
        return None
    folder = os.path.join(policies_dir(), arm) if policy == "shipped" else str(policy)
    if not os.path.isdir(folder):
        raise ValueError("policy folder %r does not exist" % folder)
    return folder


def _policy_learning(folder):
    """The learning: override the policy was trained with (train.json), or None."""
    train = os.path.join(folder, "train.json")
    if not os.path.isfile(train):
        return None
    with open(train) as f:
        learning = json.load(f).get("learning") or ""
    if not learning:
        return None
    if not os.path.isabs(learning):
        learning = os.path.join(repo_root(), learning)
    own_copy = os.path.join(folder, os.path.basename(learning))
    if not os.path.isfile(learning) and os.path.isfile(own_copy):
        learning = own_copy
    if not os.path.isfile(learning):
        raise ValueError("policy %r: its learning override %r (train.json) is missing" % (folder, learning))
    return learning


def build(scenario, arm, mode, pr, demand, ramp_demand, seed, duration_s, out_dir, policy, reproducible, config):
    """(tree, rsu_ids): the parameters of the bridge and of every RSU of `arm`."""
    if mode not in ("train", "eval"):
        raise ValueError("mode %r: train or eval" % (mode,))
    if reproducible is None:
        reproducible = mode == "eval"  # as system.launch
    config = dict(config or {})
    unknown = set(config) - {"bridge", "rsu"}
    if unknown:
        raise ValueError("config keys %s: only 'bridge' and 'rsu' (dicts of parameters or YAML files)" % sorted(unknown))
    cfg = config_dir()
    folder = scenario_folder(scenario)
    entry = arm_entry(arm)
    scenario_yaml = _load_yaml(os.path.join(folder, "scenario.yaml"))
    clusters = int(scenario_yaml.get("road", {}).get("clusters", 3))
    rsus = entry.get("rsus", "none")
    rsu_ids = ["central"] if rsus == "central" else ["rsu_%d" % k for k in range(clusters)] if rsus == "zones" else []
    if rsu_ids and entry.get("advice") != "network":
        raise ValueError("arm %r advises by rule; palcas_env's caller gives the advice: choose a learning arm" % arm)
    pfolder = policy_folder(policy, arm)
    seed = int(seed)

    tree = {}
    b = BRIDGE_NS
    _put(tree, b, _load_yaml(os.path.join(cfg, "bridge.yaml")))
    _put(tree, b + "/scenario", scenario_yaml)
    if reproducible:
        _put(tree, b, _load_yaml(os.path.join(cfg, "reproducible", "bridge.yaml")))
    _put(tree, b, _load_yaml(os.path.join(cfg, "v2x.yaml")))
    tree[b + "/v2x/seed"] = seed
    # The evaluated policy's own bridge parameters (its bridge.yaml), else the arm's.
    if pfolder and os.path.isfile(os.path.join(pfolder, "bridge.yaml")):
        _put(tree, b, _load_yaml(os.path.join(pfolder, "bridge.yaml")))
    elif entry.get("bridge_params"):
        _put(tree, b, _load_yaml(os.path.join(cfg, entry["bridge_params"])))
    _put(tree, b, _overrides(config.get("bridge"), "bridge"))
    tree.update({
        b + "/scenario_dir": folder, b + "/out_dir": out_dir, b + "/episodes": 1, b + "/first_episode": 0,
        b + "/scenario/penetration_rate": float(pr) / 100.0, b + "/scenario/seed": seed,
        b + "/scenario/duration_s": float(duration_s), b + "/gui": False, b + "/gui_quit_on_end": False,
        b + "/advisory_control": bool(entry.get("advisory_control", False)), b + "/expected_rsus": rsu_ids,
        b + "/inprocess_rsus": True, b + "/real_time_factor": 0.0, b + "/rviz_template": "",
        b + "/trajectory_period_steps": int(tree.get(b + "/trajectory_period_steps", 0)), b + "/min_subscribers": 0,
        b + "/min_marker_subscribers": 0,
        b + "/command_line": "palcas_env", b + "/git_commit": "unrecorded"})
    if demand is not None:
        tree[b + "/scenario/mainline_flow_vphpl"] = float(demand)
    if ramp_demand is not None:
        tree[b + "/scenario/onramp_flow_vphpl"] = float(ramp_demand)
    if entry.get("assist_mode"):
        tree[b + "/assist_mode"] = True

    learning = _policy_learning(pfolder) if pfolder else None
    for index, rsu_id in enumerate(rsu_ids):
        ns = "/%s/rsu" % rsu_id
        for name in ("rsu.yaml", "reward.yaml", "learning.yaml", "rules.yaml", "departures.yaml"):
            _put(tree, ns, _load_yaml(os.path.join(cfg, name)))
        if learning:
            _put(tree, ns, _load_yaml(learning))
        _put(tree, ns, _load_yaml(os.path.join(cfg, "v2x.yaml")))
        tree[ns + "/v2x/seed"] = seed
        if reproducible:
            _put(tree, ns, _load_yaml(os.path.join(cfg, "reproducible", "rsu.yaml")))
        _put(tree, ns, _overrides(config.get("rsu"), "rsu"))
        tree.update({
            ns + "/rsu/rsu_id": rsu_id, ns + "/rsu/cluster_index": index, ns + "/rsu/train": mode == "train",
            ns + "/rsu/advice": "network", ns + "/learning/seed": seed * 1000 + index,
            ns + "/whole_road": rsus == "central", ns + "/federation": bool(entry.get("federation", False)),
            ns + "/i2i": bool(entry.get("i2i", False)), ns + "/checkpoint_dir": "", ns + "/resume": False,
            ns + "/policy_dir": os.path.join(pfolder, "checkpoints") if pfolder else ""})
        if not entry.get("priority_reward", False):
            tree[ns + "/reward/lambda"] = 0.0
    return tree, rsu_ids
