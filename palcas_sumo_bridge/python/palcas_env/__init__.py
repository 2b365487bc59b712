"""palcas_env: the PALCAS road as a multi-agent environment for Python learners.

The PettingZoo *parallel* API (without depending on pettingzoo): reset() -> (observations,
infos), step(actions) -> (observations, rewards, terminations, truncations, infos), agents
and possible_agents. One agent is one CAV in one RSU's zone ("rsu_0/cav.12"), one step() one
decision of every RSU (rsu/decision_period_steps bridge steps, 1 s on the shipped roads).
SUMO runs inside this process, through the bridge's own episode loop: the same advisory
validator, advice guard, holds and actuation as `./palcas run`, the paper's state and reward
from the C++ core, metrics.json as the bridge writes it. README: palcas_sumo_bridge/python/.

    import palcas_env
    env = palcas_env.ParallelEnv(scenario="tiny", pr=60, duration_s=120, mode="train")
    observations, infos = env.reset(seed=101)
    while env.agents:
        actions = {agent: (3, 0.0) for agent in env.agents}    # KEEP for everyone
        observations, rewards, terminations, truncations, infos = env.step(actions)
    print(env.metrics()["dsr_pct"])
"""
import json
import os
import tempfile

# One Eigen/OpenMP thread, as every RSU node runs (launch/rsu.launch): decisions repeat.
os.environ.setdefault("OMP_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from . import _params  # noqa: E402
from ._palcas_env import ParallelEnvCore, PolicyCore, build_info  # noqa: E402,F401

# The hybrid action's discrete part: palcas::Action (src/include/palcas_core/common/action.h),
# the codes of palcas_msgs/Advisory.
LANE_LEFT, LANE_RIGHT, ACCELERATE, KEEP = 0, 1, 2, 3
ADVISORY_NAMES = ("LANE_LEFT", "LANE_RIGHT", "ACCELERATE", "KEEP")

__all__ = ["ParallelEnv", "Policy", "LANE_LEFT", "LANE_RIGHT", "ACCELERATE", "KEEP", "ADVISORY_NAMES",
           "build_info"]


def _action(agent, action):
    """(advisory_index, acceleration) from a tuple, list or array of two; errors name the agent."""
    if isinstance(action, (str, bytes, dict)):
        raise TypeError("agent %r: action must be (advisory_index, acceleration), got %r" % (agent, action))
    try:
        parts = list(np.asarray(action, dtype=object).reshape(-1)) if isinstance(action, np.ndarray) else list(action)
    except TypeError:
        raise TypeError("agent %r: action must be (advisory_index, acceleration), got %r" % (agent, action)) from None
    if len(parts) != 2:
        raise ValueError("agent %r: action must have 2 parts (advisory_index, acceleration), got %d: %r"
                         % (agent, len(parts), action))
    index, accel = parts
    if isinstance(index, (bool, np.bool_)) or not isinstance(index, (int, np.integer)):
        if isinstance(index, (float, np.floating)) and float(index).is_integer():
            index = int(index)
        else:
            raise ValueError("agent %r: advisory index must be an integer 0..3, got %r" % (agent, index))
    try:
        accel = float(accel)
    except (TypeError, ValueError):
        raise ValueError("agent %r: acceleration must be a number, got %r" % (agent, accel)) from None
    return int(index), accel


class ParallelEnv:
    """The PALCAS road, one agent per CAV in an RSU's zone (PettingZoo parallel API).

    scenario    a road under config/scenarios/ ("paper", "tiny", ...) or a folder with scenario.yaml
    arm         a learning arm of config/arms.json: its RSUs (zones or one central), I2I, priority
                reward, advisory or assist mode ("palcas")
    mode        "train": the RSUs' training semantics (rewards of the transitions they close) |
                "eval": an evaluating RSU's (its members; rewards from a training twin, so a
                policy sees what `./palcas run` does)
    pr          CAV penetration rate [%]
    demand, ramp_demand   mainline veh/h per lane, on-ramp veh/h per ramp (None: the scenario's)
    seed        the traffic's seed: reset() without a seed runs seed, seed + 1, ... as a training
    duration_s  simulated seconds per episode
    out_dir     run folder (metrics.json, manifest.json, the generated scenario); None: a new
                temporary folder
    policy      the policy folder whose parameters apply ("shipped" = policies/<arm>/, as
                `./palcas run`): its bridge.yaml and its learning override; None = none
    reproducible  config/reproducible/ over config/ (None: True in eval, as system.launch)
    config      {"bridge": {...} or YAML file, "rsu": {...} or YAML file}: parameters over the
                shipped ones, as --bridge-params / --rsu-params
    """

    metadata = {"name": "palcas_v0", "is_parallel": True}

    def __init__(self, scenario="tiny", arm="palcas", mode="train", pr=60, demand=None, ramp_demand=None, seed=101,
                 duration_s=1800.0, out_dir=None, policy=None, reproducible=None, config=None):
        if out_dir is None:
            out_dir = tempfile.mkdtemp(prefix="palcas_env-")
        out_dir = os.path.abspath(str(out_dir))
        self.arm, self.mode, self.scenario = arm, mode, scenario
        tree, self.rsu_ids = _params.build(scenario, arm, mode, pr, demand, ramp_demand, seed, duration_s, out_dir,
                                           policy, reproducible, config)
        self._core = ParallelEnvCore(tree, _params.BRIDGE_NS)
        self._out_dir = self._core.out_dir
        self.agents = []
        self.possible_agents = []  # CAVs enter as traffic does: grows with every new agent
        self._seen = set()

    # -- PettingZoo parallel API --
    def _live(self):
        if self._core is None:
            raise RuntimeError("this ParallelEnv is closed")
        return self._core

    def reset(self, seed=None, options=None):
        if seed is not None and (isinstance(seed, bool) or not isinstance(seed, (int, np.integer))
                                 or not 0 <= seed <= 2147483647):
            raise ValueError("seed must be an integer in 0..2147483647 (as ~scenario/seed) or None, got %r" % (seed,))
        result = self._live().reset(None if seed is None else int(seed))
        observations, _, _, _, infos = self._unpack(result)
        return observations, infos

    def step(self, actions):
        if not isinstance(actions, dict):
            raise TypeError("actions must be a dict {agent: (advisory_index, acceleration)}, got %s"
                            % type(actions).__name__)
        checked = {str(agent): _action(agent, a) for agent, a in actions.items()}
        return self._unpack(self._live().step(checked))

    def observation_space(self, agent):
        """The observation's shape and dtype (no gymnasium here): the paper's state vector."""
        return {"shape": (self._live().state_size,), "dtype": np.float32}

    def action_space(self, agent):
        """The hybrid action: an advisory index (ADVISORY_NAMES) and an acceleration that
        ACCELERATE holds, within the RSU's bounds [m/s^2]."""
        rsu = agent.split("/", 1)[0] if agent else self.rsu_ids[0]
        low, high = self._live().accel_bounds(rsu)
        return {"advisory": tuple(range(4)), "acceleration": (float(low), float(high))}

    # -- more --
    @property
    def state_size(self):
        return self._live().state_size

    @property
    def out_dir(self):
        return self._out_dir

    @property
    def decision_period_steps(self):
        return self._live().decision_period_steps

    def metrics(self):
        """The last finished episode's metrics.json (the bridge's own writer), as a dict."""
        path = os.path.join(self._out_dir, "metrics.json")
        if not os.path.isfile(path):
            raise RuntimeError("no episode finished yet: metrics.json is written at the episode's end")
        with open(path) as f:
            return json.load(f)

    def close(self):
        """Ends SUMO (libsumo runs one simulation per process: close an environment before
        making the next; a dropped environment closes too)."""
        self._core = None
        self.agents = []

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def _unpack(self, result):
        observations, rewards, terminations, truncations, header, agents = result
        infos = {}
        for agent in observations:
            rsu, vehicle = agent.split("/", 1)
            infos[agent] = {"rsu": rsu, "vehicle": vehicle, "step": header["step"], "time_s": header["time_s"]}
            if agent not in self._seen:
                self._seen.add(agent)
                self.possible_agents.append(agent)
        self.agents = list(agents)
        return observations, rewards, terminations, truncations, infos


class Policy:
    """A trained policy of the suite (a policy folder, as `./palcas run --policy`) for the
    RSUs of an environment: greedy decisions, as an evaluating RSU takes them."""

    def __init__(self, core, env):
        self._core, self.rsu_ids = core, list(core.rsu_ids)

    @classmethod
    def load(cls, folder, env):
        """`folder`: a policy folder (train.json + checkpoints/, e.g. policies/palcas), a
        checkpoints folder, or "shipped" (policies/<env.arm>/). Its networks take the
        environment's state size (its road's lane count)."""
        if folder == "shipped":
            folder = os.path.join(_params.policies_dir(), env.arm)
        return cls(PolicyCore(str(folder), env._live()), env)

    @property
    def model_files(self):
        return dict(self._core.model_files)

    def act(self, observations):
        """{agent: (advisory_index, acceleration)} for {agent: state}."""
        return self._core.act({str(a): np.asarray(s, dtype=np.float32) for a, s in observations.items()})

    def evaluate(self, rsu_id, states):
        """(q_values (n, 4), accelerations (n,)) of RSU `rsu_id`'s networks on states (n, state_size)."""
        return self._core.evaluate(rsu_id, np.asarray(states, dtype=np.float32))

    def export_npz(self, path):
        """Every RSU's networks as arrays in one .npz (numpy_policy.NumpyPolicy reads it)."""
        arrays = {"rsu_ids": np.array(self.rsu_ids)}
        for rsu in self.rsu_ids:
            layout, values, config = self._core.export_model(rsu)
            arrays[rsu + ".layout"] = np.array(layout)
            for key, value in config.items():
                arrays[rsu + "." + key] = np.array(value)
            from .numpy_policy import split_tensors
            for name, tensor in split_tensors(layout, values).items():
                arrays[rsu + "." + name] = tensor
        np.savez(path, **arrays)
        return path
