"""A PALCAS policy's decisions in plain numpy, from the .npz that Policy.export_npz writes.

Needs numpy only (copy this file anywhere). Per RSU, two networks as the C++ agent builds
them (src/include/palcas_core/learning/pdqn_agent.h, src/doc/learning.md), in eval mode:
  mu: state -> tanh in [-1, 1], the acceleration accel_mid + accel_half * c
  q:  concat(state, c) -> one value per advisory (0 LANE_LEFT, 1 LANE_RIGHT, 2 ACCELERATE, 3 KEEP)
  decision = argmax q (first on ties), acceleration clamped to [accel_min, accel_max].
Layers: Linear (y = W x + b), BatchNorm1d (running statistics, eps 1e-5), ReLU, Tanh,
Dropout (identity in eval mode). Float32 throughout, as the C++ core; its folded kernels
sum in another order, so accelerations agree to float rounding, not bit for bit.

    policy = NumpyPolicy("policy.npz")
    advisories, accels = policy.decide("rsu_0", states)    # states: (n, state_size)
"""
import re

import numpy as np

BATCH_NORM_EPS = np.float32(1e-5)  # BatchNorm1d's default (nn/batch_norm.h)
ACCEL_INDEX = 2  # ACCELERATE: the one advisory with a parameter (multi-pass input)


def networks_of(layout):
    """[(network name, [layer description])] of an agent layout 'palcas-pdqn/1 p-dqn mu[...] q[...]'."""
    found = re.findall(r"(\w+)\[([^\]]*)\]", layout)
    if not found:
        raise ValueError("layout %r names no networks" % layout)
    return [(name, body.split(";")) for name, body in found]


def _tensors_of(layers):
    """(name, shape) per tensor of one network, in the model's order: every layer's
    parameters, then every layer's buffers (tools/read_palcas_model.py)."""
    params, buffers = [], []
    for i, layer in enumerate(layers):
        m = re.fullmatch(r"(\w+)\(([^)]*)\)", layer)
        if not m:
            raise ValueError("unknown layer description %r" % layer)
        kind, args = m.group(1), m.group(2).split(",")
        if kind == "Linear":
            params += [("%d.Linear.weight" % i, (int(args[1]), int(args[0]))), ("%d.Linear.bias" % i, (int(args[1]),))]
        elif kind == "BatchNorm1d":
            n = int(args[0])
            params += [("%d.BatchNorm1d.gamma" % i, (n,)), ("%d.BatchNorm1d.beta" % i, (n,))]
            buffers += [("%d.BatchNorm1d.running_mean" % i, (n,)), ("%d.BatchNorm1d.running_var" % i, (n,))]
    return params + buffers


def split_tensors(layout, values):
    """{"<net>.<layer>.<Kind>.<tensor>": array} from a model's flat values (Eigen: column-major)."""
    values = np.asarray(values, dtype=np.float32)
    out, off = {}, 0
    for net, layers in networks_of(layout):
        for name, shape in _tensors_of(layers):
            n = int(np.prod(shape))
            if off + n > values.size:
                raise ValueError("the values end inside tensor %s.%s" % (net, name))
            out[net + "." + name] = values[off:off + n].reshape(shape, order="F")
            off += n
    if off != values.size:
        raise ValueError("%d values left over after the layout's tensors" % (values.size - off))
    return out


def forward(layers, tensors, prefix, x):
    """One network in eval mode on x (features, n) -> (outputs, n)."""
    x = np.asarray(x, dtype=np.float32)
    for i, layer in enumerate(layers):
        kind = layer.split("(", 1)[0]
        key = "%s.%d.%s." % (prefix, i, kind)
        if kind == "Linear":
            x = tensors[key + "weight"] @ x + tensors[key + "bias"][:, None]
        elif kind == "BatchNorm1d":
            inv_std = np.float32(1.0) / np.sqrt(tensors[key + "running_var"] + BATCH_NORM_EPS)
            x = (x - tensors[key + "running_mean"][:, None]) * (inv_std * tensors[key + "gamma"])[:, None] \
                + tensors[key + "beta"][:, None]
        elif kind == "ReLU":
            x = np.maximum(x, np.float32(0.0))
        elif kind == "Tanh":
            x = np.tanh(x)
        elif kind == "Dropout":
            pass  # identity in eval mode
        else:
            raise ValueError("unknown layer %r" % layer)
    return x.astype(np.float32)


class NumpyPolicy:
    """Every RSU's networks from an exported .npz; decide() reproduces the C++ decisions."""

    def __init__(self, path):
        data = np.load(path)
        self.rsu_ids = [str(r) for r in data["rsu_ids"]]
        self._rsus = {}
        for rsu in self.rsu_ids:
            layout = str(data[rsu + ".layout"])
            nets = dict(networks_of(layout))
            tensors = {k[len(rsu) + 1:]: data[k].astype(np.float32) for k in data.files
                       if k.startswith(rsu + ".") and ".Linear." in k or k.startswith(rsu + ".") and ".BatchNorm1d." in k}
            self._rsus[rsu] = {
                "mu": nets["mu"], "q": nets["q"], "tensors": tensors,
                "state_size": int(data[rsu + ".state_size"]),
                "accel_min": np.float32(data[rsu + ".accel_min_mps2"]),
                "accel_max": np.float32(data[rsu + ".accel_max_mps2"]),
                "multi_pass": bool(data[rsu + ".multi_pass"])}

    def q_values(self, rsu_id, states):
        """(q (n, 4), acceleration (n,)) of RSU `rsu_id` on states (n, state_size)."""
        r = self._rsus[rsu_id]
        s = np.asarray(states, dtype=np.float32)
        if s.ndim != 2 or s.shape[1] != r["state_size"]:
            raise ValueError("states must have shape (n, %d), got %s" % (r["state_size"], s.shape))
        x = s.T
        c = forward(r["mu"], r["tensors"], "mu", x)  # (1, n) in [-1, 1]
        n = x.shape[1]
        if r["multi_pass"]:
            passes = []
            for a in range(4):
                param = c if a == ACCEL_INDEX else np.zeros_like(c)
                passes.append(forward(r["q"], r["tensors"], "q", np.vstack([x, param]))[a])
            q = np.stack(passes)
        else:
            q = forward(r["q"], r["tensors"], "q", np.vstack([x, c]))
        mid = np.float32(0.5) * (r["accel_max"] + r["accel_min"])
        half = np.float32(0.5) * (r["accel_max"] - r["accel_min"])
        accel = (mid + half * c[0]).astype(np.float32)
        assert q.shape == (4, n)
        return q.T, accel

    def decide(self, rsu_id, states):
        """(advisory indices (n,), accelerations (n,)) as the C++ agent's greedy act()."""
        q, accel = self.q_values(rsu_id, states)
        r = self._rsus[rsu_id]
        return np.argmax(q, axis=1), np.clip(accel, r["accel_min"], r["accel_max"])
