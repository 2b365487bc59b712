#!/usr/bin/env python3
"""Tests of the fair trial's results page (tools/trial_results.py), its statistics
(tools/palcas_stats.py: paired and bootstrap intervals, Clopper-Pearson) and the seed sets
(tools/seed_sets.py, config/seeds.yaml), on a hand-made FIXTURE (fixtures/trial/: 2 demands x
PR 60 x palcas, keep, sumo_native x seeds 1001-1003, one point failed, one missing, one arm
from a bridge without the censored rates; its page as generated in fixtures/trial/expected/).

usage: trial_results_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
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
FIXTURE = pathlib.Path(__file__).resolve().parent / "fixtures" / "trial"
EXPECTED = FIXTURE / "expected"
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import palcas_stats  # noqa: E402
import seed_sets  # noqa: E402
import trial_results  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402

SPEED = trial_results.SPEED
LOW = (1000.0, 60.0)
HIGH = (2200.0, 60.0)
SEEDS = [1001, 1002, 1003]


def fixture_rows():
    return trial_results.read_trial(FIXTURE, EXPECTED)[0]


def scipy_available():
    try:
        import scipy.stats  # noqa: F401
        return True
    except ImportError:
        return False


class ClopperPearsonTest(unittest.TestCase):
    KNOWN = (((0, 100), (0.0, 0.0362)), ((5, 100), (0.0164, 0.1128)), ((50, 100), (0.3983, 0.6017)),
             ((100, 100), (0.9638, 1.0)), ((1, 10), (0.0025, 0.4450)), ((0, 1), (0.0, 0.975)))

    def test_known_intervals_with_the_own_beta_quantile(self):
        for (k, n), (lo, hi) in self.KNOWN:
            got = palcas_stats.clopper_pearson(k, n, use_scipy=False)
            self.assertAlmostEqual(got[0], lo, places=4, msg=f"{k} of {n}")
            self.assertAlmostEqual(got[1], hi, places=4, msg=f"{k} of {n}")
        # 0 of n: the upper bound has a closed form, 1 - 0.025^(1/n).
        self.assertAlmostEqual(palcas_stats.clopper_pearson(0, 100, use_scipy=False)[1],
                               1 - 0.025 ** (1 / 100), places=12)

    def test_scipy_and_the_own_quantile_agree(self):
        if not scipy_available():
            self.skipTest("scipy is not importable: the own quantile is the one in use")
        for k, n in ((0, 100), (5, 100), (3, 2400), (17, 9000), (4999, 10000)):
            a = palcas_stats.clopper_pearson(k, n, use_scipy=True)
            b = palcas_stats.clopper_pearson(k, n, use_scipy=False)
            self.assertAlmostEqual(a[0], b[0], places=10)
            self.assertAlmostEqual(a[1], b[1], places=10)

    def test_incomplete_beta_and_its_quantile(self):
        self.assertAlmostEqual(palcas_stats.betainc_reg(2, 3, 0.4), 0.5248, places=12)  # 1 - sum of binomials
        self.assertAlmostEqual(palcas_stats.betainc_reg(1, 1, 0.3), 0.3, places=12)
        self.assertAlmostEqual(palcas_stats.betainc_reg(0.5, 0.5, 0.5), 0.5, places=12)
        for q, a, b in ((0.025, 5, 96), (0.975, 6, 95), (0.5, 2, 2)):
            self.assertAlmostEqual(palcas_stats.betainc_reg(a, b, palcas_stats.beta_ppf(q, a, b)), q, places=12)
        for bad in ((0, 0), (101, 100), (-1, 5)):
            with self.assertRaises(ValueError):
                palcas_stats.clopper_pearson(*bad)


class IntervalTest(unittest.TestCase):
    def test_paired_t_interval(self):
        mean, lo, hi = palcas_stats.t_interval([0.4, 0.55, 0.55])
        self.assertAlmostEqual(mean, 0.5)
        self.assertAlmostEqual(hi - mean, 4.303 * math.sqrt(0.0075) / math.sqrt(3), places=9)
        self.assertTrue(math.isnan(palcas_stats.t_interval([1.0])[1]))

    def test_bootstrap_is_seeded_and_reproducible(self):
        d = [0.31, -0.12, 0.83, 0.27, 0.55, 0.04, 0.46, 1.13, -0.37, 0.61, 0.19, 0.72]
        a = palcas_stats.bootstrap_mean_ci(d, seed=palcas_stats.stable_seed("x", 1))
        self.assertEqual(a, palcas_stats.bootstrap_mean_ci(d, seed=palcas_stats.stable_seed("x", 1)))
        self.assertNotEqual(a, palcas_stats.bootstrap_mean_ci(d, seed=palcas_stats.stable_seed("x", 2)))
        self.assertTrue(min(d) <= a[0] < sum(d) / len(d) < a[1] <= max(d))
        self.assertEqual(palcas_stats.stable_seed("a", 1.0), palcas_stats.stable_seed("a", 1.0))
        self.assertEqual(palcas_stats.bootstrap_mean_ci([2.0], seed=1), (2.0, 2.0))
        with self.assertRaises(ValueError):
            palcas_stats.bootstrap_mean_ci([1.0, float("nan")], seed=1)

    def test_a_comparison_is_the_same_whatever_ran_before(self):
        rows = fixture_rows()
        first = trial_results.compare(rows, "palcas", "sumo_native", LOW, SPEED, SEEDS)
        trial_results.compare(rows, "palcas", "keep", HIGH, "dsr", SEEDS)  # draws from another generator
        again = trial_results.compare(rows, "palcas", "sumo_native", LOW, SPEED, SEEDS)
        self.assertEqual((first["b_lo"], first["b_hi"]), (again["b_lo"], again["b_hi"]))


class PairingTest(unittest.TestCase):
    def test_only_seeds_both_arms_finished_are_paired_the_rest_named(self):
        rows = fixture_rows()
        pairs, left, column, fallback = trial_results.pair(rows, "palcas", "keep", HIGH, SPEED, SEEDS)
        self.assertEqual([(s, a, b) for s, a, b in pairs], [(1001, 21.0, 21.3), (1002, 19.6, 19.0)])
        self.assertEqual(left, [(1003, "keep: failed")])
        self.assertEqual((column, fallback), (SPEED, False))
        _, left, _, _ = trial_results.pair(rows, "palcas", "sumo_native", HIGH, SPEED, SEEDS)
        self.assertEqual(left, [(1003, "sumo_native: no row")])
        c = trial_results.compare(rows, "palcas", "keep", HIGH, SPEED, SEEDS)
        self.assertEqual(c["n"], 2)
        self.assertAlmostEqual(c["mean"], 0.15)
        self.assertAlmostEqual(c["worst"], -0.3)  # the seed least favourable to palcas
        self.assertEqual(c["worst_seed"], 1001)

    def test_a_seed_without_the_metric_is_left_out_and_named(self):
        rows = [dict(r) for r in fixture_rows()]
        for r in rows:
            if (r["arm"], r["demand"], r["seed"]) == ("keep", 1000.0, 1002):
                r["throughput_vph"] = ""
        pairs, left, _, _ = trial_results.pair(rows, "palcas", "keep", LOW, "throughput_vph", SEEDS)
        self.assertEqual([s for s, _, _ in pairs], [1001, 1003])
        self.assertEqual(left, [(1002, "keep: no throughput_vph")])

    def test_censored_rates_fall_back_together(self):
        rows = fixture_rows()
        # sumo_native's rows at 1000 come from a bridge without dsr_censored_pct: both sides uncensored.
        self.assertEqual(trial_results.pair(rows, "palcas", "sumo_native", LOW, "dsr", SEEDS)[2:], ("dsr_pct", True))
        self.assertEqual(trial_results.pair(rows, "palcas", "keep", LOW, "dsr", SEEDS)[2:], ("dsr_censored_pct", False))

    def test_ratio_and_readings(self):
        rows = fixture_rows()
        r = trial_results.compare(rows, "palcas", "sumo_native", LOW, SPEED, SEEDS, ratio=True)
        want = [100 * (28.4 / 28.0 - 1), 100 * (28.15 / 27.6 - 1), 100 * (28.85 / 28.3 - 1)]
        self.assertAlmostEqual(r["mean"], sum(want) / 3)
        self.assertEqual(trial_results.verdict(r), "gain")
        line = trial_results.reading_line(r, pct=True)
        self.assertRegex(line, r"^speed \+1\.8 % \[\+1\.0, \+2\.6\], worst seed \+1\.4 %: a gain$")
        self.assertEqual(trial_results.verdict(trial_results.compare(rows, "palcas", "keep", HIGH, SPEED, SEEDS)), "none")
        # Lower is better for time spent; lane changes are neither.
        self.assertEqual(trial_results.verdict(
            trial_results.compare(rows, "palcas", "sumo_native", LOW, "total_time_spent_veh_h", SEEDS)), "gain")
        self.assertEqual(trial_results.verdict(
            trial_results.compare(rows, "palcas", "keep", HIGH, "comfort_share_pct", SEEDS)), "loss")
        self.assertEqual(trial_results.verdict(
            trial_results.compare(rows, "palcas", "keep", LOW, "lane_changes_per_cav", SEEDS)), "more")

    def test_verdict_needs_both_intervals_on_one_side(self):
        base = {"n": 10, "better": "higher", "t_lo": 0.1, "t_hi": 0.5, "b_lo": 0.2, "b_hi": 0.4}
        self.assertEqual(trial_results.verdict(base), "gain")
        self.assertEqual(trial_results.verdict(dict(base, b_lo=-0.01)), "none")
        self.assertEqual(trial_results.verdict(dict(base, better="lower")), "loss")
        self.assertEqual(trial_results.verdict(dict(base, t_lo=-0.5, t_hi=-0.1, b_lo=-0.4, b_hi=-0.2,
                                                    better="lower")), "gain")
        self.assertEqual(trial_results.verdict(dict(base, better="neutral")), "more")
        self.assertEqual(trial_results.verdict(dict(base, n=1, t_lo=float("nan"))), "none")


class CellTest(unittest.TestCase):
    def test_best_control_and_pooled_collision_rate(self):
        a = trial_results.analyse(fixture_rows(), json.loads((FIXTURE / "trial.json").read_text()),
                                  trial_results.load_registry())
        self.assertEqual((a["learned"], a["controls"]), (["palcas"], ["keep", "sumo_native"]))
        low, high = a["cells"]
        self.assertEqual((low["best"], high["best"]), ("sumo_native", "keep"))
        self.assertTrue(low["comparisons"][0]["best"] and low["comparisons"][0]["control"] == "sumo_native")
        cr = high["arms"]["palcas"]["cr"]
        self.assertEqual((cr["k"], cr["n"]), (6, 2561 + 2540 + 2555))
        lo, hi = palcas_stats.clopper_pearson(6, 7656)
        self.assertAlmostEqual(cr["lo"], 100 * lo)
        self.assertAlmostEqual(cr["hi"], 100 * hi)
        self.assertEqual(high["arms"]["keep"]["n"], 2)
        self.assertEqual(high["arms"]["palcas"]["p99"], {"max": 5.2, "seed": 1002})
        # Unserved vehicles: the worst seed is the highest.
        self.assertEqual(high["arms"]["palcas"]["metrics"]["unserved_vehicles"]["worst_seed"], 1002)


class SeedsByDemandTest(unittest.TestCase):
    def test_a_part_run_with_fewer_seeds_is_paired_and_counted_on_its_own(self):
        settings = json.loads((FIXTURE / "trial.json").read_text())
        settings["seeds_by_demand"] = {"2200": [1001, 1002]}
        self.assertEqual(trial_results.seeds_for(settings, HIGH, SEEDS), [1001, 1002])
        self.assertEqual(trial_results.seeds_for(settings, LOW, SEEDS), SEEDS)
        a = trial_results.analyse(fixture_rows(), settings, trial_results.load_registry())
        high = [c for c in a["cells"] if c["cell"] == HIGH][0]
        vs_native = [x for x in high["comparisons"] if x["control"] == "sumo_native"][0]["ratio"]
        self.assertEqual(vs_native["n"], 2)
        self.assertNotIn(1003, [seed for seed, _ in vs_native["left_out"]], "1003 is not planned there")
        lines = trial_results.what_was_run(fixture_rows(), [FIXTURE / "results.csv"], settings, FIXTURE, a)
        self.assertIn("- Seeds at 2200 veh/h/lane: 2 planned, 1001, 1002", lines)
        self.assertFalse([l for l in lines if "2200" in l and "s1003" in l], "no missing point outside the plan")


class OwnDemandTest(unittest.TestCase):
    def tearDown(self):
        trial_results.name_own_demand({})

    def test_a_cell_at_the_scenarios_own_demand_is_named_from_trial_json(self):
        cell = (None, 20.0)
        trial_results.name_own_demand({})
        self.assertEqual(trial_results.cell_title(cell), "the scenario's own demand, PR 20 %")
        trial_results.name_own_demand({"own_demand_title": "the printed scenario", "own_demand_short": "printed"})
        self.assertEqual(trial_results.cell_title(cell), "the printed scenario, PR 20 %")
        self.assertEqual(trial_results.cell_short(cell), "printed / PR 20")
        self.assertEqual(trial_results.cell_short((2200.0, 20.0)), "2200 / PR 20")
        settings = json.loads((FIXTURE / "trial.json").read_text())
        settings.update(own_demand_title="the printed scenario", seeds_by_demand={"scenario": [1001]})
        a = trial_results.analyse(fixture_rows(), settings, trial_results.load_registry())
        lines = trial_results.what_was_run(fixture_rows(), [FIXTURE / "results.csv"], settings, FIXTURE, a)
        self.assertIn("- Seeds at the printed scenario: 1 planned, 1001", lines)


class FederationTest(unittest.TestCase):
    """trial.json's federation table: the reference (palcas) paired with arms trained with the
    same budget under another scheme, which are neither missing points nor 'outside the grid'."""

    def setUp(self):
        self.settings = json.loads((FIXTURE / "trial.json").read_text())
        self.settings["federation"] = {"arms": {"independent": "no federation, same budget"}}
        self.rows = fixture_rows()
        for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
            other = dict(r, arm="independent", point=r["point"].replace("palcas", "independent"))
            other[SPEED] = str(float(r[SPEED]) - 1.0 - 0.1 * (r["seed"] - 1001))
            for column in ("dsr_pct", "dsr_censored_pct"):
                if r.get(column):
                    other[column] = str(float(r[column]) - 5.0)
            self.rows.append(other)

    def test_the_reference_is_paired_with_each_arm_by_seed(self):
        a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        fed = trial_results.analyse_federation(self.rows, self.settings, a)
        self.assertEqual([x["cell"] for x in fed], [LOW], "only where the arm has rows")
        e = fed[0]["entries"][0]
        self.assertEqual((e["arm"], e["ratio"]["learned"], e["ratio"]["control"]), ("independent", "palcas", "independent"))
        speed = [c for c in e["metrics"] if c["metric"] == "dsr"][0]
        self.assertAlmostEqual(speed["mean"], 5.0)
        self.assertEqual(trial_results.verdict(e["ratio"]), "gain", "palcas faster on every seed")
        self.assertEqual(e["vs_best"]["control"], [x for x in a["cells"] if x["cell"] == LOW][0]["best"])
        page = "\n".join(trial_results.federation_section(fed))
        self.assertIn("## The federation against its alternatives, same training budget", page)
        self.assertIn("- `independent`: no federation, same budget", page)
        self.assertIn("| `palcas` vs `independent` | DSR", page)

    def test_a_reference_that_ships_as_a_variant_reads_the_variants_rows(self):
        # palcas now ships as palcas_heads (faster by 2 % on LOW's seeds): the table's palcas is
        # palcas_heads, and the rows the trial ran of palcas stay in it as palcas_before.
        for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
            self.rows.append(dict(r, arm="palcas_heads", point=r["point"].replace("palcas", "palcas_heads"),
                                  **{SPEED: repr(float(r[SPEED]) * 1.02)}))
        self.settings["variants"] = {"palcas_heads": {"base": "palcas", "what": "heads", "ships": True,
                                                      "replaced_as": "palcas_before"}}
        self.settings["federation"] = {"reference_what": "a shared body under per-zone heads",
                                       "arms": {"independent": "alone", "palcas_before": "shipped before"}}
        a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        fed = trial_results.analyse_federation(self.rows, self.settings, a)
        [x] = [x for x in fed if x["cell"] == LOW]
        self.assertEqual((x["reference"], x["reference_rows_of"]), ("palcas", "palcas_heads"))
        before = [e for e in x["entries"] if e["arm"] == "palcas_before"][0]
        self.assertAlmostEqual(before["ratio"]["mean"], 2.0, places=6)
        self.assertEqual(trial_results.verdict(before["ratio"]), "gain")
        page = "\n".join(trial_results.federation_section([x]))
        self.assertIn("`palcas` (the shipped federation: a shared body under per-zone heads; its rows are "
                      "those of the variant `palcas_heads`, as it ships)", page)
        self.assertIn("| `palcas` vs `palcas_before` | speed ratio", page)
        lines = trial_results.what_was_run(self.rows, [FIXTURE / "results.csv"], self.settings, FIXTURE, a)
        self.assertIn("- The federation table: 9 rows of `independent`, `palcas_before` (9 finished), against "
                      "`palcas`'s own points", lines)
        # Without replaced_as the rows the trial ran of palcas are left out of the table.
        del self.settings["variants"]["palcas_heads"]["replaced_as"]
        [x] = trial_results.analyse_federation(self.rows, self.settings, a)
        self.assertEqual((x["cell"], [e["arm"] for e in x["entries"]]), (LOW, ["independent"]))

    def test_its_rows_are_counted_not_listed_as_outside_the_grid(self):
        a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        lines = trial_results.what_was_run(self.rows, [FIXTURE / "results.csv"], self.settings, FIXTURE, a)
        self.assertIn("- The federation table: 3 rows of `independent` (3 finished), against `palcas`'s own points", lines)
        self.assertFalse([l for l in lines if "outside the planned grid" in l and "independent" in l])
        self.assertEqual(trial_results.analyse_federation(self.rows, json.loads((FIXTURE / "trial.json").read_text()), a),
                         [], "no federation table without trial.json's federation")


class VariantTest(unittest.TestCase):
    """trial.json's variants: a learned arm run another way, paired with the best control and
    with the arm it varies, outside the planned grid."""

    def test_a_variant_is_paired_with_the_best_control_and_its_base(self):
        settings = json.loads((FIXTURE / "trial.json").read_text())
        settings["variants"] = {"palcas_margin": {"base": "palcas", "what": "palcas with a margin"}}
        rows = fixture_rows()
        for r in [r for r in rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
            rows.append(dict(r, arm="palcas_margin", point=r["point"].replace("palcas", "palcas_margin"),
                             **{SPEED: str(float(r[SPEED]) + 0.5)}))
        a = trial_results.analyse(rows, settings, trial_results.load_registry())
        var = trial_results.analyse_variants(rows, settings, a)
        self.assertEqual([x["cell"] for x in var], [LOW])
        e = var[0]["entries"][0]
        best = [x for x in a["cells"] if x["cell"] == LOW][0]["best"]
        self.assertEqual(e["vs_best"]["control"], best)
        speed = [c for c in e["vs_base"]["metrics"] if c["metric"] == "dsr"]
        self.assertEqual(speed[0]["mean"], 0.0, "the same DSR as its base on every seed")
        base_ratio = e["vs_base"]["ratio"]
        self.assertEqual((base_ratio["learned"], base_ratio["control"]), ("palcas_margin", "palcas"))
        self.assertEqual(trial_results.verdict(base_ratio), "gain")
        page = "\n".join(trial_results.variants_section(var))
        self.assertIn("## Learned variants chosen on the development seeds", page)
        self.assertIn(f"| `palcas_margin` vs `{best}` (best control) | speed ratio − 1 |", page)
        lines = trial_results.what_was_run(rows, [FIXTURE / "results.csv"], settings, FIXTURE, a)
        self.assertIn("- Variants chosen on the development seeds: 3 rows of `palcas_margin` (3 finished)", lines)
        self.assertFalse([l for l in lines if "outside the planned grid" in l and "palcas_margin" in l])


    @staticmethod
    def rules_on_top(own_control):
        """The fixture's settings with one variant, palcas_rules_on_top, naming `own_control`."""
        settings = json.loads((FIXTURE / "trial.json").read_text())
        settings["variants"] = {"palcas_rules_on_top": {
            "base": "palcas", "what": "palcas with a rule on top", "own_control": own_control}}
        return settings

    @staticmethod
    def low_copies(rows, arm, name, speed_delta=0.0):
        """`arm`'s rows of the LOW cell under another name, their speed moved by speed_delta m/s."""
        moved = lambda r: {SPEED: str(float(r[SPEED]) + speed_delta)} if speed_delta else {}
        return [dict(r, arm=name, point=r["point"].replace(arm, name), **moved(r))
                for r in rows if r["arm"] == arm and (r["demand"], r["pr"]) == LOW]

    def test_a_variants_own_control_is_paired_with_it_and_with_the_best_control(self):
        settings = self.rules_on_top({"arm": "rule_on_keep", "what": "the rule on top of KEEP"})
        rows = fixture_rows()
        # The control is faster than the variant by 1 m/s on every seed.
        rows += self.low_copies(rows, "palcas", "palcas_rules_on_top") \
            + self.low_copies(rows, "palcas", "rule_on_keep", speed_delta=1.0)
        a = trial_results.analyse(rows, settings, trial_results.load_registry())
        e = trial_results.analyse_variants(rows, settings, a)[0]["entries"][0]
        self.assertEqual(len(e["vs_own"]), 1)
        own = e["vs_own"][0]
        self.assertEqual((own["ratio"]["learned"], own["ratio"]["control"]), ("palcas_rules_on_top", "rule_on_keep"))
        self.assertEqual(trial_results.verdict(own["ratio"]), "loss", "the control is faster on every seed")
        best = [x for x in a["cells"] if x["cell"] == LOW][0]["best"]
        self.assertEqual((own["vs_best"]["learned"], own["vs_best"]["control"]), ("rule_on_keep", best))
        page = "\n".join(trial_results.variants_section(trial_results.analyse_variants(rows, settings, a)))
        self.assertIn("  - its own control `rule_on_keep`: the rule on top of KEEP", page)
        self.assertIn("| `palcas_rules_on_top` vs `rule_on_keep` (its own control) | speed ratio − 1 |", page)
        self.assertIn(f"| `rule_on_keep` vs `{best}` (best control) | speed ratio − 1 |", page)
        self.assertIn("  - reading against `rule_on_keep`: ", page)
        lines = trial_results.what_was_run(rows, [FIXTURE / "results.csv"], settings, FIXTURE, a)
        self.assertIn("- Variants' own controls (their hand-made mechanisms without the network): "
                      "3 rows of `rule_on_keep` (3 finished)", lines)
        self.assertFalse([l for l in lines if "outside the planned grid" in l and "rule_on_keep" in l])
        csv_text = trial_results.variants_csv(trial_results.analyse_variants(rows, settings, a))
        self.assertIn(f",palcas_rules_on_top,rule_on_keep,{SPEED} ratio %,3,", csv_text)
        self.assertIn(f",rule_on_keep,{best},{SPEED} ratio %,3,", csv_text)

    def test_a_variant_with_two_own_controls_is_paired_with_each(self):
        settings = self.rules_on_top([{"arm": "rule_on_keep", "what": "the rule on top of KEEP"},
                                      {"arm": "rule_on_rule", "what": "the rule on top of the rule"}])
        rows = fixture_rows()
        # KEEP slower than the variant by 1 m/s on every seed, the rule faster by 1 m/s.
        rows += self.low_copies(rows, "palcas", "palcas_rules_on_top") \
            + self.low_copies(rows, "palcas", "rule_on_keep", speed_delta=-1.0) \
            + self.low_copies(rows, "palcas", "rule_on_rule", speed_delta=1.0)
        self.assertEqual(trial_results.own_control_arms(settings), {"rule_on_keep", "rule_on_rule"})
        a = trial_results.analyse(rows, settings, trial_results.load_registry())
        var = trial_results.analyse_variants(rows, settings, a)
        e = var[0]["entries"][0]
        self.assertEqual([o["control"] for o in e["vs_own"]], ["rule_on_keep", "rule_on_rule"])
        self.assertEqual([trial_results.verdict(o["ratio"]) for o in e["vs_own"]], ["gain", "loss"])
        page = "\n".join(trial_results.variants_section(var))
        for name in ("rule_on_keep", "rule_on_rule"):
            self.assertIn(f"| `palcas_rules_on_top` vs `{name}` (its own control) | speed ratio − 1 |", page)
            self.assertIn(f"  - reading against `{name}`: ", page)
        self.assertIn("  - its own control `rule_on_rule`: the rule on top of the rule", page)
        csv_text = trial_results.variants_csv(var)
        self.assertIn(f",palcas_rules_on_top,rule_on_rule,{SPEED} ratio %,3,", csv_text)
        lines = trial_results.what_was_run(rows, [FIXTURE / "results.csv"], settings, FIXTURE, a)
        self.assertIn("- Variants' own controls (their hand-made mechanisms without the network): "
                      "6 rows of `rule_on_keep`, `rule_on_rule` (6 finished)", lines)
        self.assertFalse([l for l in lines if "outside the planned grid" in l and "rule_on_rule" in l])

    def test_an_own_control_whose_rows_equal_a_trial_arm_is_named_as_that_arm(self):
        settings = self.rules_on_top({"arm": "rule_on_keep", "what": "the rule on top of KEEP"})
        rows = fixture_rows()
        rows += self.low_copies(rows, "palcas", "palcas_rules_on_top")
        keep = [r for r in rows if r["arm"] == "keep" and (r["demand"], r["pr"]) == LOW]
        copies = self.low_copies(rows, "keep", "rule_on_keep")
        a = trial_results.analyse(rows + copies, settings, trial_results.load_registry())
        own = trial_results.analyse_variants(rows + copies, settings, a)[0]["entries"][0]["vs_own"][0]
        self.assertEqual(own["same_as"], ["keep"])
        page = "\n".join(trial_results.variants_section(trial_results.analyse_variants(rows + copies, settings, a)))
        self.assertIn(f"    - here its {len(keep)} rows equal `keep`'s seed for seed on every metric", page)
        # One seed's lane changes differ: not the same runs.
        copies[-1] = dict(copies[-1], lane_changes_per_cav=str(float(copies[-1]["lane_changes_per_cav"]) + 0.01))
        own = trial_results.analyse_variants(rows + copies, settings, a)[0]["entries"][0]["vs_own"][0]
        self.assertEqual(own["same_as"], [])

    def test_an_own_control_named_twice_or_an_empty_list_is_refused(self):
        twice = {"arm": "c", "what": "x"}
        settings = {"variants": {"a": {"base": "palcas", "own_control": [twice, dict(twice)]}}}
        with self.assertRaisesRegex(trial_results.TrialError, "'a' own_control 'c' is named twice"):
            trial_results.own_controls(settings)
        settings = {"variants": {"a": {"base": "palcas", "own_control": []}}}
        with self.assertRaisesRegex(trial_results.TrialError, "'a' own_control is an empty list"):
            trial_results.own_controls(settings)
        settings = {"variants": {"a": {"base": "palcas", "own_control": [twice, {"arm": "a", "what": "y"}]}}}
        with self.assertRaisesRegex(trial_results.TrialError, "'a' own_control 'a' is a variant"):
            trial_results.own_controls(settings)

    def test_an_own_control_that_is_a_variant_or_says_nothing_is_refused(self):
        settings = {"variants": {"a": {"base": "palcas", "own_control": {"arm": "a", "what": "x"}}}}
        with self.assertRaisesRegex(trial_results.TrialError, "'a' own_control 'a' is a variant"):
            trial_results.own_controls(settings)
        settings = {"variants": {"a": {"base": "palcas", "own_control": {"arm": "c"}}}}
        with self.assertRaisesRegex(trial_results.TrialError, "'a' own_control needs an arm and a what"):
            trial_results.own_controls(settings)


class TrainingsTest(unittest.TestCase):
    """trial.json's trainings: the shipped configuration trained from other seeds, each paired
    with the cell's best control and with the shipped training, and the spread between the
    trainings beside the spread between traffic seeds."""

    def setUp(self):
        self.settings = json.loads((FIXTURE / "trial.json").read_text())
        self.settings["trainings"] = {"reference": "palcas", "arms": {
            "palcas": {"seed": 1, "what": "the shipped training"},
            "palcas_s201": {"seed": 201, "what": "trained from seed 201"},
            "palcas_s301": {"seed": 301, "what": "trained from seed 301"}}}
        self.rows = fixture_rows()
        for arm, factor in (("palcas_s201", 1.02), ("palcas_s301", 0.98)):
            for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
                self.rows.append(dict(r, arm=arm, point=r["point"].replace("palcas", arm),
                                      **{SPEED: repr(float(r[SPEED]) * factor)}))
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())

    def test_each_training_against_the_best_control_and_the_spread_between_them(self):
        tr = trial_results.analyse_trainings(self.rows, self.settings, self.a)
        self.assertEqual([x["cell"] for x in tr], [LOW], "only where a retraining has rows")
        x = tr[0]
        self.assertEqual(x["control"], [c for c in self.a["cells"] if c["cell"] == LOW][0]["best"])
        self.assertEqual([e["arm"] for e in x["entries"]], ["palcas", "palcas_s201", "palcas_s301"])
        ref = x["entries"][0]
        own = trial_results.compare(self.rows, "palcas", x["control"], LOW, SPEED, x["seeds"], ratio=True)
        self.assertAlmostEqual(ref["mean"], own["mean"])
        # speed x 1.02: each per-seed value is 1.02 (the reference's) + 2 points.
        means = [ref["mean"], 1.02 * ref["mean"] + 2.0, 0.98 * ref["mean"] - 2.0]
        for e, m in zip(x["entries"], means):
            self.assertAlmostEqual(e["mean"], m)
        self.assertAlmostEqual(x["between_sd"], trial_results.stdev(means))
        own = trial_results.arm_cell(self.rows, "palcas", LOW)["metrics"]
        self.assertAlmostEqual(ref["dsr"], own["dsr"]["mean"])
        self.assertAlmostEqual(x["entries"][1]["lane_changes"], own["lane_changes_per_cav"]["mean"],
                               msg="only the speed of the copies was changed")
        self.assertAlmostEqual(x["between_range"][0], min(means))
        pooled = ref["sd"] * math.sqrt((1 + 1.02 ** 2 + 0.98 ** 2) / 3)
        self.assertAlmostEqual(x["within_sd"], pooled)
        self.assertAlmostEqual(x["within_se"], pooled / math.sqrt(len(x["seeds"])))
        up, down = x["entries"][1]["vs_reference"], x["entries"][2]["vs_reference"]
        self.assertAlmostEqual(up["mean"], 2.0)
        self.assertAlmostEqual(down["mean"], -2.0)
        self.assertEqual((trial_results.verdict(up), trial_results.verdict(down)), ("gain", "loss"))
        page = "\n".join(trial_results.trainings_section(tr))
        self.assertIn("## Variance across trainings of the shipped configuration", page)
        self.assertIn("| `palcas_s201` vs `palcas` | speed ratio − 1 |", page)
        self.assertIn("- Between trainings (3): mean", page)
        csv_lines = trial_results.trainings_csv(tr).splitlines()
        self.assertEqual(len(csv_lines), 1 + 3 + 2)

    def test_its_rows_are_counted_and_the_reference_stays_in_the_grid(self):
        lines = trial_results.what_was_run(self.rows, [FIXTURE / "results.csv"], self.settings, FIXTURE, self.a)
        self.assertIn("- Trainings of the shipped configuration from other seeds: 6 rows of `palcas_s201`, "
                      "`palcas_s301` (6 finished)", lines)
        self.assertFalse([l for l in lines if "outside the planned grid" in l and "palcas_s" in l])
        self.assertIn("palcas", self.a["learned"], "the reference is still a learned arm of the grid")
        self.assertTrue(math.isnan(trial_results.stdev([1.0])), "no spread from one training")

    def add_alternative(self, factors):
        """An alternative configuration whose trainings are the reference's speeds × each factor."""
        arms = {}
        for i, factor in enumerate(factors):
            arm = f"palcas_alt_s{i + 1}"
            arms[arm] = {"seed": i + 1, "what": f"alternative from seed {i + 1}"}
            for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
                self.rows.append(dict(r, arm=arm, point=r["point"].replace("palcas", arm),
                                      **{SPEED: repr(float(r[SPEED]) * factor)}))
        self.settings["trainings"]["alternatives"] = {"cheap": {"what": "a cheaper schedule", "arms": arms}}
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())

    def test_an_alternative_configuration_is_compared_training_by_training(self):
        self.add_alternative([0.90, 0.91, 0.89])
        x = trial_results.analyse_trainings(self.rows, self.settings, self.a)[0]
        alt = x["alternatives"][0]
        self.assertEqual([e["arm"] for e in alt["entries"]], ["palcas_alt_s1", "palcas_alt_s2", "palcas_alt_s3"])
        ref = x["entries"][0]["mean"]
        means = [f * ref + 100.0 * (f - 1.0) for f in (0.90, 0.91, 0.89)]
        for e, m in zip(alt["entries"], means):
            self.assertAlmostEqual(e["mean"], m)
        shipped = [e["mean"] for e in x["entries"]]
        diff, lo, hi = trial_results.welch_interval(means, shipped)
        self.assertAlmostEqual(alt["diff"], sum(means) / 3 - sum(shipped) / 3)
        self.assertAlmostEqual(alt["lo"], lo)
        self.assertAlmostEqual(alt["hi"], hi)
        self.assertEqual(alt["verdict"], "loss", "10 points below, against trainings 2 points apart")
        page = "\n".join(trial_results.trainings_section([x]))
        self.assertIn("#### Another configuration, `cheap`, trained from 3 seeds", page)
        self.assertIn("a cheaper schedule", page)
        self.assertIn("(3 against 3 trainings, their means over the same", page)
        self.assertEqual(len(trial_results.trainings_csv([x]).splitlines()), 1 + 3 + 2 + 3 + 1)
        self.assertIn("palcas_alt_s2", trial_results.extra_arms(self.settings))
        lines = trial_results.what_was_run(self.rows, [FIXTURE / "results.csv"], self.settings, FIXTURE, self.a)
        self.assertIn("- Trainings of other configurations: 9 rows of `palcas_alt_s1`, `palcas_alt_s2`, "
                      "`palcas_alt_s3` (9 finished)", lines)

    def test_an_alternative_inside_the_spread_is_no_difference_and_one_training_is_none(self):
        self.add_alternative([1.01, 0.99])
        x = trial_results.analyse_trainings(self.rows, self.settings, self.a)[0]
        self.assertEqual(x["alternatives"][0]["verdict"], "none")
        self.rows = [r for r in self.rows if r["arm"] != "palcas_alt_s2"]
        x = trial_results.analyse_trainings(self.rows, self.settings, self.a)[0]
        self.assertEqual(x["alternatives"], [], "one training has no spread to compare with")

    def test_an_alternative_against_another_is_compared_with_that_ones_trainings(self):
        self.add_alternative([0.90, 0.91, 0.89])
        arms = {}
        for i, factor in enumerate([0.80, 0.82]):
            arm = f"palcas_alt2_s{i + 1}"
            arms[arm] = {"seed": i + 1, "what": f"the other alternative from seed {i + 1}"}
            for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
                self.rows.append(dict(r, arm=arm, point=r["point"].replace("palcas", arm),
                                      **{SPEED: repr(float(r[SPEED]) * factor)}))
        self.settings["trainings"]["alternatives"]["cheaper"] = {"what": "cheaper still", "arms": arms,
                                                                 "against": "cheap"}
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        x = trial_results.analyse_trainings(self.rows, self.settings, self.a)[0]
        by = {alt["name"]: alt for alt in x["alternatives"]}
        cheap, cheaper = by["cheap"], by["cheaper"]
        diff, lo, hi = trial_results.welch_interval(cheaper["means"], cheap["means"])
        self.assertAlmostEqual(cheaper["diff"], diff)
        self.assertAlmostEqual(cheaper["lo"], lo)
        self.assertAlmostEqual(cheaper["base_mean"], cheap["mean_of_means"])
        self.assertEqual(cheaper["base_n"], 3)
        shipped = trial_results.welch_interval(cheap["means"], [e["mean"] for e in x["entries"]])
        self.assertAlmostEqual(cheap["diff"], shipped[0], msg="the one without `against` stays on the shipped")
        page = "\n".join(trial_results.trainings_section([x]))
        self.assertIn("- `cheaper` against `cheap`, the training as the unit (2 against 3 trainings", page)
        self.assertIn("- `cheap` against the shipped configuration, the training as the unit (3 against 3", page)
        self.assertIn(',"cheaper minus cheap (Welch, trainings)",', trial_results.trainings_csv([x]))
        # What it is compared with has one training in the cell: no comparison there.
        self.rows = [r for r in self.rows if r["arm"] not in ("palcas_alt_s2", "palcas_alt_s3")]
        x = trial_results.analyse_trainings(self.rows, self.settings, self.a)[0]
        self.assertEqual(x["alternatives"], [])

    def test_an_alternative_against_what_is_not_an_alternative_is_refused(self):
        self.add_alternative([0.90, 0.91])
        for against in ("cheap", "nonesuch"):
            self.settings["trainings"]["alternatives"]["cheap"]["against"] = against
            with self.assertRaisesRegex(trial_results.TrialError, f"alternative 'cheap' is against '{against}'"):
                trial_results.analyse_trainings(self.rows, self.settings, self.a)

    def test_the_welch_interval(self):
        diff, lo, hi = trial_results.welch_interval([1.0, 2.0, 3.0], [4.0, 5.0, 6.0])
        # Equal variances 1, n 3 and 3: se sqrt(2/3), Welch df 4, t 2.776.
        half = 2.776 * math.sqrt(2.0 / 3.0)
        self.assertAlmostEqual(diff, -3.0)
        self.assertAlmostEqual(lo, -3.0 - half)
        self.assertAlmostEqual(hi, -3.0 + half)
        self.assertTrue(math.isnan(trial_results.welch_interval([1.0], [2.0, 3.0])[1]))
        self.assertEqual(trial_results.welch_interval([1.0, 1.0], [2.0, 2.0]), (-1.0, -1.0, -1.0))

    def test_no_section_without_a_retraining(self):
        only_ref = [r for r in self.rows if r["arm"] not in ("palcas_s201", "palcas_s301")]
        self.assertEqual(trial_results.analyse_trainings(only_ref, self.settings, self.a), [])
        self.assertEqual(trial_results.trainings_section([]), [])


class TargetsTest(unittest.TestCase):
    """trial.json's targets: each target of the learned advice on each cell, from the page's own
    numbers, met or missed and by how much."""

    def setUp(self):
        self.settings = json.loads((FIXTURE / "trial.json").read_text())
        self.settings["targets"] = {}
        self.rows = fixture_rows()
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())

    def targets(self, **override):
        self.settings["targets"].update(override)
        return trial_results.analyse_targets(self.a, [], self.settings)

    def find(self, targets, start, cell):
        return [r for r in targets if r["target"].startswith(start) and r["cell"] == cell]

    def test_no_section_unless_the_trial_names_targets(self):
        del self.settings["targets"]
        self.assertEqual(trial_results.analyse_targets(self.a, [], self.settings), [])
        self.assertEqual(trial_results.targets_section([]), [])

    def test_each_target_is_read_from_the_cells_numbers(self):
        targets = self.targets()
        x = {c["cell"]: c for c in self.a["cells"]}
        best = x[HIGH]["best"]
        [speed] = self.find(targets, "speed of the better learned mode", HIGH)
        c = trial_results.compare(self.rows, "palcas", best, HIGH, SPEED, SEEDS, ratio=True)
        self.assertEqual(speed["met"], c["mean"] >= 3.0 and trial_results.span(c)[0] > 0)
        self.assertEqual(speed["arm"], "palcas")
        self.assertEqual(self.find(targets, "speed of the better learned mode", LOW), [],
                         "1000 is not a busy demand")
        arms = x[LOW]["arms"]
        [decided] = self.find(targets, "advisory mode: DSR of the decided exits", LOW)
        plain = [float(r["dsr_pct"]) for r in self.rows
                 if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW and r["status"] == "done"]
        self.assertAlmostEqual(arms["palcas"]["dsr_decided"]["mean"], sum(plain) / len(plain))
        self.assertEqual(decided["met"], sum(plain) / len(plain) >= 99.5)
        [censored] = self.find(targets, "advisory mode: DSR, censored counted, vs `sumo_native`", LOW)
        c = trial_results.compare(self.rows, "palcas", "sumo_native", LOW, "dsr", SEEDS)
        self.assertEqual(censored["met"], c["mean"] >= -0.5)
        self.assertTrue(censored["measured"].startswith(trial_results.fmt(c["mean"], 1, signed=True) + " points"))
        [lc] = self.find(targets, "advisory mode: lane changes", LOW)
        factor = (arms["palcas"]["metrics"]["lane_changes_per_cav"]["mean"]
                  / arms["sumo_native"]["metrics"]["lane_changes_per_cav"]["mean"])
        self.assertTrue(lc["measured"].startswith(trial_results.fmt(factor, 2) + " ×"))
        self.assertEqual(lc["met"], factor <= 1.5)
        self.assertEqual(self.find(targets, "assist mode", LOW), [], "no assist arm in the fixture")
        for r in targets:
            self.assertEqual(r["short"] == "", r["met"], r)

    def test_assist_modes_dsr_reads_the_decided_exits(self):
        # An assist arm that serves every decided exit but ends with exit-bound CAVs still on
        # the road: met on the decided exits, whatever the censored count; one missed exit on
        # one seed misses it.
        for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
            self.rows.append(dict(r, arm="palcas_assist", point=r["point"].replace("palcas", "palcas_assist"),
                                  dsr_pct="100.0", dsr_censored_pct="96.0"))
        for r in [r for r in self.rows if r["arm"] == "sumo_native" and (r["demand"], r["pr"]) == LOW]:
            self.rows.append(dict(r, arm="rules_assist", point=r["point"].replace("sumo_native", "rules_assist")))
        self.settings["arms"] += ["palcas_assist", "rules_assist"]
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        [dsr] = self.find(self.targets(), "assist mode: DSR", LOW)
        self.assertEqual(dsr["target"], "assist mode: DSR of the decided exits")
        self.assertTrue(dsr["met"], dsr)
        self.assertIn("censored counted 96.0 %", dsr["measured"])
        next(r for r in self.rows if r["arm"] == "palcas_assist")["dsr_pct"] = "97.0"
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        [dsr] = self.find(self.targets(), "assist mode: DSR", LOW)
        self.assertFalse(dsr["met"])
        self.assertEqual(dsr["short"], "1.0 points below")

    def test_the_thresholds_come_from_the_trial(self):
        for r in self.find(self.targets(decision_p99_ms=1e-6), "decision p99", HIGH):
            self.assertFalse(r["met"])
            self.assertIn("ms over", r["short"])
        [speed] = self.find(self.targets(busy_speed_gain_pct=-1000.0), "speed of the better", HIGH)
        self.assertNotIn("below", speed["short"], "a gain of -1000 % is always reached")
        self.assertEqual(self.find(self.targets(busy_demands=[1000]), "speed of the better", HIGH), [])
        self.settings["targets"] = {"busy_speed_gain": 3}
        with self.assertRaisesRegex(trial_results.TrialError, "unknown key.*busy_speed_gain"):
            trial_results.analyse_targets(self.a, [], self.settings)

    def test_a_shipping_variant_stands_for_its_base(self):
        # palcas now ships another way, run at LOW only: its rows are what the targets read.
        for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
            self.rows.append(dict(r, arm="palcas_shipped", point=r["point"].replace("palcas", "palcas_shipped"),
                                  **{SPEED: repr(float(r[SPEED]) * 1.05)}))
        self.settings["variants"] = {"palcas_shipped": {"base": "palcas", "what": "as shipped", "ships": True},
                                     "palcas_other": {"base": "palcas", "what": "not shipped"}}
        shipped = trial_results.shipped_variants(self.settings)
        self.assertEqual(shipped, {"palcas": "palcas_shipped"})
        rows = trial_results.as_shipped(self.rows, shipped)
        self.assertFalse([r for r in rows if r["arm"] == "palcas_shipped"])
        self.assertFalse([r for r in rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == HIGH])
        a = trial_results.analyse(rows, self.settings, trial_results.load_registry())
        targets = trial_results.analyse_targets(a, [], self.settings, shipped)
        best = [x for x in a["cells"] if x["cell"] == LOW][0]["best"]
        [speed] = self.find(targets, "advisory mode: speed", LOW)
        self.assertEqual((speed["arm"], speed["rows_of"]), ("palcas", "palcas_shipped"))
        c = trial_results.compare(self.rows, "palcas_shipped", best, LOW, SPEED, SEEDS, ratio=True)
        self.assertTrue(speed["measured"].startswith(trial_results.fmt(c["mean"], 2, signed=True) + " %"), speed)
        self.assertFalse([r for r in targets if r["cell"] == HIGH and r["arm"] == "palcas"],
                         "the shipped way did not run at HIGH: no target of palcas there")
        page = "\n".join(trial_results.targets_section(targets))
        self.assertIn("| `palcas` (`palcas_shipped`) |", page)
        self.assertIn("`palcas` is read as it ships: from the rows of the variant `palcas_shipped`", page)
        self.assertIn(",palcas,palcas_shipped,", trial_results.targets_csv(targets))
        self.settings["variants"]["palcas_other"]["ships"] = True
        with self.assertRaisesRegex(trial_results.TrialError, "both ship as 'palcas'"):
            trial_results.shipped_variants(self.settings)
        self.settings["variants"] = {"palcas_shipped": {"what": "no base", "ships": True}}
        with self.assertRaisesRegex(trial_results.TrialError, "'palcas_shipped' ships but names no base"):
            trial_results.shipped_variants(self.settings)

    def test_the_federation_target_needs_a_gain_on_speed_and_dsr(self):
        for r in [r for r in self.rows if r["arm"] == "palcas" and (r["demand"], r["pr"]) == LOW]:
            self.rows.append(dict(r, arm="independent", point=r["point"].replace("palcas", "independent"),
                                  **{SPEED: repr(float(r[SPEED]) / 1.05)}))
        self.settings["federation"] = {"reference": "palcas", "arms": {"independent": "alone"}}
        self.a = trial_results.analyse(self.rows, self.settings, trial_results.load_registry())
        fed = trial_results.analyse_federation(self.rows, self.settings, self.a)
        [row] = [r for r in trial_results.analyse_targets(self.a, fed, self.settings)
                 if r["target"].startswith("federation")]
        self.assertFalse(row["met"])
        self.assertEqual(row["short"], "DSR no difference shown", "speed +5 % on every seed, DSR equal")
        page = "\n".join(trial_results.targets_section([row]))
        self.assertIn("**0 of 1 met.**", page)
        self.assertIn("**missed**: DSR no difference shown", page)
        self.assertEqual(len(trial_results.targets_csv([row]).splitlines()), 2)


class ApproachesTest(unittest.TestCase):
    """trial.json's approaches: what was tried where a target is missed, quoted on the page with
    the journal entry it comes from, which must exist."""

    def setUp(self):
        self.journal = pathlib.Path(tempfile.mkdtemp()) / "experiments.md"
        self.journal.write_text("# Journal\n\n## A dwell between changes (dev)\n\ntext\n")
        self.item = {"for": "item 2", "approach": "a dwell", "seeds": "dev 101-103",
                     "outcome": "fewer lane changes, slower", "journal": "A dwell between changes (dev)"}

    def tearDown(self):
        shutil.rmtree(self.journal.parent, ignore_errors=True)

    def test_each_approach_is_a_row_naming_its_journal_entry(self):
        items = trial_results.approaches({"approaches": [self.item]}, self.journal)
        page = "\n".join(trial_results.approaches_section(items))
        self.assertIn("## What was tried where a target is missed", page)
        self.assertIn("| item 2 | a dwell | dev 101-103 | fewer lane changes, slower | "
                      "A dwell between changes (dev) |", page)
        self.assertEqual(trial_results.approaches_section(trial_results.approaches({}, self.journal)), [])

    def test_a_missing_field_or_journal_entry_is_named(self):
        bad = dict(self.item, outcome=" ")
        with self.assertRaisesRegex(trial_results.TrialError, r"approaches\[0\]: no outcome"):
            trial_results.approaches({"approaches": [bad]}, self.journal)
        bad = dict(self.item, journal="A dwell (renamed)")
        with self.assertRaisesRegex(trial_results.TrialError, "journal heading 'A dwell \\(renamed\\)' is not in"):
            trial_results.approaches({"approaches": [self.item, bad]}, self.journal)
        with self.assertRaisesRegex(trial_results.TrialError, "approaches: not a list"):
            trial_results.approaches({"approaches": {"x": 1}}, self.journal)

    def test_the_committed_trial_names_only_journal_entries_that_exist(self):
        settings = json.loads((trial_results.ROOT / "docs" / "trial" / "trial.json").read_text())
        self.assertEqual(len(trial_results.approaches(settings)), len(settings.get("approaches") or []))


class TrialRowsTest(unittest.TestCase):
    """tools/trial_rows.py: an experiment's rows of one arm added to the trial under another name,
    and nothing written when anything is wrong."""

    def setUp(self):
        import trial_rows
        self.tool = trial_rows
        self.d = pathlib.Path(tempfile.mkdtemp(prefix="palcas_trial_rows_"))
        self.addCleanup(shutil.rmtree, self.d)
        self.src = self.d / "results.csv"
        shutil.copy(FIXTURE / "results.csv", self.src)
        self.palcas = [r for r in csv.DictReader(open(self.src)) if r["arm"] == "palcas"]

    def write_rows(self, name, rows):
        path = self.d / name
        with open(path, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(self.palcas[0]), lineterminator="\n")
            w.writeheader()
            w.writerows(rows)
        return path

    def test_rows_are_renamed_and_appended(self):
        out = self.d / "trial" / "results_x.csv"
        out.parent.mkdir()
        done = [r for r in self.palcas if r["status"] == "done"]
        only_done = self.write_rows("done.csv", done)
        self.assertEqual(self.tool.main(["--arm", "palcas", "--as", "palcas_x", "--out", str(out), str(only_done)]), 0)
        rows = list(csv.DictReader(open(out)))
        self.assertEqual([r["point"] for r in rows], [r["point"].replace("palcas_", "palcas_x_", 1) for r in done])
        self.assertEqual({r["arm"] for r in rows}, {"palcas_x"})
        self.assertEqual([r[SPEED] for r in rows], [r[SPEED] for r in done], "numbers untouched")
        before = out.read_text()
        with self.assertRaisesRegex(self.tool.RowsError, "already in"):
            self.tool.add_rows("palcas", "palcas_x", [str(only_done)], out)
        self.assertEqual(out.read_text(), before, "nothing written on a refusal")

    def test_refusals_name_what_is_wrong(self):
        out = self.d / "out.csv"
        cases = [("palcas", "keep", "an arm of config/arms.json"),
                 ("no_such_arm", "x", "no row of arm 'no_such_arm'"),
                 ("palcas", "palcas", "the same name")]
        for arm, new, why in cases:
            with self.assertRaisesRegex(self.tool.RowsError, why):
                self.tool.add_rows(arm, new, [str(self.src)], out)
        failed = self.write_rows("failed.csv", [self.palcas[0], dict(self.palcas[1], status="failed")])
        with self.assertRaisesRegex(self.tool.RowsError, "palcas_pr60_d1000_s1002 did not finish"):
            self.tool.add_rows("palcas", "palcas_x", [str(failed)], out)
        other = self.d / "other.csv"
        other.write_text("point,arm,status\npalcas_a,palcas,done\n")
        with self.assertRaisesRegex(self.tool.RowsError, "columns differ"):
            self.tool.add_rows("palcas", "palcas_x", [str(self.src), str(other)], out, keep_failed=True)
        self.assertFalse(out.exists())
        self.assertEqual(self.tool.main(["--arm", "palcas", "--as", "keep", "--out", str(out), str(self.src)]), 2)


class MechanismTest(unittest.TestCase):
    def test_the_real_registry(self):
        import yaml
        registry = trial_results.load_registry()
        defaults = yaml.safe_load((ROOT / "config" / "bridge.yaml").read_text())
        rows = {r[0]: dict(zip(trial_results.MECHANISM_HEAD, r))
                for r in trial_results.mechanism_rows(list(registry), registry, {})}
        self.assertEqual(list(rows), list(registry))
        for arm, entry in registry.items():
            r = rows[arm]
            self.assertEqual(r["RSUs"], entry["rsus"])
            self.assertEqual(r["advisory control"], "yes" if entry["advisory_control"] else "no")
            guard = [r[k] for k in trial_results.MECHANISM_HEAD[8:12]]
            if not entry["advisory_control"]:
                self.assertEqual(guard, ["—"] * 4, arm)
                continue
            params = dict(defaults)
            own = ROOT / "policies" / arm / "bridge.yaml"
            if entry["shipped_policy"] and own.exists():
                params.update(yaml.safe_load(own.read_text()))
            elif entry.get("bridge_params"):
                params.update(yaml.safe_load((ROOT / "config" / entry["bridge_params"]).read_text()))
            lc = float(params["guard_busy_lc_assertive"])
            self.assertEqual(r["busy-zone gap acceptance"], f"lcAssertive {lc:.1f}" if lc > 0 else "off", arm)
            self.assertEqual(r["busy-zone hand-back"], "on" if params["guard_busy_handback"] else "off", arm)
            for col, key in (("busy-zone change bound", "guard_busy_change_max_accel_mps2"),
                             ("advised-change accel. bound", "lane_change_max_accel_mps2")):
                v = float(params[key])
                self.assertEqual(r[col], f"{v:g} m/s²" if v > 0 else "off", (arm, col))
        self.assertEqual(rows["sumo_native"]["advice"], "none")
        self.assertEqual(rows["palcas"]["advice"], "learned network")
        self.assertIn("policies/palcas/bridge.yaml", rows["palcas"]["bridge files over config/bridge.yaml"])

    def test_a_guard_turned_off_shows_its_columns_off(self):
        import yaml
        from unittest import mock
        registry = trial_results.load_registry()
        arm = next(a for a, e in registry.items() if e["advisory_control"])
        params = dict(yaml.safe_load((ROOT / "config" / "bridge.yaml").read_text()), guard_enabled=False)
        with mock.patch.object(trial_results, "bridge_params", return_value=(params, [])):
            row = dict(zip(trial_results.MECHANISM_HEAD, trial_results.mechanism_rows([arm], registry, {})[0]))
        self.assertEqual([row[k] for k in trial_results.MECHANISM_HEAD[8:11]], ["off"] * 3)

    def test_advice_is_the_field_else_inferred_from_the_rsus(self):
        self.assertEqual(trial_results.advice_of({"rsus": "zones"}), "network")
        self.assertEqual(trial_results.advice_of({"rsus": "none"}), "none")
        self.assertEqual(trial_results.advice_of({"rsus": "zones", "advice": "rules"}), "rules")
        self.assertEqual(trial_results.ADVICE_WORDS[trial_results.advice_of({"rsus": "central"})], "learned network")


class PageTest(unittest.TestCase):
    def setUp(self):
        self.out = pathlib.Path(tempfile.mkdtemp(prefix="palcas_trial_test_"))

    def tearDown(self):
        shutil.rmtree(self.out, ignore_errors=True)

    def test_the_committed_fixture_page_is_current(self):
        self.assertIsNone(trial_results.check(FIXTURE, EXPECTED))

    def test_the_page_is_deterministic(self):
        a, _ = trial_results.generate(FIXTURE, EXPECTED)
        b, _ = trial_results.generate(FIXTURE, EXPECTED)
        self.assertEqual(a, b)
        page = a["RESULTS.md"]
        self.assertIn("`keep` 2200 / PR 60 s1003: failed ([FATAL] rsu_0: fixture failure)", page)
        self.assertIn("`sumo_native` 2200 / PR 60 s1003: missing (no row)", page)
        self.assertIn("Seeds (3, set `test` of config/seeds.yaml): 1001, 1002, 1003", page)
        self.assertIn("- `palcas` vs `keep`: seeds left out: s1003 (keep: failed)", page)
        self.assertIn("- `palcas` vs best control (sumo_native), 3 paired seeds: speed +1.8 % [+1.0, +2.6]", page)

    def test_check_names_the_first_difference(self):
        with contextlib.redirect_stdout(io.StringIO()):
            trial_results.main([str(FIXTURE), "--out", str(self.out / "page")])
        page = self.out / "page" / "RESULTS.md"
        self.assertIsNone(trial_results.check(FIXTURE, self.out / "page"))
        text = page.read_text()
        page.write_text(text.replace("28.47 ± 0.88", "28.48 ± 0.88", 1))
        diff = trial_results.check(FIXTURE, self.out / "page")
        self.assertIn("RESULTS.md line", diff)
        self.assertIn("28.48 ± 0.88", diff)
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            self.assertEqual(trial_results.main([str(FIXTURE), "--out", str(self.out / "page"), "--check"]), 1)
        self.assertIn("28.48", err.getvalue())
        page.write_text(text)
        (self.out / "page" / "results" / "paired.csv").unlink()
        self.assertIn("paired.csv is missing", trial_results.check(FIXTURE, self.out / "page"))

    def test_writing_gives_what_check_accepts(self):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            self.assertEqual(trial_results.main([str(FIXTURE), "--out", str(self.out)]), 0)
        self.assertTrue((self.out / "results" / "speed_ratio.png").stat().st_size > 5000)
        self.assertTrue((self.out / "results" / "paired_seeds.png").stat().st_size > 5000)
        self.assertIsNone(trial_results.check(FIXTURE, self.out))
        (self.out / "results" / "old.csv").write_text("x\n")
        self.assertIn("old.csv is not generated", trial_results.check(FIXTURE, self.out))

    def test_bad_input_is_named(self):
        err = io.StringIO()
        with contextlib.redirect_stderr(err):
            self.assertEqual(trial_results.main([str(self.out / "nope"), "--out", str(self.out)]), 2)
        self.assertIn("no such folder", err.getvalue())
        twice = self.out / "twice"
        twice.mkdir()
        shutil.copy(FIXTURE / "results.csv", twice / "a.csv")
        shutil.copy(FIXTURE / "results.csv", twice / "b.csv")
        with self.assertRaisesRegex(trial_results.TrialError, "is also in"):
            trial_results.read_trial(twice)

    def test_the_committed_results_page_is_current(self):
        trial = ROOT / "docs" / "trial"
        if not trial.is_dir():
            self.skipTest("no docs/trial yet: no committed trial results")
        self.assertIsNone(trial_results.check(trial, ROOT / "docs"))


class SeedSetsTest(unittest.TestCase):
    def test_the_sets(self):
        sets = seed_sets.load()
        self.assertEqual(sets["dev"], list(range(101, 131)))
        self.assertEqual(sets["test"], list(range(1001, 1031)))
        self.assertEqual(seed_sets.seeds("dev", 3), [101, 102, 103])
        self.assertEqual(seed_sets.set_of([1001, 1030]), "test")
        self.assertIsNone(seed_sets.set_of([101, 1001]))
        with self.assertRaisesRegex(seed_sets.SeedSetError, r"seed set 'dev' has 30 seeds \(101-130\), not 31"):
            seed_sets.seeds("dev", 31)
        with self.assertRaisesRegex(seed_sets.SeedSetError, "unknown seed set 'x'"):
            seed_sets.seeds("x", 1)

    def test_a_seed_in_two_sets_is_refused(self):
        d = pathlib.Path(tempfile.mkdtemp())
        self.addCleanup(shutil.rmtree, d)
        (d / "seeds.yaml").write_text("dev: [1, 2]\ntest: [2, 3]\n")
        with self.assertRaisesRegex(seed_sets.SeedSetError, "seed 2 is also in set 'dev'"):
            seed_sets.load(d / "seeds.yaml")


def main():
    run_as_junit(sys.modules[__name__], "trial_results")


if __name__ == "__main__":
    main()
