#!/usr/bin/env python3
"""Tests of tools/train.py (./palcas train's orchestration) without a simulation: the
options a resumed training settles on, the training record, and how a console log is read
(nodes that died for good, why a simulation ended early); and of tools/ship_policy.py.

usage: train_tool_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import json
import os
import pathlib
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import ship_policy  # noqa: E402
import train  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402

NOT_GIVEN = dict(arm=None, episodes=None, duration=None, pr=None, seed=None, scenario=None, explore_fraction=None)
RECORD = {"arm": "independent", "scenario": "tiny", "pr": 40, "seed": 3, "episodes": 4, "duration_s": 300,
          "learning": "/x/learning_schedule.yaml", "rsu_params": "", "bridge_params": "/b.yaml",
          "paper_printed": False, "explore_fraction": 0.4, "git_commit": "abc"}


def given(**kw):
    g = dict(NOT_GIVEN)
    g.update(kw)
    return g


class SettleOptions(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp()
        with open(os.path.join(self.dir, "train.json"), "w") as f:
            json.dump(RECORD, f)

    def test_a_new_training_takes_defaults_for_what_was_not_given(self):
        opts, record = train.settle_options(given(pr=20.0), "", resume=False)
        self.assertIsNone(record)
        self.assertEqual((opts["arm"], opts["pr"], opts["episodes"], opts["scenario"]), ("palcas", 20.0, 5, "paper"))

    def test_a_new_training_refuses_a_folder_that_holds_one(self):
        with self.assertRaisesRegex(train.OptionError, "already holds a training"):
            train.settle_options(given(), self.dir, resume=False)

    def test_resume_takes_everything_from_the_record(self):
        opts, _ = train.settle_options(given(), self.dir, resume=True)
        for option, key in (("arm", "arm"), ("scenario", "scenario"), ("pr", "pr"), ("seed", "seed"),
                            ("duration", "duration_s"), ("episodes", "episodes"),
                            ("explore_fraction", "explore_fraction"), ("bridge_params", "bridge_params"),
                            ("learning", "learning")):
            self.assertEqual(opts[option], RECORD[key], option)

    def test_resume_may_grow_episodes_and_repeat_a_recorded_value(self):
        opts, _ = train.settle_options(given(episodes=10, pr=40.0, arm="independent"), self.dir, resume=True)
        self.assertEqual((opts["episodes"], opts["pr"]), (10, 40))

    def test_resume_refuses_a_contradicting_flag_naming_both_values(self):
        for kw, text in ((dict(pr=60.0), "trained with --pr 40, not --pr 60"),
                         (dict(scenario="paper"), "trained with --scenario tiny, not --scenario paper"),
                         (dict(seed=4), "trained with --seed 3, not --seed 4"),
                         (dict(explore_fraction=0.5), "leave --explore-fraction out")):
            with self.assertRaisesRegex(train.OptionError, text):
                train.settle_options(given(**kw), self.dir, resume=True)

    def test_resume_needs_a_record(self):
        with self.assertRaisesRegex(train.OptionError, "holds no training to resume"):
            train.settle_options(given(), tempfile.mkdtemp(), resume=True)
        with open(os.path.join(self.dir, "train.json"), "w") as f:
            f.write('{"arm": "palcas"}')
        with self.assertRaisesRegex(train.OptionError, "no field 'scenario'"):
            train.settle_options(given(), self.dir, resume=True)


class Record(unittest.TestCase):
    def test_paths_with_quotes_stay_valid_json_and_numbers_stay_as_written(self):
        out = tempfile.mkdtemp(prefix='it\'s "quoted" \\ ')
        opts = dict(train.DEFAULTS, pr=60.0, duration=1200.0, learning=out + "/l.yaml", rsu_params="",
                    bridge_params="", paper_printed=False)
        train.write_record(out, opts, "abc")
        with open(os.path.join(out, "train.json")) as f:
            record = json.load(f)
        self.assertEqual(record["learning"], out + "/l.yaml")
        self.assertEqual((record["pr"], record["duration_s"]), (60, 1200))
        self.assertIsInstance(record["pr"], int)

    def test_message_key_is_made_once_and_owner_only(self):
        out = tempfile.mkdtemp()
        key = train.message_key(out)
        first = open(key).read()
        self.assertEqual(len(first), 64)
        self.assertEqual(os.stat(key).st_mode & 0o777, 0o600)
        self.assertEqual(open(train.message_key(out)).read(), first)


class ConsoleLog(unittest.TestCase):
    def test_a_node_that_died_and_came_back_is_not_lost(self):
        text = ("[rsu_0/rsu-4] process has died [pid 1, exit code -9, cmd x]\n"
                "[rsu_0/rsu-4] restarting process\n")
        self.assertEqual(train.node_deaths(text), [])

    def test_a_death_without_restart_or_a_crash_loop_is_lost(self):
        text = "\x1b[31m[rsu_1/rsu-5] process has died [pid 2, exit code 1, cmd x]\x1b[0m\n"
        loop = "".join("[fedserver-3] process has died [pid %d, exit code -6, cmd x]\n"
                       "[fedserver-3] restarting process\n" % k for k in range(3))
        self.assertEqual(train.node_deaths(text + loop),
                         ["fedserver-3 (exit code -6, died 3 times)", "rsu_1/rsu-5 (exit code 1)"])

    def test_a_clean_exit_is_not_a_death(self):
        self.assertEqual(train.node_deaths("[rsu_0/rsu-4] process has died [pid 1, exit code 0, cmd x]\n"), [])

    def test_the_simulations_own_error_is_the_crash_reason(self):
        text = ("[rsu_0/rsu-4] process has died [pid 1, exit code -15, cmd x]\n"
                "sumo: MSVehicle.cpp:123: Assertion `myFurtherLanes.size() > 0' failed.\n")
        self.assertIn("myFurtherLanes", train.crash_reason(text))
        self.assertIn("process has died", train.crash_reason("[x] process has died [pid 1, exit code 1]"))
        self.assertEqual(train.crash_reason("all fine"), "")
        self.assertIn("[FATAL]", train.last_fatal("[ INFO] ok\n[FATAL] [1.0]: bad key\n"))

    def test_clusters_come_from_the_roads_description(self):
        self.assertEqual(train.scenario_clusters(str(ROOT), "paper"), 3)
        self.assertEqual(train.scenario_clusters(str(ROOT), "tiny"), 2)
        self.assertEqual(train.rsu_ids("centralized", 3), ["central"])
        self.assertEqual(train.rsu_ids("palcas", 2), ["rsu_0", "rsu_1"])


class ScenarioFiles(unittest.TestCase):
    """One description per road: each scenario folder holds scenario.yaml and vtypes.xml, and
    the RSU count system.launch derives from it (roslaunch cannot parse YAML, it reads the
    clusters: line) is the YAML's road/clusters."""

    def launch_rsu_count(self, scenario_dir):
        import xml.etree.ElementTree as ET
        from roslaunch.substitution_args import resolve_args
        args = {a.get("name"): a.get("value") for a in ET.parse(str(ROOT / "launch/system.launch")).getroot().iter("arg")}
        return int(resolve_args(args["rsu_count"], context={"arg": {"clusters": "auto", "scenario_dir": scenario_dir}}))

    def test_every_scenario_is_one_yaml_whose_cluster_count_the_launch_reads(self):
        import yaml
        folders = sorted((ROOT / "config/scenarios").iterdir())
        self.assertGreaterEqual(len([f for f in folders if f.is_dir()]), 3)
        for folder in folders:
            if not folder.is_dir():
                continue
            road = yaml.safe_load((folder / "scenario.yaml").read_text())["road"]
            self.assertEqual(self.launch_rsu_count(str(folder)), road["clusters"], folder.name)
            self.assertEqual(train.scenario_clusters(str(ROOT), folder.name), road["clusters"], folder.name)
            for gone in ("rsus.yaml", "learning.yaml", "network.nod.xml"):
                self.assertFalse((folder / gone).exists(), "%s/%s: the road is generated" % (folder.name, gone))

    def test_the_launch_reads_a_changed_cluster_count(self):
        folder = pathlib.Path(tempfile.mkdtemp())
        text = (ROOT / "config/scenarios/tiny/scenario.yaml").read_text()
        (folder / "scenario.yaml").write_text(text.replace("clusters: 2", "clusters: 4", 1))
        self.assertEqual(self.launch_rsu_count(str(folder)), 4)


class ShipPolicy(unittest.TestCase):
    """A training folder becomes a policy folder; its bridge parameters travel only when asked."""

    def training(self, bridge_params):
        src = pathlib.Path(tempfile.mkdtemp()) / "train-x"
        (src / "checkpoints/rsu_0").mkdir(parents=True)
        (src / "checkpoints/rsu_0/model.palcas").write_bytes(b"model")
        record = dict(RECORD, arm="palcas", bridge_params=bridge_params, learning="")
        (src / "train.json").write_text(json.dumps(record))
        (src / "episodes.csv").write_text("episode,seed,sim_seconds,wall_seconds\n0,3,300,30\n")
        return src

    def test_bridge_as_trained_carries_the_trainings_bridge_parameters(self):
        bridge = pathlib.Path(tempfile.mkdtemp()) / "lc.yaml"
        bridge.write_text("cav_lane_change_mode: 1792\n")
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(self.training(str(bridge))), str(dest), rsu_models=True, bridge_as_trained=True)
        self.assertEqual((dest / "bridge.yaml").read_text(), "cav_lane_change_mode: 1792\n")
        self.assertEqual(json.loads((dest / "train.json").read_text())["runs_with_bridge"], "bridge.yaml")
        self.assertIn("trained with: `bridge.yaml`", (dest / "TRAINING.md").read_text())

    def test_without_the_flag_a_policy_runs_under_the_default_bridge(self):
        bridge = pathlib.Path(tempfile.mkdtemp()) / "unclipped.yaml"
        bridge.write_text("max_advised_accel_mps2: 0.0\n")
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(self.training(str(bridge))), str(dest), rsu_models=True)
        self.assertFalse((dest / "bridge.yaml").exists())
        self.assertNotIn("runs_with_bridge", json.loads((dest / "train.json").read_text()))
        self.assertIn("runs under config/bridge.yaml (trained under `unclipped.yaml` over it)",
                      (dest / "TRAINING.md").read_text())

    def test_run_with_bridge_carries_a_file_the_training_did_not_use_and_says_so(self):
        bridge = pathlib.Path(tempfile.mkdtemp()) / "gentle.yaml"
        bridge.write_text("lane_change_max_accel_mps2: 1.47\n")
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(self.training("")), str(dest), rsu_models=True, run_bridge=str(bridge))
        self.assertEqual((dest / "bridge.yaml").read_text(), "lane_change_max_accel_mps2: 1.47\n")
        self.assertIn("which its training did not use (trained under config/bridge.yaml)",
                      (dest / "TRAINING.md").read_text())
        with self.assertRaises(SystemExit) as e:
            ship_policy.main(str(self.training("")), str(dest), run_bridge="/nonexistent.yaml")
        self.assertIn("no such file /nonexistent.yaml", str(e.exception.code))
        self.assertTrue((dest / "bridge.yaml").exists())  # the folder shipped before is kept

    def test_rsu_models_ship_the_global_model_as_the_default_for_zones_without_their_own(self):
        src = self.training("")
        (src / "checkpoints/fedserver").mkdir()
        (src / "checkpoints/fedserver/global_model.palcas").write_bytes(b"global")
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(src), str(dest), rsu_models=True)
        self.assertEqual((dest / "checkpoints/rsu_0/model.palcas").read_bytes(), b"model")
        self.assertEqual((dest / "checkpoints/default/model.palcas").read_bytes(), b"global")
        self.assertFalse((dest / "checkpoints/fedserver/global_model.palcas").exists())
        self.assertEqual(json.loads((dest / "train.json").read_text())["default_model"], "global")
        self.assertIn("an RSU without one loads `checkpoints/default/model.palcas`", (dest / "TRAINING.md").read_text())

    def test_default_from_names_the_rsu_whose_model_is_the_default_and_must_exist(self):
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(self.training("")), str(dest), rsu_models=True, default_from="rsu_0")
        self.assertEqual((dest / "checkpoints/default/model.palcas").read_bytes(), b"model")
        with self.assertRaises(SystemExit) as e:
            ship_policy.main(str(self.training("")), str(dest), rsu_models=True, default_from="rsu_7")
        self.assertIn("no checkpoints/rsu_7/model.palcas", str(e.exception.code))
        self.assertTrue((dest / "checkpoints/default/model.palcas").exists())  # kept

    def test_bridge_as_trained_without_bridge_parameters_is_refused_and_touches_nothing(self):
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        dest.mkdir()
        (dest / "kept").write_text("x")
        with self.assertRaises(SystemExit) as e:
            ship_policy.main(str(self.training("")), str(dest), bridge_as_trained=True)
        self.assertIn("no --bridge-params", str(e.exception.code))
        self.assertTrue((dest / "kept").exists())
        with self.assertRaises(SystemExit) as e:
            ship_policy.main(str(self.training("/nonexistent/lc.yaml")), str(dest), bridge_as_trained=True)
        self.assertIn("/nonexistent/lc.yaml are gone", str(e.exception.code))
        self.assertTrue((dest / "kept").exists())


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "train_tool")
