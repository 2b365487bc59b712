#!/usr/bin/env python3
"""Tests of ./palcas train's orchestration (tools/palcas_cli/train.py) without a simulation:
the options a resumed training settles on, the training record, the launch loop; and of
tools/ship_policy.py. How a console log is read: test/tools/palcas_cli_test.py.

usage: train_tool_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import json
import math
import os
import pathlib
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_cli import launch, train  # noqa: E402
from palcas_cli.options import OptionError  # noqa: E402
import ship_policy  # noqa: E402
import train_monitor  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402

NOT_GIVEN = {k: None for k in train.ALL_GIVEN}
RECORD = {"arm": "independent", "scenario": "tiny", "pr": 40, "seed": 3, "episodes": 4, "duration_s": 300,
          "learning": "/x/learning_schedule.yaml", "rsu_params": "", "bridge_params": "/b.yaml",
          "paper_printed": False, "explore_fraction": 0.4, "git_commit": "abc"}


def given(**kw):
    g = dict(NOT_GIVEN)
    g.update(kw)
    return g


class MonitorProgress(unittest.TestCase):
    """A training that draws its traffic per episode runs one launch per episode: the time
    left must cover the episodes still to come, not only the running one."""

    def test_time_left_covers_every_episode_still_to_run(self):
        # episode 5 of 36 (0-based 4, first of this launch), 300 of 1200 s after 60 s of wall
        done, left = train_monitor.progress(4, 4, 36, 1200.0, 300.0, 60.0)
        self.assertEqual(done, 300.0)
        self.assertAlmostEqual(left, (32 * 1200.0 - 300.0) * 60.0 / 300.0)

    def test_one_launch_for_every_episode(self):
        # episodes 0..3 in one launch; the second one half done after 150 s of wall
        done, left = train_monitor.progress(0, 1, 4, 100.0, 50.0, 150.0)
        self.assertEqual(done, 150.0)
        self.assertAlmostEqual(left, 250.0 * 150.0 / 150.0)

    def test_no_progress_yet_gives_no_estimate(self):
        self.assertTrue(math.isnan(train_monitor.progress(0, 0, 4, 100.0, 0.0, 5.0)[1]))

    def test_time_left_at_the_whole_trainings_pace(self):
        # two episodes of 1200 s took 600 s of wall before this launch; it ran 300 s in 60 s
        done, left = train_monitor.progress(2, 2, 4, 1200.0, 300.0, 60.0, before=(2400.0, 600.0))
        self.assertEqual(done, 300.0)
        self.assertAlmostEqual(left, (2 * 1200.0 - 300.0) * 660.0 / 2700.0)
        # a launch that has not yet stepped still gets an estimate from the episodes before it
        self.assertAlmostEqual(train_monitor.progress(2, 2, 4, 1200.0, 0.0, 1.0, before=(2400.0, 600.0))[1],
                               2400.0 * 601.0 / 2400.0)

    def test_episodes_finished_before_this_launch(self):
        d = tempfile.mkdtemp()
        path = os.path.join(d, "episodes.csv")
        self.assertEqual(train_monitor.finished_before(path), (None, (0.0, 0.0)))
        with open(path, "w") as f:
            f.write("episode,seed,sim_seconds,wall_seconds,collision_rate_pct,dsr_pct,msr_pct\n"
                    "0,1,1200,273.5,0,94.0,100\n1,2,1200,212.5,0.35,97.5,99.0\n")
        last, before = train_monitor.finished_before(path)
        self.assertEqual((last.collision_rate_pct, last.dsr_pct, last.msr_pct), (0.35, 97.5, 99.0))
        self.assertEqual(before, (2400.0, 486.0))


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
        with self.assertRaisesRegex(OptionError, "already holds a training"):
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
            with self.assertRaisesRegex(OptionError, text):
                train.settle_options(given(**kw), self.dir, resume=True)

    def test_resume_needs_a_record(self):
        with self.assertRaisesRegex(OptionError, "holds no training to resume"):
            train.settle_options(given(), tempfile.mkdtemp(), resume=True)
        with open(os.path.join(self.dir, "train.json"), "w") as f:
            f.write('{"arm": "palcas"}')
        with self.assertRaisesRegex(OptionError, "no field 'scenario'"):
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

    def test_the_starting_command_survives_every_resume(self):
        out = tempfile.mkdtemp()
        opts = dict(train.DEFAULTS, learning="", rsu_params="", bridge_params="", paper_printed=False)
        train.write_record(out, opts, "abc", "./palcas train --arm palcas --episodes 36")
        train.write_record(out, opts, "def", "./palcas train --resume --out x", resume=True)
        train.write_record(out, opts, "def", "./palcas train --resume --out x --episodes 40", resume=True)
        with open(os.path.join(out, "train.json")) as f:
            record = json.load(f)
        self.assertEqual(record["command_line"], "./palcas train --arm palcas --episodes 36")
        self.assertEqual(record["resumed_with"], ["./palcas train --resume --out x",
                                                  "./palcas train --resume --out x --episodes 40"])

    def test_message_key_is_made_once_and_owner_only(self):
        out = tempfile.mkdtemp()
        key = launch.message_key(out)
        first = open(key).read()
        self.assertEqual(len(first), 64)
        self.assertEqual(os.stat(key).st_mode & 0o777, 0o600)
        self.assertEqual(open(launch.message_key(out)).read(), first)


class DemandAndRanges(unittest.TestCase):
    """--demand / --ramp-demand for every episode, --demand-range / --pr-range drawn per
    episode from the training seed, recorded in train.json, one launch per drawn episode."""

    def opts(self, **kw):
        o = dict(train.DEFAULTS, seed=7, episodes=6, demand_range=[1000, 2200], pr_range=[20, 60])
        o.update(kw)
        return o

    def test_draws_are_uniform_in_the_ranges_and_follow_from_seed_and_episode(self):
        draws = [train.episode_draw(self.opts(), k) for k in range(200)]
        self.assertTrue(all(1000 <= d["demand_vphpl"] <= 2200 and 20 <= d["pr"] <= 60 for d in draws))
        self.assertEqual([d["seed"] for d in draws[:3]], [7, 8, 9])  # episode k: seed + k
        # Spread over the range (uniform: 200 draws reach both ends' tenths), not one value.
        self.assertLess(min(d["demand_vphpl"] for d in draws), 1120)
        self.assertGreater(max(d["demand_vphpl"] for d in draws), 2080)
        self.assertLess(min(d["pr"] for d in draws), 23)
        self.assertGreater(max(d["pr"] for d in draws), 57)
        self.assertGreater(len({d["pr"] for d in draws}), 150)
        # The same training seed and episode: the same draw, in whatever order asked.
        self.assertEqual(train.episode_draw(self.opts(), 5), draws[5])
        self.assertNotEqual(train.episode_draw(self.opts(seed=8), 5), draws[5])

    def test_without_ranges_every_episode_has_the_given_or_the_scenarios_values(self):
        d = train.episode_draw(self.opts(demand_range=None, pr_range=None, demand=1400.0, pr=40.0), 3)
        self.assertEqual((d["demand_vphpl"], d["pr"]), (1400, 40))
        d = train.episode_draw(self.opts(demand_range=None, demand=None), 3)
        self.assertIsNone(d["demand_vphpl"])  # the scenario's
        self.assertTrue(20 <= d["pr"] <= 60)

    def test_the_record_holds_ranges_and_every_episodes_draw(self):
        out = tempfile.mkdtemp()
        opts = self.opts(learning="", rsu_params="", bridge_params="", paper_printed=False, ramp_demand=450.0)
        train.write_record(out, opts, "abc")
        with open(os.path.join(out, "train.json")) as f:
            record = json.load(f)
        self.assertEqual((record["demand_range"], record["pr_range"], record["ramp_demand_vph"]),
                         ([1000, 2200], [20, 60], 450))
        self.assertIsNone(record["demand_vphpl"])
        self.assertEqual(record["episode_draws"], [train.episode_draw(opts, k) for k in range(6)])
        plain = dict(opts, demand_range=None, pr_range=None, demand=1800.0)
        train.write_record(out, plain, "abc")
        with open(os.path.join(out, "train.json")) as f:
            record = json.load(f)
        self.assertEqual(record["demand_vphpl"], 1800)
        self.assertNotIn("episode_draws", record)

    def test_resume_keeps_the_recorded_demand_and_refuses_another(self):
        out = tempfile.mkdtemp()
        with open(os.path.join(out, "train.json"), "w") as f:
            json.dump(dict(RECORD, demand_vphpl=None, ramp_demand_vph=None, demand_range=[1000, 2000],
                           pr_range=None), f)
        opts, _ = train.settle_options(given(), out, resume=True)
        self.assertEqual((opts["demand_range"], opts["demand"]), ([1000, 2000], None))
        with self.assertRaisesRegex(OptionError, "trained with --demand-range 1000,2000, not --demand-range 1000,2200"):
            train.settle_options(given(demand_range=[1000, 2200]), out, resume=True)
        with self.assertRaisesRegex(OptionError, r"trained with --demand \(the scenario's\), not --demand 1400"):
            train.settle_options(given(demand=1400.0), out, resume=True)
        # A record from before demand was an option: the scenario's demand, no ranges.
        opts, _ = train.settle_options(given(), self.old_record(), resume=True)
        self.assertEqual((opts["demand"], opts["demand_range"], opts["pr_range"]), (None, None, None))

    def old_record(self):
        out = tempfile.mkdtemp()
        with open(os.path.join(out, "train.json"), "w") as f:
            json.dump(RECORD, f)
        return out

    def test_bad_ranges_are_refused_naming_the_option(self):
        for argv, text in ((["--demand-range", "2000,1000"], "--demand-range '2000,1000': MIN 2000 is greater than MAX 1000"),
                           (["--demand-range", "1000"], "--demand-range '1000': expected MIN,MAX"),
                           (["--pr-range", "10,200"], r"--pr-range '10,200': MAX '200': expected a number in \[0, 100\]"),
                           (["--demand", "1000", "--demand-range", "1000,2000"], "--demand and --demand-range"),
                           (["--pr", "40", "--pr-range", "10,20"], "--pr and --pr-range")):
            with self.subTest(argv=argv), self.assertRaisesRegex(OptionError, text):
                train.check(argv)

    def launches(self, opts):
        """run_launches with a stand-in roslaunch that finishes the episodes it is given:
        the argument list of every launch."""
        out = tempfile.mkdtemp()
        calls = []

        class FakeProcess:
            def __init__(self, cmd, **_):
                self.cmd = cmd
                if "roslaunch" in cmd:
                    calls.append(cmd[cmd.index("system.launch") + 1:])
                    n = int([a for a in cmd if a.startswith("episodes:=")][0].split(":=")[1])
                    first = int([a for a in cmd if a.startswith("first_episode:=")][0].split(":=")[1])
                    with open(os.path.join(out, "metrics.json"), "w") as f:  # what the bridge writes
                        json.dump({"episode": first + n - 1}, f)
                    path = os.path.join(out, "episodes.csv")
                    fresh = not os.path.exists(path)
                    with open(path, "a") as f:
                        f.write("episode\n" if fresh else "")
                        f.write("x\n" * n)

            def wait(self, timeout=None):
                return 0

            def poll(self):
                return 0

            def terminate(self):
                pass

        real = train.subprocess.Popen
        train.subprocess.Popen = FakeProcess
        try:
            status = train.run_launches(out, opts, {"git_commit": "x"}, False, "test")
        finally:
            train.subprocess.Popen = real
        self.assertEqual(status, 0)
        self.out = out
        return [dict(a.split(":=", 1) for a in c) for c in calls]

    def test_drawn_episodes_each_get_their_own_launch_with_their_draw(self):
        opts = self.opts(episodes=3, scenario="tiny", duration=30.0)
        calls = self.launches(opts)
        self.assertEqual(len(calls), 3)
        for k, c in enumerate(calls):
            draw = train.episode_draw(opts, k)
            self.assertEqual((c["episodes"], c["first_episode"]), ("1", str(k)))
            self.assertEqual((float(c["demand"]), float(c["pr"])), (draw["demand_vphpl"], draw["pr"]))
            self.assertEqual(c["ramp_demand"], "scenario")
            self.assertEqual(c["resume"], "true" if k > 0 else "false")
        # Episode 0 ran alone: its metrics.json is kept in episode_0/ like the others'.
        with open(os.path.join(self.out, "episode_0", "metrics.json")) as f:
            self.assertEqual(json.load(f)["episode"], 0)

    def test_a_fixed_demand_keeps_one_launch_for_every_episode(self):
        calls = self.launches(self.opts(episodes=3, scenario="tiny", duration=30.0, demand_range=None,
                                        pr_range=None, demand=1400.0, ramp_demand=500.0, pr=40.0))
        self.assertEqual(len(calls), 1)
        self.assertEqual((calls[0]["episodes"], calls[0]["demand"], calls[0]["ramp_demand"], calls[0]["pr"]),
                         ("3", "1400", "500", "40"))
        calls = self.launches(self.opts(episodes=2, scenario="tiny", duration=30.0, demand_range=None, pr_range=None))
        self.assertEqual(calls[0]["demand"], "scenario")


class Simulations(unittest.TestCase):
    """--simulations K: what the options, the record and the folders say (the launches
    themselves: test/cli/train_simulations_test.sh)."""

    def test_bad_counts_and_combinations_are_refused_naming_the_option(self):
        for argv, text in ((["--simulations", "0"], "--simulations '0': expected an integer in \\[1, 64\\]"),
                           (["--simulations", "-2"], "--simulations '-2'"),
                           (["--simulations", "two"], "--simulations 'two'"),
                           (["--simulations", "65"], "--simulations '65'"),
                           (["--simulations", "2", "--arm", "independent"], "has no federation"),
                           (["--simulations", "2", "--pr-range", "10,20"], "not with --demand-range or --pr-range"),
                           (["--simulations", "2", "--episodes", "1001"], "at most 1000 --episodes"),
                           (["--plan"], "--plan"),
                           (["--in-process", "--rsu-nodes"], "give one of them"),
                           (["--simulations", "2", "--rsu-nodes"], "--rsu-nodes: not with --simulations 2")):
            with self.subTest(argv=argv), self.assertRaisesRegex(OptionError, text):
                train.check(argv)

    def test_one_simulation_is_todays_training(self):
        opts = train.check([])[0]
        self.assertEqual((opts["simulations"], opts["inprocess"]), (1, True))
        self.assertFalse(train.check(["--rsu-nodes"])[0]["inprocess"])
        self.assertTrue(train.check(["--in-process"])[0]["inprocess"])
        out = tempfile.mkdtemp()
        record = train.write_record(out, dict(opts, learning="", rsu_params="", bridge_params=""), "abc")
        self.assertNotIn("simulations", record)
        opts = train.check(["--simulations", "3"])[0]
        self.assertEqual((opts["simulations"], opts["inprocess"]), (3, True))

    def test_resume_keeps_the_recorded_count_and_refuses_another(self):
        out = tempfile.mkdtemp()
        opts = dict(train.check(["--simulations", "2", "--scenario", "tiny"])[0], learning="", rsu_params="",
                    bridge_params="")
        train.write_record(out, opts, "abc")
        self.assertEqual(train.check(["--resume", "--out", out])[0]["simulations"], 2)
        with self.assertRaisesRegex(OptionError, "trained with --simulations 2, not --simulations 3"):
            train.check(["--resume", "--out", out, "--simulations", "3"])

    def test_ids_seeds_and_folders_differ_per_simulation(self):
        self.assertEqual(train.simulation_rsu_ids("palcas", 2, 0), ["rsu_0", "rsu_1"])
        self.assertEqual(train.simulation_rsu_ids("palcas", 2, 2), ["rsu_0_s2", "rsu_1_s2"])
        self.assertEqual([train.simulation_seed(5, k) for k in range(3)], [5, 1005, 2005])
        self.assertEqual(train.simulation_dir("/o", 1), "/o/sim1")
        args = train.federation_launch_args(dict(train.DEFAULTS, simulations=2), "/o", 2, "/o/auth.key")
        self.assertIn("expected_rsus:=[rsu_0, rsu_1, rsu_0_s1, rsu_1_s1]", args)

    def test_episodes_csv_merges_every_simulation_with_its_column(self):
        out = tempfile.mkdtemp()
        for k, rows in ((0, ["0,1,600", "1,2,600"]), (1, ["0,1001,600"])):
            os.makedirs(train.simulation_dir(out, k))
            with open(os.path.join(train.simulation_dir(out, k), "episodes.csv"), "w") as f:
                f.write("episode,seed,sim_seconds\n" + "".join(r + "\n" for r in rows))
        train.merge_simulation_episodes(out, 2)
        with open(os.path.join(out, "episodes.csv")) as f:
            self.assertEqual(f.read(), "simulation,episode,seed,sim_seconds\n0,0,1,600\n1,0,1001,600\n0,1,2,600\n")
        self.assertEqual(train.training_episodes_done(out, {"simulations": 2}), 1)
        self.assertEqual(train.training_episodes_done(out, {"simulations": 1}), 3)


class Roads(unittest.TestCase):
    def test_clusters_come_from_the_roads_description(self):
        self.assertEqual(train.scenario_clusters("paper"), 3)
        self.assertEqual(train.scenario_clusters("tiny"), 2)


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
            self.assertEqual(train.scenario_clusters(folder.name), road["clusters"], folder.name)
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

    def test_training_md_names_the_starting_command_and_its_resumes(self):
        src = self.training("")
        record = json.loads((src / "train.json").read_text())
        record.update(command_line="./palcas train --arm palcas --episodes 4",
                      resumed_with=["./palcas train --resume --out train-x"])
        (src / "train.json").write_text(json.dumps(record))
        (src / "manifest.json").write_text(json.dumps({"command_line": "./palcas train --resume --out train-x"}))
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(src), str(dest), rsu_models=True)
        self.assertIn("- command: `./palcas train --arm palcas --episodes 4`, continued with "
                      "`./palcas train --resume --out train-x`", (dest / "TRAINING.md").read_text())

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

    def test_run_with_rsu_carries_rsu_parameters_and_says_so(self):
        rsu = pathlib.Path(tempfile.mkdtemp()) / "no_left_for_exit.yaml"
        rsu.write_text("rsu:\n  no_left_for_exit_within_m: 100000.0\n")
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(self.training("")), str(dest), rsu_models=True, run_rsu=str(rsu))
        self.assertEqual((dest / "rsu.yaml").read_text(), rsu.read_text())
        self.assertEqual(json.loads((dest / "train.json").read_text())["runs_with_rsu"], "rsu.yaml")
        self.assertIn("its RSUs run under the parameters in `rsu.yaml` (over config/departures.yaml), which its "
                      "training did not use (`no_left_for_exit.yaml`; trained without one)",
                      (dest / "TRAINING.md").read_text())
        # Trained under the same parameters: said so, not "did not use".
        src = self.training("")
        record = json.loads((src / "train.json").read_text())
        (src / "train.json").write_text(json.dumps(dict(record, rsu_params=str(rsu))))
        ship_policy.main(str(src), str(dest), rsu_models=True, run_rsu=str(rsu))
        self.assertIn("(over config/departures.yaml), the ones its training used (`no_left_for_exit.yaml`)",
                      (dest / "TRAINING.md").read_text())
        with self.assertRaises(SystemExit) as e:
            ship_policy.main(str(self.training("")), str(dest), run_rsu="/nonexistent.yaml")
        self.assertIn("--run-with-rsu: no such file /nonexistent.yaml", str(e.exception.code))
        self.assertTrue((dest / "rsu.yaml").exists())  # the folder shipped before is kept
        ship_policy.main(str(self.training("")), str(dest), rsu_models=True)
        self.assertFalse((dest / "rsu.yaml").exists())  # without the flag, none

    def test_a_schedule_recorded_in_another_checkout_is_taken_from_the_training_folder(self):
        src = self.training("")
        record = json.loads((src / "train.json").read_text())
        record["learning"] = "results/train-x/learning_schedule.yaml"  # relative to the worktree that trained
        (src / "train.json").write_text(json.dumps(record))
        (src / "learning_schedule.yaml").write_text("learning:\n  epsilon_start: 1.0\n")
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(src), str(dest), rsu_models=True)
        self.assertEqual((dest / "learning_schedule.yaml").read_text(), "learning:\n  epsilon_start: 1.0\n")
        self.assertEqual(json.loads((dest / "train.json").read_text())["learning"], "learning_schedule.yaml")
        (src / "learning_schedule.yaml").unlink()
        with self.assertRaises(SystemExit) as e:
            ship_policy.main(str(src), str(dest), rsu_models=True)
        self.assertIn("learning parameters", str(e.exception.code))
        self.assertTrue((dest / "learning_schedule.yaml").exists(), "the folder shipped before is kept")

    def test_the_record_says_how_pr_and_demand_were_drawn(self):
        src = self.training("")
        record = json.loads((src / "train.json").read_text())
        record.update(pr_range=[5.0, 60.0], demand_range=[800.0, 2400.0])
        (src / "train.json").write_text(json.dumps(record))
        dest = pathlib.Path(tempfile.mkdtemp()) / "policy"
        ship_policy.main(str(src), str(dest), rsu_models=True)
        text = (dest / "TRAINING.md").read_text()
        self.assertIn("PR drawn per episode from 5-60 %, mainline demand drawn per episode from 800-2400 veh/h/lane",
                      text)
        self.assertEqual(ship_policy.traffic_text(dict(pr=60, demand_vphpl=1000.0)),
                         "PR 60 %, mainline demand 1000 veh/h/lane")

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
