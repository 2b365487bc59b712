#!/usr/bin/env python3
"""Evaluates a trained policy of the suite from Python: the same episode as
`./palcas run --arm palcas --no-compare --seed S --duration D` (shipped policy, its bridge
parameters, eval mode), driven through palcas_env; prints the run folder's metrics.json.

  examples/evaluate_policy.py [--policy shipped|DIR] [--scenario paper] [--seed 101]
                              [--duration 1800] [--pr 60] [--demand VPHPL] [--out DIR]
"""
import argparse
import json
import os
import sys

import palcas_env


def evaluate(policy="shipped", scenario="paper", seed=101, duration_s=1800.0, pr=60, demand=None, out_dir=None,
             arm="palcas"):
    """metrics.json of one episode of `policy` (a dict), and the environment's run folder."""
    with palcas_env.ParallelEnv(scenario=scenario, arm=arm, mode="eval", pr=pr, demand=demand, seed=seed,
                                duration_s=duration_s, out_dir=out_dir, policy=policy) as env:
        decider = palcas_env.Policy.load(policy, env)
        observations, _ = env.reset(seed=seed)
        decisions = 0
        while env.agents:
            actions = decider.act({agent: observations[agent] for agent in env.agents})
            decisions += len(actions)
            observations, _, _, _, _ = env.step(actions)
        return env.metrics(), env.out_dir, decisions


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--policy", default="shipped")
    ap.add_argument("--arm", default="palcas")
    ap.add_argument("--scenario", default="paper")
    ap.add_argument("--seed", type=int, default=101)
    ap.add_argument("--duration", type=float, default=1800.0)
    ap.add_argument("--pr", type=float, default=60)
    ap.add_argument("--demand", type=float)
    ap.add_argument("--out")
    a = ap.parse_args()
    metrics, out, decisions = evaluate(a.policy, a.scenario, a.seed, a.duration, a.pr, a.demand, a.out, a.arm)
    print(json.dumps({k: metrics[k] for k in ("cavs_seen", "dsr_pct", "msr_pct", "collision_rate_pct",
                                               "efficiency_all_mps", "advisories", "wall_seconds")}, indent=1))
    print("%d agent decisions; run folder %s" % (decisions, out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
