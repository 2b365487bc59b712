#!/usr/bin/env python3
"""Write a training's "learning:" override: the user's (if any) plus the exploration
schedule stated as a fraction of the training budget.

usage: train_schedule.py OUT.yaml --episodes N --duration S --fraction F
                         [--decision-period-s P] [--base USER.yaml]

epsilon falls linearly from epsilon_start to epsilon_final over F x (decision rounds of
the whole training), one round per RSU decision (every P simulated seconds)."""
import argparse
import sys

import yaml


def write(out, episodes, duration, fraction, base="", decision_period_s=1.0):
    """Writes OUT; raises ValueError naming what is wrong with the fraction or the base file."""
    if not 0.0 < fraction <= 1.0:
        raise ValueError("train_schedule: --explore-fraction must be in (0, 1], got %s" % fraction)
    doc = {}
    if base:
        with open(base) as f:
            doc = yaml.safe_load(f) or {}
        if not isinstance(doc.get("learning", {}), dict):
            raise ValueError("train_schedule: %s has no 'learning:' map" % base)
    learning = doc.setdefault("learning", {})
    rounds = fraction * episodes * duration / decision_period_s
    learning["epsilon_linear_rounds"] = float(max(1.0, round(rounds)))
    with open(out, "w") as f:
        f.write("# Written by ./palcas train: the learning override of this training "
                "(exploration over %.0f %% of %d x %.0f s).\n" % (100 * fraction, episodes, duration))
        yaml.safe_dump(doc, f, default_flow_style=False)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--episodes", type=int, required=True)
    ap.add_argument("--duration", type=float, required=True)
    ap.add_argument("--fraction", type=float, required=True)
    ap.add_argument("--decision-period-s", type=float, default=1.0)
    ap.add_argument("--base", default="")
    a = ap.parse_args()
    try:
        write(a.out, a.episodes, a.duration, a.fraction, a.base, a.decision_period_s)
    except ValueError as e:
        sys.exit(str(e))


if __name__ == "__main__":
    main()
