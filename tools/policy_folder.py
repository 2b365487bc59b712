#!/usr/bin/env python3
"""The layout of a policy folder: a ./palcas train folder, or what tools/ship_policy.py makes
of one under policies/<arm>/ (policies/README.md describes it for users). The tools name its
files through this module; the RSU's own load order (palcas_rsu) and system.launch's
checkpoints/ and bridge.yaml follow the same layout.

usage: policy_folder.py check DIR   exit 0 if DIR is a policy folder, else 1 and why"""
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
SHIPPED = ROOT / "policies"  # policies/<arm>/: an arm's shipped policy

TRAIN_RECORD = "train.json"  # the training's command line and parameters
CHECKPOINTS = "checkpoints"  # checkpoints/<rsu>/ per RSU, checkpoints/fedserver/ the server
FEDSERVER = "fedserver"
GLOBAL_MODEL = "global_model.palcas"  # in checkpoints/fedserver/: every RSU loads it first
FEDERATION_STATE = "federation_state.json"  # in checkpoints/fedserver/: the rounds closed
RSU_MODEL = "model.palcas"  # in checkpoints/<rsu>/
DEFAULT_RSU = "default"  # checkpoints/default/model.palcas: for an RSU without its own model
LEARNING_LOG = "learning.csv"  # in checkpoints/<rsu>/: per-RSU learning rows
BRIDGE_PARAMS = "bridge.yaml"  # bridge parameters the policy runs under (over config/bridge.yaml)
RSU_PARAMS = "rsu.yaml"  # RSU parameters the policy runs under (over config/departures.yaml)
TRAINING_NOTES = "TRAINING.md"
EPISODES = "episodes.csv"
# The training record shipped beside the models.
RECORD_FILES = (EPISODES, "learning_curves.csv", "learning_curves.png", "aborted_episodes.txt")


def shipped(arm):
    """Where an arm's shipped policy lives."""
    return SHIPPED / arm


def checkpoints(folder):
    return pathlib.Path(folder) / CHECKPOINTS


def global_model(folder):
    return checkpoints(folder) / FEDSERVER / GLOBAL_MODEL


def federation_state(folder):
    return checkpoints(folder) / FEDSERVER / FEDERATION_STATE


def rsu_model(folder, rsu):
    return checkpoints(folder) / rsu / RSU_MODEL


def rsu_models(folder):
    """Every RSU's own model (checkpoints/<rsu>/model.palcas), sorted."""
    return sorted(checkpoints(folder).glob("*/" + RSU_MODEL))


def learning_logs(folder):
    return sorted(checkpoints(folder).glob("*/" + LEARNING_LOG))


def bridge_params(folder):
    return pathlib.Path(folder) / BRIDGE_PARAMS


def rsu_params(folder):
    return pathlib.Path(folder) / RSU_PARAMS


def train_record_path(folder):
    return pathlib.Path(folder) / TRAIN_RECORD


def train_record(folder):
    return json.loads(train_record_path(folder).read_text())


def why_not(folder):
    """None if FOLDER holds a policy (its training record and checkpoints/), else why not."""
    folder = pathlib.Path(folder)
    if not folder.is_dir():
        return "no such folder"
    if not train_record_path(folder).is_file() or not checkpoints(folder).is_dir():
        return f"not a ./palcas train folder (needs {TRAIN_RECORD} and {CHECKPOINTS}/)"
    return None


def main(argv):
    if len(argv) != 2 or argv[0] != "check":
        sys.exit(__doc__.split("\n\n")[-1])
    why = why_not(argv[1])
    if why:
        print(why)
    return 1 if why else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
