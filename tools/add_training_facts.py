#!/usr/bin/python3
"""Adds what a policy's training did to an evaluation's metrics.json: federation_rounds
(rounds the federation server closed while training; 0 for arms without federation).

    add_training_facts.py METRICS_JSON TRAIN_DIR
"""
import json
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import policy_folder  # noqa: E402


def main(metrics_path, train_dir):
    metrics_path = pathlib.Path(metrics_path)
    metrics = json.loads(metrics_path.read_text())
    state = policy_folder.federation_state(train_dir)
    rounds = 0
    if state.exists():
        rounds = json.loads(state.read_text()).get("rounds_closed", 0)
    metrics["federation_rounds"] = rounds
    metrics["policy"] = str(pathlib.Path(train_dir).resolve())
    metrics_path.write_text(json.dumps(metrics, indent=2, sort_keys=True) + "\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
