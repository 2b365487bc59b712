#!/usr/bin/python3
"""Test: no committed record names a folder of the machine that wrote it, and the tools that
write records keep the repository's paths repository-relative (tools/repo_paths.py):
train.json (./palcas train, tools/ship_policy.py), experiment.json and point.json
(./palcas experiment). A relative path read back is relative to the repository.

usage: record_paths_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import json
import os
import pathlib
import re
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(ROOT / "test" / "tools"))
from palcas_cli import experiment, train  # noqa: E402
import repo_paths  # noqa: E402
import ship_policy  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402

# An absolute path inside a string (a whole value, or a word of a command line).
ABSOLUTE = re.compile(r"(?:^|[\s=:\"'(,])(/[A-Za-z0-9_.+-]+/[^\s\"',)]*)")
# Folders that are the same on every machine the suite runs on (Debian's own).
SYSTEM = ("/usr/", "/etc/", "/dev/", "/proc/", "/sys/")
BRIDGE = ROOT / "config" / "training" / "gentle_lane_changes.yaml"
V2X = ROOT / "config" / "v2x" / "impaired_300ms_30pct.yaml"


def absolute_paths(value):
    """Every absolute path in a JSON value's strings, outside SYSTEM."""
    if isinstance(value, dict):
        return [p for v in value.values() for p in absolute_paths(v)]
    if isinstance(value, list):
        return [p for v in value for p in absolute_paths(v)]
    if isinstance(value, str):
        return [m.group(1) for m in ABSOLUTE.finditer(value) if not m.group(1).startswith(SYSTEM)]
    return []


class CommittedRecords(unittest.TestCase):
    def test_no_record_names_a_folder_of_the_machine_that_wrote_it(self):
        files = subprocess.run(["git", "-C", str(ROOT), "ls-files", "*.json"], capture_output=True, text=True,
                               check=True).stdout.split()
        self.assertTrue(any(f.endswith("train.json") for f in files))
        found = {}
        for f in files:
            paths = absolute_paths(json.loads((ROOT / f).read_text()))
            if paths:
                found[f] = paths
        self.assertEqual(found, {}, "records with absolute paths (make them repository-relative)")


class RepoPaths(unittest.TestCase):
    def test_a_path_in_the_repository_is_kept_relative_and_read_back_absolute(self):
        self.assertEqual(repo_paths.recorded(str(BRIDGE)), "config/training/gentle_lane_changes.yaml")
        self.assertEqual(repo_paths.usable("config/training/gentle_lane_changes.yaml"), str(BRIDGE))
        self.assertEqual(repo_paths.recorded("/elsewhere/x.yaml"), "/elsewhere/x.yaml")
        self.assertEqual(repo_paths.usable("/elsewhere/x.yaml"), "/elsewhere/x.yaml")
        self.assertEqual((repo_paths.recorded(""), repo_paths.usable("")), ("", ""))
        here = os.getcwd()
        try:  # a relative path given on the command line is relative to the working folder
            os.chdir(ROOT / "config")
            self.assertEqual(repo_paths.recorded("training/gentle_lane_changes.yaml"),
                             "config/training/gentle_lane_changes.yaml")
        finally:
            os.chdir(here)


class Writers(unittest.TestCase):
    def test_train_json_keeps_repository_paths_relative_and_a_resume_reads_them_back(self):
        with tempfile.TemporaryDirectory() as out:
            opts = dict(train.DEFAULTS, learning=os.path.join(out, "learning_schedule.yaml"),
                        rsu_params="", bridge_params=str(BRIDGE), v2x_params=str(V2X))
            record = train.write_record(out, opts, "abc", "./palcas train")
            self.assertEqual((record["bridge_params"], record["v2x_params"], record["learning"]),
                             ("config/training/gentle_lane_changes.yaml", "config/v2x/impaired_300ms_30pct.yaml",
                              opts["learning"]))  # a training folder outside the repository stays absolute
            self.assertEqual(json.loads(pathlib.Path(out, "train.json").read_text())["bridge_params"],
                             "config/training/gentle_lane_changes.yaml")
            resumed, _ = train.settle_options({k: None for k in train.ALL_GIVEN}, out, True)
            self.assertEqual((resumed["bridge_params"], resumed["v2x_params"]), (str(BRIDGE), str(V2X)))

    def test_experiment_json_keeps_repository_paths_relative_and_takes_an_older_absolute_one(self):
        with tempfile.TemporaryDirectory() as out:
            _, a = experiment.parse(["--out", out, "--arms", "palcas,keep", "--seeds", "1",
                                     "--bridge-params", str(BRIDGE)])
            wanted = experiment.settings_from_args(a)
            self.assertEqual((wanted["policies"], wanted["bridge_params"]),
                             ({"palcas": "policies/palcas"}, "config/training/gentle_lane_changes.yaml"))
            older = dict(wanted, policies={"palcas": str(ROOT / "policies" / "palcas")}, bridge_params=str(BRIDGE))
            pathlib.Path(out, "experiment.json").write_text(json.dumps(older))
            merged = experiment.merge_settings(pathlib.Path(out), wanted)  # the same experiment
            self.assertEqual((merged["policies"], merged["bridge_params"]),
                             ({"palcas": "policies/palcas"}, "config/training/gentle_lane_changes.yaml"))

    def test_a_shipped_train_json_keeps_repository_paths_relative(self):
        with tempfile.TemporaryDirectory() as tmp:
            src = pathlib.Path(tmp) / "train-x"
            (src / "checkpoints/rsu_0").mkdir(parents=True)
            (src / "checkpoints/rsu_0/model.palcas").write_bytes(b"model")
            (src / "train.json").write_text(json.dumps({
                "arm": "palcas", "scenario": "tiny", "pr": 40, "seed": 3, "episodes": 1, "duration_s": 300,
                "learning": "", "rsu_params": "", "bridge_params": str(BRIDGE), "v2x_params": str(V2X),
                "explore_fraction": 0.5, "git_commit": "abc"}))
            (src / "episodes.csv").write_text("episode,seed,sim_seconds,wall_seconds\n0,3,300,30\n")
            dest = pathlib.Path(tmp) / "policy"
            ship_policy.main(str(src), str(dest), rsu_models=True, bridge_as_trained=True)
            shipped = json.loads((dest / "train.json").read_text())
            self.assertEqual((shipped["bridge_params"], shipped["v2x_params"]),
                             ("config/training/gentle_lane_changes.yaml", "config/v2x/impaired_300ms_30pct.yaml"))
            self.assertEqual((dest / "bridge.yaml").read_text(), BRIDGE.read_text())


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "record_paths")
