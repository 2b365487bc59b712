#!/usr/bin/env python3
"""What driving the episode from Python costs: the shipped policy evaluated through
palcas_env (observations to Python, Policy.act, actions back, every decision step) against
the bridge's own in-process loop on the same episode (`./palcas run --in-process`: RSUs as
calls inside the bridge, no Python). Prints both wall times (metrics.json's wall_seconds,
the same clock of the same EpisodeRunner loop in both) and their ratio. A measurement, not a
test: run it on a quiet machine.

  examples/step_overhead.py [--duration 300] [--seed 101] [--scenario paper] [--out DIR]
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import evaluate_policy  # noqa: E402
import palcas_env  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=300.0)
    ap.add_argument("--seed", type=int, default=101)
    ap.add_argument("--scenario", default="paper")
    ap.add_argument("--out")
    a = ap.parse_args()
    out = a.out or tempfile.mkdtemp(prefix="palcas_overhead-")
    root = palcas_env._params.repo_root()
    env = dict(os.environ, PALCAS_NO_BUILD="1")
    started = time.monotonic()
    r = subprocess.run([os.path.join(root, "palcas"), "run", "--arm", "palcas", "--no-compare", "--in-process",
                        "--scenario", a.scenario, "--duration", "%g" % a.duration, "--seed", str(a.seed),
                        "--out", os.path.join(out, "cpp")], env=env, capture_output=True, text=True)
    cpp_total = time.monotonic() - started
    if r.returncode != 0:
        print(r.stdout[-2000:] + r.stderr[-2000:], file=sys.stderr)
        return 1
    with open(os.path.join(out, "cpp", "palcas", "metrics.json")) as f:
        cpp = json.load(f)
    started = time.monotonic()
    py, _, decisions = evaluate_policy.evaluate("shipped", a.scenario, a.seed, a.duration,
                                                out_dir=os.path.join(out, "python"))
    py_total = time.monotonic() - started
    print("episode: %s road, %g s simulated, seed %d, %d agent decisions" % (a.scenario, a.duration, a.seed, decisions))
    print("C++ in-process loop (./palcas run --in-process): %.2f s (whole command with roslaunch: %.1f s)"
          % (cpp["wall_seconds"], cpp_total))
    print("Python loop (palcas_env + Policy.act):          %.2f s (whole script part: %.1f s)"
          % (py["wall_seconds"], py_total))
    print("ratio Python / C++ loop: %.2f" % (py["wall_seconds"] / cpp["wall_seconds"]))
    differ = sorted(k for k in set(cpp) | set(py) if cpp.get(k) != py.get(k))
    print("metrics.json fields that differ (wall time, decision latencies, facts the command adds): %s"
          % ", ".join(differ))
    return 0


if __name__ == "__main__":
    sys.exit(main())
