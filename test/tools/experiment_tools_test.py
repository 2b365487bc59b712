#!/usr/bin/env python3
"""Tests of the experiment planner and collector (tools/palcas_cli/experiment.py,
tools/experiment_results.py), the interval arithmetic (tools/palcas_stats.py) and the
figure functions (tools/run_figures.py), on fake run folders and a tiny recorded episode
(fixtures/tiny_run: 60 s of the tiny road, keep and sumo_native, seed 101).

usage: experiment_tools_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import argparse
import contextlib
import csv
import io
import json
import math
import pathlib
import shutil
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIXTURE = pathlib.Path(__file__).resolve().parent / "fixtures" / "tiny_run"
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_cli import experiment  # noqa: E402
import eval_table  # noqa: E402
import loop_cost  # noqa: E402
import experiment_results  # noqa: E402
import palcas_stats  # noqa: E402
import run_figures  # noqa: E402
import seed_ratio  # noqa: E402
import training_pace  # noqa: E402
import ratio_by_demand  # noqa: E402
import comfort_breakdown  # noqa: E402
import lane_change_breakdown  # noqa: E402
import exit_check  # noqa: E402
import v2x_table  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402


def args(**kw):
    # The dev seed set (101, 102, ...): the fake points below are named after its seeds.
    base = dict(arms="keep,sumo_native", prs="5,60", seeds=2, seed_set="dev", duration=600.0,
                scenario="tiny", policy=None, jobs=1, demands=None, v2x="", bridge_params="", inprocess=False)
    base.update(kw)
    return argparse.Namespace(**base)


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class IntervalTest(unittest.TestCase):
    def test_hand_computed_intervals(self):
        mean, half = palcas_stats.mean_ci95([1.0, 2.0, 3.0])  # sd 1, t(2) = 4.303
        self.assertAlmostEqual(mean, 2.0)
        self.assertAlmostEqual(half, 4.303 / math.sqrt(3), places=9)
        mean, half = palcas_stats.mean_ci95([10.0, 12.0])  # sd sqrt(2), t(1) = 12.706
        self.assertAlmostEqual(mean, 11.0)
        self.assertAlmostEqual(half, 12.706, places=9)
        mean, half = palcas_stats.mean_ci95([5.0, 5.0, 5.0, 5.0])
        self.assertEqual(half, 0.0)

    def test_edges(self):
        self.assertTrue(math.isnan(palcas_stats.mean_ci95([4.0])[1]))
        self.assertEqual(palcas_stats.t975(31), 1.96)
        self.assertEqual(palcas_stats.t975(30), 2.042)
        with self.assertRaises(ValueError):
            palcas_stats.mean_ci95([])
        with self.assertRaises(ValueError):
            palcas_stats.mean_ci95([1.0, float("nan")])
        self.assertEqual(palcas_stats.format_ci(1.234, float("nan"), 1), "1.2")
        self.assertEqual(palcas_stats.format_ci(1.234, 0.55, 1), "1.2 ± 0.6")


class PlannerTest(unittest.TestCase):
    def setUp(self):
        self.out = pathlib.Path(tempfile.mkdtemp(prefix="palcas_exp_test_"))

    def tearDown(self):
        shutil.rmtree(self.out, ignore_errors=True)

    def test_points_plan_and_slurm_array(self):
        s = experiment.settings_from_args(args())
        self.assertEqual(s["seeds"], [101, 102])
        pts = experiment.points_of(s)
        self.assertEqual(len(pts), 2 * 2 * 2)
        self.assertEqual(len({p["name"] for p in pts}), 8)
        self.assertIn("keep_pr60_s102", {p["name"] for p in pts})
        # Only the first seed records trajectories (the figures' run).
        self.assertTrue(all(p["trajectories"] == (p["seed"] == 101) for p in pts))
        experiment.save_settings(self.out, s)
        self.assertEqual(experiment.write_plan(self.out, s), 8)
        lines = (self.out / "plan.txt").read_text().splitlines()
        self.assertEqual(len(lines), 8)
        self.assertTrue(all("./palcas experiment --point " in line for line in lines))
        self.assertIn("#SBATCH --array=1-8", (self.out / "slurm_array.sh").read_text())

    def test_in_process_reaches_every_point_and_may_change_between_calls(self):
        s = experiment.settings_from_args(args())
        p = experiment.points_of(s)[0]
        self.assertNotIn("--in-process", experiment.point_argv(s, p, self.out / "p"))
        experiment.save_settings(self.out, s)
        merged = experiment.merge_settings(self.out, experiment.settings_from_args(args(inprocess=True)))
        self.assertTrue(merged["inprocess"])
        argv = experiment.point_argv(merged, p, self.out / "p")
        self.assertIn("--in-process", argv)
        self.assertEqual(argv[:4], ["--arm", p["arm"], "--no-compare", "--pr"])

    def test_bad_options_are_named(self):
        for kw, text in ((dict(arms="keep,nope"), "nope"), (dict(prs="5,101"), "101"),
                         (dict(prs="5,5"), "twice"), (dict(seeds=0), "--seeds"),
                         (dict(duration=0.0), "--duration"), (dict(scenario="nope"), "nope"),
                         (dict(arms="no_priority", policy=["no_priority=/nonexistent"]), "no trained policy")):
            with self.assertRaises(experiment.UsageError) as e:
                experiment.settings_from_args(args(**kw))
            self.assertIn(text, str(e.exception))

    def test_demands_are_a_dimension_of_the_points(self):
        s = experiment.settings_from_args(args(demands="1000,1800"))
        self.assertEqual(s["demands"], [1000.0, 1800.0])
        pts = experiment.points_of(s)
        self.assertEqual(len(pts), 2 * 2 * 2 * 2)
        self.assertIn("keep_pr60_d1800_s102", {p["name"] for p in pts})
        self.assertEqual({p["demand"] for p in pts}, {1000.0, 1800.0})
        # The first seed of every demand records trajectories.
        self.assertEqual(sum(p["trajectories"] for p in pts), 2 * 2 * 2)
        # Without --demands: the names and points of before, at the scenario's demand.
        plain = experiment.points_of(experiment.settings_from_args(args()))
        self.assertEqual({p["demand"] for p in plain}, {None})
        self.assertIn("keep_pr60_s102", {p["name"] for p in plain})
        for bad, text in (("1000,0", "0 is outside"), ("1000,1000", "twice"), ("x", "'x' is not valid"),
                          ("200000", r"outside \(0, 100000\]")):
            with self.assertRaisesRegex(experiment.UsageError, text):
                experiment.settings_from_args(args(demands=bad))

    def test_an_experiment_keeps_its_kind_of_demand(self):
        experiment.save_settings(self.out, experiment.settings_from_args(args()))
        with self.assertRaisesRegex(experiment.UsageError, "the scenario's own demand"):
            experiment.merge_settings(self.out, experiment.settings_from_args(args(demands="1400")))
        experiment.save_settings(self.out, experiment.settings_from_args(args(demands="1400")))
        with self.assertRaisesRegex(experiment.UsageError, "--demands 1400"):
            experiment.merge_settings(self.out, experiment.settings_from_args(args()))
        merged = experiment.merge_settings(self.out, experiment.settings_from_args(args(demands="1800,1400")))
        self.assertEqual(merged["demands"], [1400.0, 1800.0])

    def test_a_channel_or_bridge_override_is_part_of_the_settings(self):
        cases = (("v2x", "--v2x", "v2x: {enabled: true}\n"),
                 ("bridge_params", "--bridge-params", "guard_busy_lc_assertive: 2.0\n"))
        for key, option, content in cases:
            with self.subTest(option=option):
                with self.assertRaises(experiment.UsageError) as e:
                    experiment.settings_from_args(args(**{key: "/no/such/file.yaml"}))
                self.assertIn(f"{option} /no/such/file.yaml: no such file", str(e.exception))
                experiment.save_settings(self.out, experiment.settings_from_args(args()))
                given = self.out / f"{key}.yaml"
                given.write_text(content)
                with_file = experiment.settings_from_args(args(**{key: str(given)}))
                self.assertEqual(with_file[key], str(given.resolve()))
                with self.assertRaises(experiment.UsageError) as e:
                    experiment.merge_settings(self.out, with_file)
                self.assertIn(key, str(e.exception))

    def test_seeds_come_from_a_named_set(self):
        s = experiment.settings_from_args(args(seed_set="test", seeds=3))
        self.assertEqual((s["seed_set"], s["seeds"]), ("test", [1001, 1002, 1003]))
        self.assertEqual(experiment.settings_from_args(args())["seed_set"], "dev")
        # The command line's default is the test set.
        _, a = experiment.parse(["--out", str(self.out), "--arms", "keep", "--scenario", "tiny"])
        self.assertEqual(a.seed_set, "test")
        self.assertEqual(experiment.settings_from_args(a)["seeds"], [1001, 1002, 1003])
        for kw, text in ((dict(seed_set="test", seeds=31), "seed set 'test' has 30 seeds (1001-1030), not 31"),
                         (dict(seed_set="nope"), "unknown seed set 'nope' (config/seeds.yaml has dev, test)")):
            with self.assertRaisesRegex(experiment.UsageError, text.replace("(", r"\(").replace(")", r"\)")):
                experiment.settings_from_args(args(**kw))
        experiment.save_settings(self.out, s)
        self.assertEqual(json.loads((self.out / "experiment.json").read_text())["seed_set"], "test")

    def test_an_experiment_keeps_its_seed_set(self):
        experiment.save_settings(self.out, experiment.settings_from_args(args(seed_set="test")))
        with self.assertRaisesRegex(experiment.UsageError, "seed set 'test' .*not on seed set 'dev'"):
            experiment.merge_settings(self.out, experiment.settings_from_args(args(seed_set="dev")))
        merged = experiment.merge_settings(self.out, experiment.settings_from_args(args(seed_set="test", seeds=4)))
        self.assertEqual(merged["seeds"], [1001, 1002, 1003, 1004])
        # A folder from before the seed sets (101.. and no seed_set) is the dev set's.
        old = experiment.settings_from_args(args())
        del old["seed_set"]
        experiment.save_settings(self.out, old)
        self.assertEqual(experiment.merge_settings(self.out, experiment.settings_from_args(args(seeds=3)))["seed_set"],
                         "dev")
        with self.assertRaisesRegex(experiment.UsageError, "seed set 'dev'"):
            experiment.merge_settings(self.out, experiment.settings_from_args(args(seed_set="test")))

    def test_training_seeds_are_still_refused(self):
        policy = self.out / "policy"
        shutil.copytree(ROOT / "policies" / "palcas", policy,
                        ignore=shutil.ignore_patterns("checkpoints", "*.csv", "*.md", "*.png"))
        (policy / "checkpoints").mkdir()
        record = json.loads((policy / "train.json").read_text())
        record.update(seed=1000, episodes=3)  # trained on 1000, 1001, 1002
        (policy / "train.json").write_text(json.dumps(record))
        with self.assertRaisesRegex(experiment.UsageError, r"seed\(s\) \[1001, 1002\] were training seeds"):
            experiment.settings_from_args(args(arms="palcas", seed_set="test", seeds=3, scenario="paper",
                                               policy=[f"palcas={policy}"]))

    def test_continuation_extends_but_never_changes_duration(self):
        s = experiment.settings_from_args(args())
        experiment.save_settings(self.out, s)
        with self.assertRaises(experiment.UsageError) as e:
            experiment.merge_settings(self.out, experiment.settings_from_args(args(duration=900.0)))
        self.assertIn("duration_s", str(e.exception))
        merged = experiment.merge_settings(self.out, experiment.settings_from_args(args(prs="60,40")))
        self.assertEqual(merged["prs"], [5.0, 60.0, 40.0])


def fake_point(out, name, arm, sim_seconds, status=None, dsr=None, speed=20.0, throughput=None):
    d = out / "points" / name
    (d / arm).mkdir(parents=True, exist_ok=True)
    if sim_seconds is not None:
        m = {"sim_seconds": sim_seconds, "efficiency_all_mps": speed, "collision_rate_pct": 0.0,
             "dsr_pct": dsr, "msr_pct": 100.0, "comfort_share_pct": 80.0, "throughput_vph": throughput}
        (d / arm / "metrics.json").write_text(json.dumps(m))
    if status:
        (d / "point.json").write_text(json.dumps({"status": status, "wall_s": 10.0,
                                                  "error": "rsu_0 died" if status == "failed" else ""}))


class CollectorTest(unittest.TestCase):
    def setUp(self):
        self.out = pathlib.Path(tempfile.mkdtemp(prefix="palcas_collect_test_"))
        self.s = experiment.settings_from_args(args(arms="keep", prs="60", seeds=4))
        experiment.save_settings(self.out, self.s)
        self.pts = experiment.points_of(self.s)
        fake_point(self.out, "keep_pr60_s101", "keep", 600.0, "done", dsr=30.0)
        fake_point(self.out, "keep_pr60_s102", "keep", 600.0, None, dsr=40.0)   # ran elsewhere
        fake_point(self.out, "keep_pr60_s103", "keep", 250.0, None, dsr=99.0)   # interrupted
        fake_point(self.out, "keep_pr60_s104", "keep", 600.0, "failed", dsr=99.0)

    def tearDown(self):
        shutil.rmtree(self.out, ignore_errors=True)

    def test_finished_points_are_never_rerun(self):
        done = {p["name"]: experiment.finished(self.out, p, 600.0) for p in self.pts}
        self.assertEqual(done, {"keep_pr60_s101": True, "keep_pr60_s102": True,
                                "keep_pr60_s103": False, "keep_pr60_s104": False})

    def test_tables_count_only_finished_points(self):
        code = experiment_results.collect(self.out, self.s, self.pts)
        self.assertEqual(code, 1)  # not every point is in
        rows = {r["point"]: r for r in read_csv(self.out / "results.csv")}
        self.assertEqual([rows[n]["status"] for n in sorted(rows)],
                         ["done", "done", "incomplete", "failed"])
        self.assertEqual(rows["keep_pr60_s104"]["error"], "rsu_0 died")
        dsr = read_csv(self.out / "table_dsr_pct.csv")
        self.assertEqual(len(dsr), 1)
        self.assertEqual(dsr[0]["n"], "2")
        self.assertAlmostEqual(float(dsr[0]["mean"]), 35.0)
        self.assertAlmostEqual(float(dsr[0]["ci95_half"]), 12.706 * math.sqrt(50.0) / math.sqrt(2), places=3)
        md = (self.out / "tables.md").read_text()
        self.assertIn("keep_pr60_s103 (incomplete)", md)
        self.assertIn("keep_pr60_s104 (failed)", md)

    def test_the_trials_columns_are_in_results_csv(self):
        # A bridge that writes the new keys: their values; one from before them: empty cells.
        m = self.out / "points" / "keep_pr60_s101" / "keep" / "metrics.json"
        d = json.loads(m.read_text())
        d.update(efficiency_steady_mps=21.5, unserved_vehicles=7, dsr_censored_pct=88.0, cav_collisions=1,
                 cavs_seen=400, exits_ok=90, exiting_cavs=100, exiting_cavs_censored=3)
        m.write_text(json.dumps(d))
        experiment_results.collect(self.out, self.s, self.pts)
        rows = {r["point"]: r for r in read_csv(self.out / "results.csv")}
        for key in ("efficiency_steady_mps", "insertion_waiting_end", "unserved_vehicles", "total_time_spent_veh_h",
                    "exiting_cavs_censored", "dsr_censored_pct", "merging_cavs_censored", "msr_censored_pct",
                    "cav_collisions", "cavs_seen", "exits_ok", "exiting_cavs", "arrived", "throughput_vph",
                    "lane_changes_per_cav", "comfort_share_pct", "collision_rate_pct", "efficiency_all_mps",
                    "insertion_dropped", "decision_ms_p99"):
            self.assertIn(key, rows["keep_pr60_s101"], key)
        self.assertEqual((rows["keep_pr60_s101"]["efficiency_steady_mps"], rows["keep_pr60_s101"]["unserved_vehicles"],
                          rows["keep_pr60_s101"]["exiting_cavs_censored"]), ("21.5", "7", "3"))
        self.assertEqual((rows["keep_pr60_s102"]["efficiency_steady_mps"], rows["keep_pr60_s102"]["dsr_censored_pct"]),
                         ("", ""))

    def test_experiments_run_apart_merge_into_one_table(self):
        experiment_results.collect(self.out, self.s, self.pts)
        # A second experiment with another arm, as if run in another session.
        other = self.out / "other"
        other.mkdir()
        with open(other / "results.csv", "w", newline="") as f:
            rows = read_csv(self.out / "results.csv")
            w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
            w.writeheader()
            for r in rows:
                w.writerow(dict(r, point=r["point"].replace("keep", "independent"),
                                arm="independent"))
        merged = self.out / "merged"
        experiment_results.merge(merged, [self.out / "results.csv", other / "results.csv"],
                                 [101, 102, 103, 104], 1800.0, "tiny")
        dsr = read_csv(merged / "table_dsr_pct.csv")
        self.assertEqual([r["arm"] for r in dsr], ["keep", "independent"])
        self.assertEqual(dsr[0]["mean"], dsr[1]["mean"])
        self.assertEqual(dsr[1]["n"], "2")  # only finished points count, as in collect
        self.assertIn("Baseline-2 (independent)", (merged / "tables.md").read_text())
        with self.assertRaisesRegex(ValueError, "already in another results.csv"):
            experiment_results.merge(merged, [other / "results.csv", other / "results.csv"],
                                     [101, 102, 103, 104], 1800.0, "tiny")

    def test_a_results_csv_from_before_a_metric_column_merges(self):
        # An older experiment's results.csv has no throughput_vph column: its arm's cells of
        # that metric stay empty, the other metrics are tabled.
        experiment_results.collect(self.out, self.s, self.pts)
        old = self.out / "old"
        old.mkdir()
        rows = read_csv(self.out / "results.csv")
        fields = [k for k in rows[0].keys() if k != "throughput_vph"]
        with open(old / "results.csv", "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
            w.writeheader()
            for r in rows:
                w.writerow(dict(r, point=r["point"].replace("keep", "sumo_native"), arm="sumo_native"))
        merged = self.out / "merged_old"
        experiment_results.merge(merged, [self.out / "results.csv", old / "results.csv"],
                                 [101, 102, 103, 104], 1800.0, "tiny")
        dsr = {r["arm"]: r for r in read_csv(merged / "table_dsr_pct.csv")}
        self.assertEqual(dsr["sumo_native"]["n"], "2")
        self.assertEqual(dsr["sumo_native"]["mean"], dsr["keep"]["mean"])
        throughput = {r["arm"]: r for r in read_csv(merged / "table_throughput_vph.csv")}
        self.assertEqual((throughput["sumo_native"]["n"], throughput["sumo_native"]["mean"]), ("0", ""))

    def test_paper_numbers_sit_beside_ours(self):
        paper = experiment_results.read_paper()
        self.assertEqual(paper[("palcas", 60.0, "dsr_pct")], (93.97, 3.56))
        self.assertEqual(paper[("no_priority", 5.0, "collision_rate_pct")], (35.97, 9.65))
        self.assertEqual(len(paper), 4 * 5 * 4)
        fake_point(self.out, "palcas_pr60_s101", "palcas", 600.0, "done", dsr=90.0)
        s = dict(self.s, arms=["palcas", "keep"])
        experiment_results.collect(self.out, s, experiment.points_of(s))
        md = (self.out / "tables.md").read_text()
        self.assertIn("PALCAS, paper", md)
        self.assertIn("*94.0 ± 3.6*", md)


class DemandCollectorTest(unittest.TestCase):
    """Tables per demand, the worst seed beside the mean, JAM against SUMO-native on the same
    traffic, and the capacity figure."""

    def setUp(self):
        self.out = pathlib.Path(tempfile.mkdtemp(prefix="palcas_demand_test_"))
        self.s = experiment.settings_from_args(args(arms="keep,sumo_native", prs="60", seeds=3,
                                                    demands="1000,1800"))
        experiment.save_settings(self.out, self.s)
        self.pts = experiment.points_of(self.s)
        # SUMO-native 25 m/s at 1000, 20 m/s at 1800; keep the same but seed 102 at 1800
        # jams (9 < 0.5 x 20) and seed 103 at 1000 is slow but no jam (13 > 12.5).
        speeds = {("keep", 1000, 101): 24.0, ("keep", 1000, 102): 26.0, ("keep", 1000, 103): 13.0,
                  ("keep", 1800, 101): 19.0, ("keep", 1800, 102): 9.0, ("keep", 1800, 103): 21.0}
        for p in self.pts:
            native = 25.0 if p["demand"] == 1000 else 20.0
            speed = speeds.get((p["arm"], int(p["demand"]), p["seed"]), native)
            fake_point(self.out, p["name"], p["arm"], 600.0, "done", dsr=50.0 + p["seed"] - 100,
                       speed=speed, throughput=3 * p["demand"] * speed / 25.0)

    def tearDown(self):
        shutil.rmtree(self.out, ignore_errors=True)

    def test_jams_worst_seeds_and_tables_per_demand(self):
        self.assertEqual(experiment_results.collect(self.out, self.s, self.pts), 0)
        rows = {r["point"]: r for r in read_csv(self.out / "results.csv")}
        self.assertEqual(rows["keep_pr60_d1800_s102"]["demand"], "1800.0")
        self.assertEqual(rows["keep_pr60_d1800_s102"]["jam"], "yes")
        self.assertEqual(rows["keep_pr60_d1000_s103"]["jam"], "no")
        self.assertEqual(rows["sumo_native_pr60_d1000_s101"]["jam"], "no")
        speed = {(r["arm"], r["demand"]): r for r in read_csv(self.out / "table_efficiency_all_mps.csv")}
        self.assertEqual(len(speed), 4)  # 2 arms x 2 demands at one PR
        self.assertAlmostEqual(float(speed[("keep", "1800")]["mean"]), (19.0 + 9.0 + 21.0) / 3, places=4)
        self.assertEqual((speed[("keep", "1800")]["worst"], speed[("keep", "1800")]["worst_seed"]), ("9.0", "102"))
        self.assertEqual(speed[("keep", "1800")]["jam_seeds"], "102")
        self.assertEqual(speed[("keep", "1000")]["jam_seeds"], "")
        dsr = {(r["arm"], r["demand"]): r for r in read_csv(self.out / "table_dsr_pct.csv")}
        self.assertEqual((dsr[("keep", "1000")]["worst"], dsr[("keep", "1000")]["worst_seed"]), ("51.0", "101"))
        md = (self.out / "tables.md").read_text()
        self.assertIn("### demand 1000 veh/h/lane", md)
        self.assertIn("### demand 1800 veh/h/lane", md)
        self.assertIn("(worst 9.00, s102) **JAM** (s102)", md)
        self.assertIn("**JAM** (1 point(s) below 0.5 x SUMO-native's speed on the same traffic): "
                      "keep_pr60_d1800_s102 (9.00 m/s)", md)
        self.assertIn("(worst 13.00, s103)", md)

    def test_capacity_figure_has_a_line_per_arm_over_demand(self):
        experiment_results.collect(self.out, self.s, self.pts)
        self.assertGreater((self.out / "figures" / "capacity.png").stat().st_size, 10000)
        cap = {(r["arm"], r["demand"], r["metric"]): r for r in read_csv(self.out / "figures" / "capacity.csv")}
        self.assertEqual(len(cap), 2 * 2 * 2)  # arms x demands x (speed, throughput)
        native = cap[("sumo_native", "1800", "efficiency_all_mps")]
        self.assertEqual((native["n"], float(native["mean"]), float(native["ci95_half"])), ("3", 20.0, 0.0))
        keep = cap[("keep", "1000", "throughput_vph")]
        self.assertAlmostEqual(float(keep["mean"]), 3 * 1000 * (24.0 + 26.0 + 13.0) / 3 / 25.0, places=3)
        self.assertGreater(float(keep["ci95_half"]), 0.0)

    def test_arms_evaluated_apart_merge_into_one_capacity_figure(self):
        experiment_results.collect(self.out, self.s, self.pts)
        rows = read_csv(self.out / "results.csv")
        apart = {}
        for arm in ("keep", "sumo_native"):  # as if each arm had been its own experiment
            apart[arm] = self.out / ("only_" + arm + ".csv")
            with open(apart[arm], "w", newline="") as f:
                w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
                w.writeheader()
                w.writerows(r for r in rows if r["arm"] == arm)
        merged = self.out / "merged"
        experiment_results.merge(merged, [apart["keep"], apart["sumo_native"]], [101, 102, 103], 600.0, "tiny")
        cap = {(r["arm"], r["demand"], r["metric"]) for r in read_csv(merged / "figures" / "capacity.csv")}
        self.assertEqual(len(cap), 2 * 2 * 2)  # both arms, both demands, speed and throughput
        self.assertGreater((merged / "figures" / "capacity.png").stat().st_size, 10000)

    def test_without_sumo_native_jams_are_not_checked_and_old_folders_still_collect(self):
        s = experiment.settings_from_args(args(arms="keep", prs="60", seeds=2))  # no --demands
        out = self.out / "old"
        experiment.save_settings(out, s)
        pts = experiment.points_of(s)
        for p in pts:
            fake_point(out, p["name"], "keep", 600.0, "done", dsr=40.0, speed=5.0)
        self.assertEqual(experiment_results.collect(out, s, pts), 0)
        rows = read_csv(out / "results.csv")
        self.assertEqual({r["demand"] for r in rows}, {"1000.0"})  # the tiny scenario's own
        self.assertEqual({r["jam"] for r in rows}, {""})
        self.assertIn("Jams not checked: no sumo_native arm", (out / "tables.md").read_text())
        self.assertFalse((out / "figures" / "capacity.png").exists())
        # A results.csv from before the demand column merges at the scenario's demand.
        old_csv = out / "old_results.csv"
        with open(old_csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=[k for k in rows[0] if k not in ("demand", "jam")])
            w.writeheader()
            for r in rows:
                w.writerow({k: v for k, v in r.items() if k in w.fieldnames})
        merged = experiment_results.merge(out / "merged", [old_csv], [101, 102], 600.0, "tiny")
        self.assertEqual({r["demand"] for r in merged}, {1000.0})
        self.assertEqual(read_csv(out / "merged" / "table_dsr_pct.csv")[0]["demand"], "1000")


class EvalTableTest(unittest.TestCase):
    def test_worst_run_and_jams_against_sumo_native_of_the_same_run(self):
        base = pathlib.Path(tempfile.mkdtemp(prefix="palcas_eval_test_"))
        for run, keep_speed in (("run-s101", 22.0), ("run-s102", 9.0)):
            for arm, speed in (("keep", keep_speed), ("sumo_native", 20.0)):
                (base / run / arm).mkdir(parents=True)
                (base / run / arm / "metrics.json").write_text(json.dumps(
                    {"efficiency_all_mps": speed, "dsr_pct": 40.0 if run == "run-s101" else 60.0}))
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            eval_table.main([str(base / "run-s101"), str(base / "run-s102")])
        out = text.getvalue()
        self.assertIn("(worst 9.00, run-s102) **JAM**", out)
        self.assertIn("(worst 40.0, run-s101)", out)
        self.assertIn("JAM: keep in run-s102: 9.00 m/s < 0.5 x sumo_native's 20.00 m/s", out)
        self.assertNotIn("JAM: sumo_native", out)
        shutil.rmtree(base, ignore_errors=True)


class V2xTableTest(unittest.TestCase):
    """tools/v2x_table.py: a row per channel setting, ratios to SUMO-native of the same seed."""

    def write(self, out, v2x_file, arms, speeds, v2x=None):
        (out).mkdir(parents=True)
        (out / "experiment.json").write_text(json.dumps({"v2x": v2x_file}))
        for arm in arms:
            for seed, speed in zip((101, 102), speeds[arm]):
                d = out / "points" / f"{arm}_pr60_s{seed}"
                (d / arm).mkdir(parents=True)
                (d / "point.json").write_text(json.dumps({"arm": arm, "seed": seed}))
                m = {"efficiency_all_mps": speed, "dsr_pct": 95.0, "msr_pct": 99.0, "collision_rate_pct": 0.0,
                     "comfort_share_pct": 85.0, "decision_ms_p99": 2.0}
                if v2x:
                    m["v2x"] = v2x
                (d / arm / "metrics.json").write_text(json.dumps(m))

    def test_a_row_per_setting_against_sumo_native_of_the_same_seed(self):
        base = pathlib.Path(tempfile.mkdtemp(prefix="palcas_v2x_test_"))
        self.write(base / "off", "", ("palcas", "keep", "sumo_native"),
                   {"palcas": (27.0, 28.0), "keep": (28.0, 28.0), "sumo_native": (30.0, 28.0)})
        link = {"latency_s": 0.1, "jitter_s": 0.0, "loss_probability": 0.1}
        self.write(base / "impaired", "/x/impaired.yaml", ("palcas",), {"palcas": (24.0, 28.0)},
                   v2x={"vehicle_state": link, "advisory": link, "cluster_state": link, "advisories_sent": 100,
                        "advisories_lost": 10, "advisories_applied_late": 90, "advisories_out_of_range": 0,
                        "advisories_too_old": 0, "advice_mean_age_s": 0.1})
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            v2x_table.main([str(base / "off"), str(base / "impaired")])
        lines = text.getvalue().splitlines()
        off = next(l for l in lines if l.startswith("| palcas, off"))
        impaired = next(l for l in lines if l.startswith("| palcas, 100 ms, 10 % lost"))
        self.assertIn("(worst 0.900)", off)       # 27 / 30 on seed 101
        self.assertIn("(worst 0.800)", impaired)  # 24 / 30 on seed 101
        self.assertIn("| 10.0 | 90.0 | 0.0 | 0.0 | 0.10 |", impaired)
        self.assertTrue(any(l.startswith("| keep (no advice to impair)") for l in lines))
        shutil.rmtree(base, ignore_errors=True)


class FiguresTest(unittest.TestCase):
    def setUp(self):
        self.out = pathlib.Path(tempfile.mkdtemp(prefix="palcas_fig_test_"))
        self.trajs = {a: run_figures.read_trajectories(FIXTURE / a / "trajectories.csv")
                      for a in ("keep", "sumo_native")}

    def tearDown(self):
        shutil.rmtree(self.out, ignore_errors=True)

    def assertFigure(self, name):
        self.assertTrue((self.out / f"{name}.png").stat().st_size > 5000, name)
        return read_csv(self.out / f"{name}.csv")

    def test_speed_over_time(self):
        run_figures.speed_over_time(self.trajs, str(self.out / "sot"), bin_s=10.0)
        rows = self.assertFigure("sot")
        self.assertEqual(list(rows[0]), ["time_s", "keep_mps", "sumo_native_mps"])
        t = self.trajs["keep"]
        on = [tt for tt, p in zip(t["time_s"], t["part"]) if p in ("mainline", "accel_lane")]
        self.assertEqual(len(rows), len({math.floor(tt / 10.0) for tt in on}))  # bins [10k, 10k+10)
        self.assertTrue(all(0.0 < float(r["keep_mps"]) < 40.0 for r in rows))

    def test_space_time(self):
        run_figures.space_time(self.trajs["keep"], "keep", str(self.out / "st"), dx_m=50.0, dt_s=10.0)
        rows = self.assertFigure("st")
        self.assertTrue(all(float(r["x_start_m"]) % 50.0 == 0.0 for r in rows))
        self.assertEqual(sum(int(r["samples"]) for r in rows),
                         int(sum(p in ("mainline", "accel_lane") for p in self.trajs["keep"]["part"])))

    def test_same_vehicle_per_route_in_every_arm(self):
        picks = run_figures.accel_and_lanes(self.trajs, str(self.out / "acc"), str(self.out / "lanes"))
        acc = self.assertFigure("acc")
        lanes = self.assertFigure("lanes")
        self.assertGreaterEqual(len(picks), 2)
        for route, vid in picks.items():
            arms = {r["arm"] for r in acc if r["route"] == route and r["vehicle"] == vid}
            self.assertEqual(arms, {"keep", "sumo_native"})
        self.assertTrue(all(int(r["lane"]) >= 1 for r in lanes))

    def test_decision_cdf_marks_percentiles(self):
        path = self.out / "decisions.csv"
        with open(path, "w") as f:
            f.write("time_s,rsu,decision_ms,advisories\n")
            for i in range(100):
                f.write(f"{i},rsu_0,{i + 1},3\n{i},rsu_1,{2 * (i + 1)},2\n")
        self.assertTrue(run_figures.decision_cdf(path, "palcas", str(self.out / "cdf")))
        rows = {r["rsu"]: r for r in self.assertFigure("cdf")}
        self.assertEqual(rows["rsu_0"]["decisions"], "100")
        self.assertAlmostEqual(float(rows["rsu_0"]["p50_ms"]), 50.5)
        self.assertAlmostEqual(float(rows["rsu_1"]["p99_ms"]), 2 * 99.01, places=2)

    def test_learning_curves_of_every_arm(self):
        pol = ROOT / "policies" / "palcas"
        self.assertTrue(run_figures.learning_curves({"palcas": pol, "copy": pol}, str(self.out / "lc")))
        rows = self.assertFigure("lc")
        n = len(read_csv(pol / "episodes.csv"))
        self.assertEqual(len(rows), 2 * n)

    def test_whole_run_folder(self):
        pngs = run_figures.figures_for_run(FIXTURE, self.out)
        names = {pathlib.Path(p).stem for p in pngs}
        self.assertTrue({"speed_over_time", "space_time_keep", "space_time_sumo_native",
                         "accel_profiles", "lane_trajectories"} <= names)


class LoopCostTest(unittest.TestCase):
    """tools/loop_cost.py: the per-step split weighted over the buckets, and each arm's wall
    against sumo_native's of the same run."""

    def test_parts_are_step_weighted_and_the_ratio_is_against_sumo_native(self):
        d = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, d)
        for arm in ("keep", "sumo_native"):
            shutil.copytree(FIXTURE / arm, d / arm)
        metrics = json.loads((d / "keep" / "metrics.json").read_text())
        metrics["step_timing"] = [
            dict(vehicles_from=0, vehicles_to=49, steps=100, sumo_ms_per_step=1.0, bridge_ms_per_step=0.1,
                 lockstep_ms_per_step=0.0),
            dict(vehicles_from=50, vehicles_to=99, steps=300, sumo_ms_per_step=3.0, bridge_ms_per_step=0.5,
                 lockstep_ms_per_step=0.4)]
        metrics["wall_seconds"] = 3.0
        (d / "keep" / "metrics.json").write_text(json.dumps(metrics))
        native_wall = json.loads((d / "sumo_native" / "metrics.json").read_text())["wall_seconds"]
        by_arm = {r[1]: r for r in loop_cost.rows(d)}
        _, _, steps, wall, sumo, bridge, lockstep, ratio = by_arm["keep"]
        self.assertEqual(steps, 400)
        self.assertAlmostEqual(sumo, 2.5)
        self.assertAlmostEqual(bridge, 0.4)
        self.assertAlmostEqual(lockstep, 0.3)
        self.assertAlmostEqual(ratio, 3.0 / native_wall)
        self.assertAlmostEqual(by_arm["sumo_native"][7], 1.0)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            loop_cost.main([str(d), "--markdown"])
        self.assertIn("| wall / sumo_native |", out.getvalue())

    def test_a_folder_without_arms_is_named(self):
        d = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, d)
        with self.assertRaises(SystemExit) as e:
            list(loop_cost.rows(d))
        self.assertIn(d, str(e.exception))


class SeedRatioTest(unittest.TestCase):
    """tools/seed_ratio.py: per-seed ratios of one set of points to another."""

    def write(self, rows):
        d = tempfile.mkdtemp()
        self.addCleanup(shutil.rmtree, d)
        path = pathlib.Path(d) / "results.csv"
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["point", "arm", "pr", "demand", "seed", "status", "efficiency_all_mps"])
            for arm, pr, demand, seed, speed, status in rows:
                w.writerow([f"{arm}_pr{pr}_d{demand}_s{seed}", arm, pr, demand, seed, status, speed])
        return str(path)

    def run_tool(self, argv):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            seed_ratio.main(argv)
        return out.getvalue()

    def test_an_arm_against_another_pairs_seed_pr_and_demand(self):
        path = self.write([
            ("palcas", 20, 1800, 101, 17.0, "done"), ("sumo_native", 20, 1800, 101, 20.0, "done"),
            ("palcas", 20, 1800, 102, 18.0, "done"), ("sumo_native", 20, 1800, 102, 18.0, "done"),
            ("palcas", 20, 1800, 103, 9.0, "failed"), ("sumo_native", 20, 1800, 103, 18.0, "done"),
            ("palcas", 20, 2200, 101, 15.0, "done"), ("sumo_native", 20, 2200, 101, 12.0, "done"),
            ("palcas", 60, 1800, 101, 21.0, "done")])  # no SUMO-native partner: left out
        text = self.run_tool([path, "--of", "palcas", "--to", "sumo_native"])
        self.assertIn("| 101 | 17.00 | 20.00 | 0.850 |", text)
        self.assertIn("| 102 | 18.00 | 18.00 | 1.000 |", text)
        self.assertNotIn("| 103 |", text)  # a failed point is not a seed
        self.assertIn("| mean of 2 | | | 0.925 |", text)
        self.assertIn("| worst seed | | | 0.850 |", text)
        self.assertIn("| seeds below 0.95 | | | 1 of 2 |", text)
        self.assertIn("| 101 | 15.00 | 12.00 | 1.250 |", text)
        self.assertNotIn("PR 60", text)

    def test_one_arm_against_itself_at_another_demand(self):
        path = self.write([
            ("sumo_native", 20, 1800, 101, 20.0, "done"), ("sumo_native", 20, 1801, 101, 17.0, "done"),
            ("sumo_native", 20, 1800, 102, 17.0, "done"), ("sumo_native", 20, 1801, 102, 17.0, "done")])
        text = self.run_tool([path, "--of", "sumo_native@1801", "--to", "sumo_native@1800"])
        self.assertIn("sumo_native@1801 ÷ sumo_native@1800", text)
        self.assertIn("| 101 | 17.00 | 20.00 | 0.850 |", text)
        self.assertIn("| seeds below 0.95 | | | 1 of 2 |", text)
        self.assertEqual(text.count("| worst seed |"), 1)  # 1800 against itself is no pair

    def test_bad_input_is_named(self):
        path = self.write([("palcas", 20, 1800, 101, 17.0, "done")])
        for argv, words in (([path, "--of", "palcas", "--to", "sumo_native"], "no seed has both"),
                            ([path, "--of", "palcas@fast", "--to", "sumo_native"], "'fast'"),
                            ([path, "--of", "@1800", "--to", "sumo_native"], "names no arm"),
                            ([path, "--of", "palcas", "--to", "sumo_native", "--metric", "nope"], "'nope'"),
                            (["/nonexistent/results.csv", "--of", "a", "--to", "b"], "/nonexistent/results.csv")):
            with self.assertRaises(SystemExit) as e:
                seed_ratio.main(argv)
            self.assertIn(words, str(e.exception))


class RatioByDemandTest(unittest.TestCase):
    """tools/ratio_by_demand.py: the ratio to SUMO-native on the same seed, against demand."""

    write = SeedRatioTest.write  # results.csv rows of (arm, pr, demand, seed, speed, status)

    def test_settings_pair_with_native_by_pr_demand_and_seed(self):
        native = self.write([("sumo_native", 60, 1400, 101, 20.0, "done"), ("sumo_native", 60, 1400, 102, 25.0, "done"),
                             ("sumo_native", 60, 2200, 101, 16.0, "done")])
        runs = self.write([("palcas", 60, 1400, 101, 19.0, "done"), ("palcas", 60, 1400, 102, 25.0, "done"),
                           ("palcas", 60, 2200, 101, 17.6, "done"), ("palcas", 60, 2200, 102, 9.0, "done"),
                           ("palcas", 60, 1800, 101, 5.0, "failed")])
        png = pathlib.Path(tempfile.mkdtemp()) / "ratio.png"
        self.addCleanup(shutil.rmtree, png.parent)
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            ratio_by_demand.main(["--out", str(png), "--native", native, f"with={runs}"])
        text = out.getvalue()
        self.assertIn("with,palcas,60,1400,2,0.9750,0.9500,1.0000", text)
        self.assertIn("with,palcas,60,2200,1,1.1000,1.1000,1.1000", text)  # seed 102 has no native row
        self.assertNotIn(",1800,", text)  # a failed point is not a seed
        self.assertGreater(png.stat().st_size, 0)

    def test_nothing_to_pair_is_named(self):
        native = self.write([("sumo_native", 60, 1400, 101, 20.0, "done")])
        runs = self.write([("palcas", 20, 1400, 101, 19.0, "done")])
        for argv, words in ((["--out", "/tmp/x.png", "--native", native, f"with={runs}"], "no point has a SUMO-native row"),
                            (["--out", "/tmp/x.png", "--native", native, runs], "is not LABEL=CSV")):
            with self.assertRaises(SystemExit) as e:
                ratio_by_demand.main(argv)
            self.assertIn(words, str(e.exception))


class ComfortBreakdownTest(unittest.TestCase):
    """tools/comfort_breakdown.py --by-lane-change: discomfort by the time from the nearest change."""

    HEADER = "time_s,vehicle,cav,route,exit_cluster,part,x_m,lane,speed_mps,accel_mps2,command,command_accel_mps2,lane_change_target"

    def run_dir(self, rows):
        d = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, d)
        (d / "palcas").mkdir()
        lines = [self.HEADER] + [f"{t},{v},{cav},r,-1,{part},0,{lane},20,{a},none,0,0" for t, v, cav, part, lane, a in rows]
        (d / "palcas" / "trajectories.csv").write_text("\n".join(lines) + "\n")
        return d

    def test_samples_fall_in_the_window_of_their_nearest_change(self):
        # CAV c1 changes lane at t = 10 (lane 1 -> 2) and its road part at t = 30; HDV h1 is not counted.
        rows = [(t, "c1", 1, "mainline", 1, 0.0) for t in range(1, 9)]
        rows += [(9, "c1", 1, "mainline", 1, 2.0),    # 1 s before the change: speeding up
                 (10, "c1", 1, "mainline", 2, 0.0),   # the change itself: 0 s after
                 (11, "c1", 1, "mainline", 2, -2.0),  # 1 s after: braking
                 (14, "c1", 1, "mainline", 2, 3.0),   # 4 s after: speeding up
                 (20, "c1", 1, "mainline", 2, 1.47),  # further, on the bound: comfortable
                 (21, "c1", 1, "mainline", 2, -1.5),  # further (9 s from either): braking
                 (30, "c1", 1, "offramp", 2, 0.0),
                 (5, "h1", 0, "mainline", 1, 4.0)]
        counts, total = comfort_breakdown.by_lane_change(self.run_dir(rows) / "palcas" / "trajectories.csv", 1.47)
        self.assertEqual(total, 15)
        self.assertEqual(counts["5-2 s before"], [3, 0, 0])  # t = 5..7 (a window's start is in it)
        self.assertEqual(counts["2-0 s before"], [2, 1, 0])  # t = 8, 9
        self.assertEqual(counts["0-2 s after"], [3, 0, 1])   # t = 10, 11 and the part change at 30
        self.assertEqual(counts["2-5 s after"], [1, 1, 0])   # t = 14
        self.assertEqual(counts[comfort_breakdown.FURTHER], [6, 0, 1])  # t = 1..4, 20, 21
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            comfort_breakdown.main([str(self.run_dir(rows)), "--by-lane-change"])
        self.assertIn("| palcas | **all** (comfort 73.3 %) | 100 | 13.33 | 13.33 |", out.getvalue())

    def test_a_folder_without_trajectories_is_named(self):
        with self.assertRaises(SystemExit) as e:
            comfort_breakdown.main([tempfile.gettempdir() + "/no_such_run", "--by-lane-change"])
        self.assertIn("no <arm>/trajectories.csv", str(e.exception))


class LaneChangeBreakdownTest(unittest.TestCase):
    """tools/lane_change_breakdown.py on a hand-made trajectories.csv: the exit lane found, each
    change classed, the undone ones counted, HDVs and the merge left out, bad input refused."""

    HEAD = "time_s,vehicle,cav,route,exit_cluster,part,x_m,lane,speed_mps,accel_mps2,command,command_accel_mps2,lane_change_target\n"

    def write(self, tracks):
        d = pathlib.Path(tempfile.mkdtemp(prefix="palcas_lc_"))
        self.addCleanup(shutil.rmtree, d)
        lines = [self.HEAD]
        for vehicle, cav, route, samples in tracks:
            for t, (part, lane) in enumerate(samples, start=1):
                lines.append(f"{t},{vehicle},{cav},{route},0,{part},{10 * t},{lane},30,0,none,0,0\n")
        (d / "trajectories.csv").write_text("".join(lines))
        return d

    def test_each_change_is_classed(self):
        m = "mainline"
        d = self.write([
            # exit-bound from lane 3 to the exit lane 1, one step away and back: needed 2
            ("e", 1, "main_exit", [(m, 3), (m, 4), (m, 3), (m, 2), (m, 1), ("off_ramp", 0)]),
            # through: left and back (undone), then one more left much later
            ("t", 1, "main_through", [(m, 2), (m, 3), (m, 2)] + [(m, 2)] * 40 + [(m, 3)]),
            # from the ramp: the merge is a change of part, not of lane; it exits from lane 1
            ("r", 1, "ramp_exit", [("on_ramp", 0), ("accel_lane", 0), (m, 1), (m, 1), ("off_ramp", 0)]),
            ("h", 0, "main_through", [(m, 1), (m, 5)]),  # an HDV: not counted
        ])
        tracks = lane_change_breakdown.read_tracks(d / "trajectories.csv")
        self.assertEqual(sorted(tracks), ["e", "r", "t"])
        self.assertEqual(lane_change_breakdown.exit_lane(tracks), 1)
        b = lane_change_breakdown.breakdown(tracks, undone_within=30.0)
        self.assertEqual(b["main_exit"], {"cavs": 1, "needed": 2, "changes": 4, "towards": 3, "away": 1, "undone": 1})
        self.assertEqual(b["main_through"], {"cavs": 1, "changes": 3, "through": 3, "undone": 1})
        self.assertEqual(b["ramp_exit"], {"cavs": 1, "needed": 0})
        self.assertEqual(b["all"]["changes"], 7)
        self.assertEqual(lane_change_breakdown.breakdown(tracks, undone_within=0.5)["all"].get("undone", 0), 0)
        out = d / "counts.csv"
        with contextlib.redirect_stdout(io.StringIO()) as text:
            self.assertEqual(lane_change_breakdown.main([str(d), "--csv", str(out)]), 0)
        self.assertIn("| main_exit | 1 | 4.00 | 2.00 | 3 | 1 | 0 | 1 |", text.getvalue())
        self.assertEqual(len(out.read_text().splitlines()), 1 + 4)

    def test_bad_input_is_refused_by_name(self):
        d = self.write([("e", 1, "main_exit", [("mainline", 1)])])
        (d / "trajectories.csv").write_text(self.HEAD + "1,e,1,main_exit,0,mainline,10,x,30,0,none,0,0\n")
        with self.assertRaisesRegex(lane_change_breakdown.BreakdownError, "line 2: .*lane 'x' is not a number"):
            lane_change_breakdown.read_tracks(d / "trajectories.csv")
        (d / "trajectories.csv").write_text("time_s,vehicle\n1,e\n")
        with self.assertRaisesRegex(lane_change_breakdown.BreakdownError, "not a PALCAS trajectories.csv"):
            lane_change_breakdown.read_tracks(d / "trajectories.csv")
        with contextlib.redirect_stderr(io.StringIO()) as err:
            self.assertEqual(lane_change_breakdown.main([str(d / "nowhere")]), 2)
            self.assertEqual(lane_change_breakdown.main([str(d), "--undone-within", "0"]), 2)
        self.assertIn("no trajectories.csv", err.getvalue())


class ExitCheckTest(unittest.TestCase):
    """tools/exit_check.py on hand-made metrics.json: each exit's CAVs pooled over seeds, the
    worst seed found, a low exit failing --min-served-pct, a training's duplicate and an
    experiment's figure copy skipped, and files that are not ours refused by name."""

    def run_folder(self, root, point, arm, seed, exits, pr=60, demand=1000):
        d = root / "points" / point / arm
        d.mkdir(parents=True)
        m = {"dsr_censored_pct": 0.0, "pr_percent": pr, "mainline_flow_vphpl": demand, "seed": seed,
             "exits_by_cluster": [dict(zip(("served", "missed", "lost", "censored"), e), cluster=k)
                                  for k, e in enumerate(exits)]}
        (d / "metrics.json").write_text(json.dumps(m))
        return d

    def setUp(self):
        self.root = pathlib.Path(tempfile.mkdtemp(prefix="palcas_exitcheck_"))
        self.addCleanup(shutil.rmtree, self.root, True)
        # Exit 1 served 9 of 10 on seed 101 and 1 of 10 on seed 102; exit 3 has no off-ramp.
        self.run_folder(self.root, "palcas_s101", "palcas", 101,
                        [(10, 0, 0, 0), (9, 1, 0, 0), (20, 0, 0, 0), (0, 0, 0, 0)])
        self.run_folder(self.root, "palcas_s102", "palcas", 102,
                        [(10, 0, 0, 0), (1, 7, 1, 1), (19, 1, 0, 0), (0, 0, 0, 0)])
        self.run_folder(self.root, "keep_s101", "keep", 101,
                        [(5, 0, 0, 0), (5, 0, 0, 0), (5, 0, 0, 0), (0, 0, 0, 0)])

    def test_pools_each_exit_over_seeds_and_names_the_worst_seed(self):
        rows = {(r[0], r[3]): r for r in exit_check.check([self.root])}
        self.assertNotIn(("palcas", 3), rows)  # no exit-bound CAV: no row
        arm, pr, demand, k, runs, pooled, pct, worst, seed = rows[("palcas", 1)]
        self.assertEqual((pr, demand, runs), (60, 1000, 2))
        self.assertEqual(pooled, {"served": 10, "missed": 8, "lost": 1, "censored": 1})
        self.assertAlmostEqual(pct, 50.0)  # censored and lost count as not served
        self.assertEqual((worst, seed), (10.0, 102))
        self.assertAlmostEqual(rows[("palcas", 2)][6], 97.5)
        self.assertEqual(len(exit_check.check([self.root], arm="keep")), 3)

    def test_min_served_pct_fails_on_the_low_exit_only(self):
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            self.assertEqual(exit_check.main([str(self.root), "--min-served-pct", "60"]), 1)
        self.assertIn("palcas, PR 60 %, 1000 veh/h/lane: exit 1 served 50.0 %", err.getvalue())
        self.assertEqual(err.getvalue().count("exit_check:"), 1)
        out = self.root / "exits.csv"
        with contextlib.redirect_stdout(io.StringIO()):
            self.assertEqual(exit_check.main([str(self.root), "--min-served-pct", "50", "--csv", str(out)]), 0)
        self.assertEqual(len(list(csv.reader(out.open()))), 1 + 6)

    def test_an_experiments_figure_copy_of_a_point_is_not_counted_again(self):
        figure_run = self.root / "figures" / "runs" / "palcas"
        figure_run.mkdir(parents=True)
        shutil.copy(self.root / "points" / "palcas_s101" / "palcas" / "metrics.json", figure_run)
        rows = {(r[0], r[3]): r for r in exit_check.check([self.root])}
        self.assertEqual(rows[("palcas", 1)][4], 2)
        self.assertEqual(rows[("palcas", 1)][5]["served"], 10)

    def test_a_trainings_own_metrics_repeats_its_last_episode_and_is_skipped(self):
        d = self.root / "train" / "palcas"
        (d / "episode_0").mkdir(parents=True)
        m = {"dsr_censored_pct": 0.0, "seed": 1, "exits_by_cluster": [
            {"served": 1, "missed": 0, "lost": 0, "censored": 0}]}
        (d / "episode_0" / "metrics.json").write_text(json.dumps(m))
        (d / "metrics.json").write_text(json.dumps(m))
        rows = exit_check.check([self.root / "train"])
        self.assertEqual([(r[0], r[4]) for r in rows], [("palcas/episode_0", 1)])

    def test_refuses_files_that_are_not_ours_and_bad_values(self):
        bad = self.root / "other" / "x"
        bad.mkdir(parents=True)
        (bad / "metrics.json").write_text("{\"speed\": 3}")
        with self.assertRaisesRegex(exit_check.ExitCheckError, "not a PALCAS run's metrics.json"):
            exit_check.check([self.root / "other"])
        (bad / "metrics.json").write_text("{\"dsr_censored_pct\": 90}")
        with self.assertRaisesRegex(exit_check.ExitCheckError, "no exits_by_cluster"):
            exit_check.check([self.root / "other"])
        (bad / "metrics.json").write_text("not json")
        with self.assertRaisesRegex(exit_check.ExitCheckError, "not readable as JSON"):
            exit_check.check([self.root / "other"])
        with self.assertRaisesRegex(exit_check.ExitCheckError, "no metrics.json of arm nobody"):
            exit_check.check([self.root / "points"], arm="nobody")
        with contextlib.redirect_stderr(io.StringIO()):
            self.assertEqual(exit_check.main([str(self.root / "nowhere")]), 2)
            with self.assertRaises(SystemExit):
                exit_check.main([str(self.root), "--min-served-pct", "140"])


class TrainingPaceTest(unittest.TestCase):
    """tools/training_pace.py: its variants and the real-time factors it reads from records."""

    def test_bad_variants_and_values_are_refused_before_anything_runs(self):
        for argv, words in ((["--out", "/tmp/x", "--variant", "noequals"], "NAME=RSU_PARAMS_YAML"),
                            (["--out", "/tmp/x", "--variant", "a=no/such.yaml"], "no file no/such.yaml"),
                            (["--out", "/tmp/x", "--variant", "a=", "--episodes", "0"], "must be positive")):
            err = io.StringIO()
            with contextlib.redirect_stderr(err), self.assertRaises(SystemExit) as exit_:
                training_pace.main(argv)
            self.assertEqual(exit_.exception.code, 2)
            self.assertIn(words, err.getvalue())
        self.assertEqual(training_pace.variant("shipped="), ("shipped", ""))

    def test_real_time_factors_are_simulated_over_wall_seconds_of_the_records(self):
        folder = pathlib.Path(tempfile.mkdtemp(prefix="palcas_pace_"))
        self.addCleanup(shutil.rmtree, folder, True)
        (folder / "episodes.csv").write_text("episode,sim_seconds,wall_seconds\n0,900,60\n1,900,90\n")
        self.assertEqual(training_pace.training_rtf(str(folder)), (12.0, 2))
        for k, wall in ((1, 20.0), (2, 30.0)):
            (folder / f"e{k}" / "sumo_native").mkdir(parents=True)
            (folder / f"e{k}" / "sumo_native" / "metrics.json").write_text(
                json.dumps({"sim_seconds": 900, "wall_seconds": wall}))
        self.assertEqual(training_pace.evaluation_rtf([str(folder / "e1"), str(folder / "e2")]), 36.0)

    def test_a_run_log_lands_in_a_round_folder_that_did_not_exist(self):
        # The first real run died here: the log of round 0's first run had no folder yet.
        folder = pathlib.Path(tempfile.mkdtemp(prefix="palcas_pace_"))
        self.addCleanup(shutil.rmtree, folder, True)
        log = folder / "round0" / "sumo_native_s1.log"
        status, wall = training_pace.timed([sys.executable, "-c", "print('ran')"], str(log))
        self.assertEqual(status, 0)
        self.assertGreaterEqual(wall, 0.0)
        self.assertEqual(log.read_text().strip(), "ran")


def merged_yaml(*paths):
    """The keys of the YAML files, later files over earlier ones, nested mappings merged."""
    import yaml

    def merge(into, more):
        for k, v in more.items():
            if isinstance(v, dict) and isinstance(into.get(k), dict):
                merge(into[k], v)
            else:
                into[k] = v
        return into

    out = {}
    for p in paths:
        merge(out, yaml.safe_load((ROOT / p).read_text()) or {})
    return out


class OverrideUnionsTest(unittest.TestCase):
    """--bridge-params and --rsu-params take one file each, so a setting made of several has a
    file of its own: each must stay the union of the files it says it is made of."""
    UNIONS = {
        "config/training/lane_change_advice_bridge.yaml": ["config/training/gentle_lane_changes.yaml",
                                                           "config/training/lane_changes_only.yaml"],
        "config/training/lane_change_advice_rsu.yaml": ["config/training/personal_heads.yaml",
                                                        "docs/experiment/lane_change_dwell_dev/dwell_10s.yaml"],
        "docs/experiment/exit_rule_dev/combination_exit_rule.yaml": [
            "docs/experiment/lane_change_dwell_dev/dwell_10s.yaml", "docs/experiment/exit_rule_dev/exit_rule.yaml"],
        "docs/experiment/exit_rule_dev/combination_late_exit_rule.yaml": [
            "docs/experiment/exit_rule_dev/combination_exit_rule.yaml", "docs/experiment/exit_rule_dev/late_exit_rule.yaml"],
        "config/training/personal_heads_bf16.yaml": ["config/training/personal_heads.yaml",
                                                     "config/training/bf16_products.yaml"],
        "config/training/personal_heads_half.yaml": ["config/training/personal_heads.yaml",
                                                     "config/training/half_gradient_steps.yaml"],
        "config/training/bf16_half_gradient_steps.yaml": ["config/training/bf16_products.yaml",
                                                          "config/training/half_gradient_steps.yaml"],
        "docs/experiment/exit_rule_dev/combination_light_exit_rule.yaml": [
            "docs/experiment/exit_rule_dev/combination_exit_rule.yaml", "docs/experiment/exit_rule_dev/light_exit_rule.yaml"],
        "docs/experiment/exit_rule_dev/combination_windowed_light_exit_rule.yaml": [
            "docs/experiment/exit_rule_dev/combination_light_exit_rule.yaml",
            "docs/experiment/exit_rule_dev/windowed_light_exit_rule.yaml"],
        "docs/experiment/exit_rule_dev/combination_inflow_exit_rule.yaml": [
            "docs/experiment/exit_rule_dev/combination_light_exit_rule.yaml",
            "docs/experiment/exit_rule_dev/inflow_exit_rule.yaml"],
    }

    def test_each_union_file_equals_its_parts(self):
        for union, parts in self.UNIONS.items():
            with self.subTest(union=union):
                self.assertEqual(merged_yaml(union), merged_yaml(*parts))

    def test_the_check_can_fail(self):
        self.assertNotEqual(merged_yaml("config/training/lane_change_advice_rsu.yaml"),
                            merged_yaml("config/training/personal_heads.yaml"))


def main():
    run_as_junit(sys.modules[__name__], "experiment_tools")


if __name__ == "__main__":
    main()
