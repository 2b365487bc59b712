#!/usr/bin/env python3
"""Tests of the arm registry (config/arms.json, tools/palcas_arms.py) and of adding an arm:
one new entry in a scratch copy of the suite, and ./palcas run / train / experiment
(tools/palcas_cli), run_figures.py and launch/system.launch take it with no other edit. The launch part
needs the workspace's ROS environment (./palcas test sources it).

usage: arm_registry_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import palcas_arms  # noqa: E402
import policy_folder  # noqa: E402
import seed_sets  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402

PYTHON = "/usr/bin/python3"  # the system Python: ROS's modules and PyYAML
NEW_ARM = "test_arm"


def entry(**kw):
    e = dict(palcas_arms.ARMS["palcas"])
    e.pop("shipped_rsu_params", None)  # says what policies/palcas/ holds, not what an arm "x" would
    e.update(kw)
    return e


class Registry(unittest.TestCase):
    def test_the_arms_and_which_learn(self):
        self.assertEqual(palcas_arms.ALL_ARMS, ("palcas", "palcas_assist", "centralized", "independent",
                                                "no_priority", "rules", "rules_assist", "keep", "sumo_native"))
        self.assertEqual(palcas_arms.LEARNING_ARMS, palcas_arms.ALL_ARMS[:5])
        self.assertEqual(palcas_arms.CONTROL_ARMS, palcas_arms.ALL_ARMS[5:])
        self.assertFalse(palcas_arms.is_learning("keep"))
        self.assertFalse(palcas_arms.is_learning("rules"))  # RSUs, but a rule: nothing learns

    def test_control_arms_drive_the_same_cavs_as_the_learned_ones(self):
        """A fair trial: every arm that carries out advice and has no policy of its own runs under
        the same bridge parameters the shipped policies carry (their bridge.yaml)."""
        shipped = {policy_folder.bridge_params(policy_folder.shipped(a)).read_text().split("\n# ")[0]
                   for a in palcas_arms.LEARNING_ARMS if palcas_arms.ARMS[a]["shipped_policy"]}
        import yaml
        shipped_values = {yaml.safe_load(policy_folder.bridge_params(policy_folder.shipped(a)).read_text()).__repr__()
                          for a in palcas_arms.LEARNING_ARMS if palcas_arms.ARMS[a]["shipped_policy"]}
        self.assertEqual(len(shipped_values), 1, shipped_values)
        for arm in palcas_arms.CONTROL_ARMS:
            e = palcas_arms.ARMS[arm]
            with self.subTest(arm=arm):
                if not e["advisory_control"]:
                    self.assertEqual(e["bridge_params"], "")
                    continue
                own = yaml.safe_load((ROOT / "config" / e["bridge_params"]).read_text())
                self.assertEqual(repr(own), shipped_values.pop() if len(shipped_values) == 1 else None)
                shipped_values = {repr(own)}
        self.assertTrue(shipped)

    def test_rsu_ids_follow_the_arms_rule(self):
        self.assertEqual(palcas_arms.rsu_ids("centralized", 3), ["central"])
        self.assertEqual(palcas_arms.rsu_ids("palcas", 2), ["rsu_0", "rsu_1"])
        self.assertEqual(palcas_arms.rsu_ids("keep", 3), [])

    def test_titles_and_order(self):
        self.assertEqual(palcas_arms.title("centralized"), "Baseline-1 (centralized)")
        self.assertEqual(palcas_arms.title("other"), "other")
        self.assertEqual(palcas_arms.sort_arms(["zz", "sumo_native", "keep", "palcas"]),
                         ["palcas", "keep", "sumo_native", "zz"])

    def test_a_bad_entry_is_refused_naming_the_arm(self):
        no_title = entry()
        del no_title["title"]
        for arms, text in (({"x": no_title}, "fields"),
                           ({"x": entry(federation="yes")}, "federation is not a bool"),
                           ({"x": entry(rsus="two")}, "rsus 'two'"),
                           ({"x": entry(rsus="central")}, "federation and i2i need RSUs per zone"),
                           ({"x": entry(rsus="none", federation=False, i2i=False)}, "without RSUs"),
                           ({"X-1": entry()}, "a name is"),
                           ({}, "not a mapping")):
            with self.subTest(text=text), self.assertRaises(palcas_arms.RegistryError) as e:
                palcas_arms.check(arms)
            self.assertIn(text, str(e.exception))
        with self.assertRaises(palcas_arms.RegistryError):
            palcas_arms.check({"x": entry(assist_mode=True, advisory_control=False)})
        rules = entry(advice="rules", federation=False, i2i=False, priority_reward=False, shipped_policy=False)
        palcas_arms.check({"x": rules})  # a rule arm as it should be
        for arms, text in (({"x": entry(advice="magic")}, "advice 'magic'"),
                           ({"x": entry(advice="none")}, "without RSUs there is no advice"),
                           ({"x": dict(rules, federation=True)}, "a rule learns nothing"),
                           ({"x": dict(rules, bridge_params="no/such.yaml")}, "is not a file under config/"),
                           ({"x": entry(bridge_params="training/gentle_lane_changes.yaml")}, "carries its own")):
            with self.subTest(text=text), self.assertRaises(palcas_arms.RegistryError) as e:
                palcas_arms.check(arms)
            self.assertIn(text, str(e.exception))

    def test_the_registry_says_which_shipped_policies_carry_rsu_parameters(self):
        # roslaunch cannot ask whether policies/<arm>/rsu.yaml exists: the flag must match the files.
        for arm, e in palcas_arms.ARMS.items():
            with self.subTest(arm=arm):
                self.assertEqual(e.get("shipped_rsu_params", False), (ROOT / "policies" / arm / "rsu.yaml").is_file())
        for arms, text in (({"x": entry(shipped_rsu_params=True)}, "policies/x/rsu.yaml does not exist"),
                           ({"x": entry(shipped_rsu_params="yes")}, "shipped_rsu_params is not a bool"),
                           ({"x": entry(shipped_rsu_params=True, shipped_policy=False)}, "needs a shipped policy"),
                           ({"x": entry(other=True)}, "optionally shipped_rsu_params")):
            with self.subTest(text=text), self.assertRaises(palcas_arms.RegistryError) as e:
                palcas_arms.check(arms)
            self.assertIn(text, str(e.exception))
        carried = [a for a, e in palcas_arms.ARMS.items() if e.get("shipped_rsu_params")]
        for arm in carried:  # a file the registry does not know of is refused too
            with self.subTest(arm=arm), self.assertRaises(palcas_arms.RegistryError) as e:
                palcas_arms.check({arm: dict(palcas_arms.ARMS[arm], shipped_rsu_params=False)})
            self.assertIn("exists (the launch would not load it)", str(e.exception))

    def test_json_that_roslaunch_would_read_otherwise_is_refused(self):
        with tempfile.TemporaryDirectory() as d:
            f = pathlib.Path(d) / "arms.json"
            f.write_text('{"x": null}\n')  # JSON's null is no Python literal
            with self.assertRaises(palcas_arms.RegistryError):
                palcas_arms.load(f)

    def test_shipped_policies_agree_with_policies_folder(self):
        """shipped_policy says policies/<arm>/ holds the arm's policy with its bridge.yaml, which
        system.launch loads by default: a policy shipped without its entry saying so, or the
        other way round, fails here (the palcas_assist bridge.yaml the launch once ignored)."""
        for arm in palcas_arms.ALL_ARMS:
            folder = policy_folder.shipped(arm)
            with self.subTest(arm=arm):
                if palcas_arms.ARMS[arm]["shipped_policy"]:
                    self.assertIsNone(policy_folder.why_not(folder))
                    self.assertTrue(policy_folder.bridge_params(folder).is_file(),
                                    f"{folder} ships no {policy_folder.BRIDGE_PARAMS}")
                    self.assertEqual(policy_folder.train_record(folder)["arm"], arm)
                else:
                    self.assertFalse(folder.exists(), f"{folder} exists: set shipped_policy in config/arms.json")


def scratch_copy_with_new_arm(new_arm=NEW_ARM, like="independent", after="palcas", **fields):
    """The suite's scripts, tools, configuration and launch files in a temporary folder, the
    policies linked, and one entry added to the copy's config/arms.json (after palcas: its
    order is the registry's)."""
    copy = pathlib.Path(tempfile.mkdtemp(prefix="palcas_new_arm_"))
    shutil.copy2(ROOT / "palcas", copy / "palcas")
    for d in ("tools", "config", "launch"):
        shutil.copytree(ROOT / d, copy / d, ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "policies").symlink_to(ROOT / "policies")
    arms = json.loads((copy / "config" / "arms.json").read_text())
    new = dict(arms[like], what="a test arm", title="Test arm", **(fields or dict(
        federation=True, i2i=True, shipped_policy=False)))
    with_new = {}
    for name, e in arms.items():
        with_new[name] = e
        if name == after:
            with_new[new_arm] = new
    (copy / "config" / "arms.json").write_text(json.dumps(with_new, indent=2) + "\n")
    return copy


def copy_launch_env(test, copy):
    """The environment in which roslaunch finds the copy's palcas_config, palcas_launch and
    palcas_policies (linked) before the workspace's, and the copy's system.launch."""
    if not shutil.which("roslaunch") or "ROS_PACKAGE_PATH" not in os.environ:
        test.fail("needs the workspace's ROS environment: source devel/setup.bash first")
    env = dict(os.environ, ROS_PACKAGE_PATH=f"{copy}:{os.environ['ROS_PACKAGE_PATH']}",
               PATH="/usr/bin:" + os.environ["PATH"])
    return env, str(copy / "launch" / "system.launch")


def run(cmd, cwd, env=None):
    return subprocess.run(cmd, cwd=cwd, env=env, capture_output=True, text=True, timeout=120)


class AddingAnArm(unittest.TestCase):
    """One entry in config/arms.json is the whole of adding an arm."""

    @classmethod
    def setUpClass(cls):
        cls.copy = scratch_copy_with_new_arm()
        cls.policy = cls.copy / "trained"  # a policy folder of the new arm (no real weights)
        policy_folder.checkpoints(cls.policy).mkdir(parents=True)
        policy_folder.train_record_path(cls.policy).write_text(json.dumps(
            {"arm": NEW_ARM, "scenario": "tiny", "seed": 1, "episodes": 2, "learning": ""}) + "\n")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.copy, ignore_errors=True)

    def palcas(self, root, *args):
        r = run(["bash", str(root / "palcas"), *args], cwd=root)
        self.assertEqual(r.returncode, 2, r.stderr)  # a checked option: nothing built or started
        self.assertNotIn("building", r.stderr)
        return r.stderr

    def test_the_registry_lists_it(self):
        r = run([PYTHON, "tools/palcas_arms.py", "--list", "learning"], cwd=self.copy)
        self.assertIn(NEW_ARM, r.stdout.split())

    def test_palcas_option_checks_accept_it(self):
        # run: a learning arm without a shipped policy, not an unknown arm.
        self.assertIn(f"--arm {NEW_ARM}: no trained policy in policies/{NEW_ARM}/",
                      self.palcas(self.copy, "run", "--arm", NEW_ARM))
        self.assertIn(f"--arm '{NEW_ARM}': unknown arm", self.palcas(ROOT, "run", "--arm", NEW_ARM))
        # run --policy: a policy trained for it is a learning arm's (the check after the arm's).
        (self.policy / "bridge.yaml").write_text("- not a mapping\n")
        try:
            self.assertIn("its bridge.yaml is not a YAML mapping",
                          self.palcas(self.copy, "run", "--policy", str(self.policy)))
        finally:
            (self.policy / "bridge.yaml").unlink()
        # train: a learning arm (the check after the arm's refuses the --learning file).
        self.assertIn("--learning", self.palcas(self.copy, "train", "--arm", NEW_ARM, "--learning", "/nonexistent"))
        self.assertIn("unknown arm", self.palcas(ROOT, "train", "--arm", NEW_ARM, "--learning", "/nonexistent"))

    def test_experiment_plans_its_points(self):
        out = self.copy / "experiment"
        r = run([PYTHON, "tools/palcas_cli", "experiment", "--plan", "--out", str(out), "--arms", f"keep,{NEW_ARM}",
                 "--prs", "60", "--seeds", "1", "--duration", "10", "--scenario", "tiny",
                 "--policy", f"{NEW_ARM}={self.policy}"], cwd=self.copy)
        self.assertEqual(r.returncode, 0, r.stderr)
        first_test_seed = seed_sets.seeds("test", 1)[0]  # experiments report on the test seeds
        self.assertIn(f"{NEW_ARM}_pr60_s{first_test_seed}", (out / "plan.txt").read_text())

    def test_figures_order_and_tables_title_it(self):
        r = run([PYTHON, "-c", "import sys; sys.path.insert(0, 'tools'); import run_figures, experiment_results; "
                 f"print(run_figures.sort_arms(['keep', '{NEW_ARM}', 'palcas']), experiment_results.title('{NEW_ARM}'))"],
                cwd=self.copy)
        self.assertEqual(r.stdout.strip(), f"['palcas', '{NEW_ARM}', 'keep'] Test arm", r.stderr)

    def test_train_takes_it_with_its_rsus(self):
        r = run([PYTHON, "tools/palcas_cli", "check", "train", "--out", str(self.copy / "t"), "--arm", NEW_ARM],
                cwd=self.copy)
        self.assertEqual(r.returncode, 0, r.stderr)
        r = run([PYTHON, str(ROOT / "tools" / "palcas_cli"), "check", "train", "--out", str(self.copy / "t"),
                 "--arm", NEW_ARM], cwd=self.copy)
        self.assertEqual(r.returncode, 2)
        self.assertIn(f"--arm '{NEW_ARM}': unknown arm", r.stderr)
        r = run([PYTHON, "-c", f"import sys; sys.path.insert(0, 'tools'); from palcas_cli import train; "
                 f"print(train.palcas_arms.rsu_ids('{NEW_ARM}', 3))"], cwd=self.copy)
        self.assertEqual(r.stdout.strip(), "['rsu_0', 'rsu_1', 'rsu_2']", r.stderr)

    def test_the_launch_runs_it(self):
        env, launch = copy_launch_env(self, self.copy)
        r = run(["roslaunch", "--nodes", launch, f"arm:={NEW_ARM}", "out_dir:=/tmp/unused"], cwd=self.copy, env=env)
        self.assertEqual(sorted(r.stdout.split()), ["/fedserver/palcas_fedserver", "/palcas_sumo_bridge",
                                                    "/rsu_0/rsu", "/rsu_1/rsu", "/rsu_2/rsu"], r.stdout + r.stderr)
        r = run(["roslaunch", "--dump-params", launch, f"arm:={NEW_ARM}", "out_dir:=/tmp/unused"], cwd=self.copy, env=env)
        for line in ("/rsu_0/rsu/federation: true", "/rsu_0/rsu/i2i: true", "/palcas_sumo_bridge/assist_mode: false",
                     f"/rsu_0/rsu/policy_dir: {self.copy}/policies/{NEW_ARM}/checkpoints"):
            self.assertIn(line, r.stdout.splitlines(), r.stderr)
        # The workspace's own registry does not know it.
        r = run(["roslaunch", "--nodes", str(ROOT / "launch" / "system.launch"), f"arm:={NEW_ARM}",
                 "out_dir:=/tmp/unused"], cwd=ROOT)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn(f"unknown_arm_{NEW_ARM}", r.stdout + r.stderr)




CONTROL_ARM = "test_rule_arm"


class AddingAControlArm(unittest.TestCase):
    """A non-learning control arm (RSUs advising by the rule) is one registry entry too, and
    every command runs it like any other arm."""

    @classmethod
    def setUpClass(cls):
        cls.copy = scratch_copy_with_new_arm(CONTROL_ARM, like="rules", after="rules", i2i=True)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.copy, ignore_errors=True)

    def test_it_is_a_control_not_a_learning_arm(self):
        r = run([PYTHON, "tools/palcas_arms.py", "--help-text"], cwd=self.copy)
        self.assertIn(f"  {CONTROL_ARM}", r.stdout)
        line = next(l for l in r.stdout.splitlines() if l.strip().startswith(CONTROL_ARM))
        self.assertIn("rule", line.split()[1])
        r = run([PYTHON, "tools/palcas_arms.py", "--list", "learning"], cwd=self.copy)
        self.assertNotIn(CONTROL_ARM, r.stdout.split())

    def test_run_and_experiment_take_it_without_a_policy(self):
        r = run([PYTHON, "tools/palcas_cli", "check", "run", "--arm", CONTROL_ARM, "--duration", "10"], cwd=self.copy)
        self.assertEqual(r.returncode, 0, r.stderr)  # good options: only the workspace is missing
        r = run([PYTHON, "tools/palcas_cli", "check", "train", "--arm", CONTROL_ARM], cwd=self.copy)
        self.assertEqual(r.returncode, 2, r.stderr)  # a rule learns nothing
        out = self.copy / "experiment"
        r = run([PYTHON, "tools/palcas_cli", "experiment", "--plan", "--out", str(out), "--arms", f"keep,{CONTROL_ARM}",
                 "--prs", "60", "--seeds", "1", "--duration", "10", "--scenario", "tiny"], cwd=self.copy)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn(f"{CONTROL_ARM}_pr60_s{seed_sets.seeds('test', 1)[0]}", (out / "plan.txt").read_text())

    def test_the_launch_starts_rule_rsus_under_the_learned_arms_actuation(self):
        env, launch = copy_launch_env(self, self.copy)
        r = run(["roslaunch", "--nodes", launch, f"arm:={CONTROL_ARM}", "out_dir:=/tmp/unused"], cwd=self.copy, env=env)
        self.assertEqual(sorted(r.stdout.split()), ["/palcas_sumo_bridge", "/rsu_0/rsu", "/rsu_1/rsu", "/rsu_2/rsu"],
                         r.stdout + r.stderr)  # no federation server: a rule learns nothing
        r = run(["roslaunch", "--dump-params", launch, f"arm:={CONTROL_ARM}", "out_dir:=/tmp/unused"],
                cwd=self.copy, env=env)
        lines = r.stdout.splitlines()
        for line in ("/rsu_0/rsu/rsu/advice: rules", "/rsu_0/rsu/rsu/train: false", "/rsu_0/rsu/i2i: true",
                     "/rsu_0/rsu/federation: false", "/rsu_0/rsu/rules/exit_distance_per_lane_m: 300.0",
                     "/palcas_sumo_bridge/advisory_control: true",
                     # the shipped policies' own bridge.yaml value: the same actuation
                     "/palcas_sumo_bridge/lane_change_max_accel_mps2: 1.47"):
            self.assertIn(line, lines, r.stderr)
        self.assertIn("/rsu_0/rsu/policy_dir: ''", lines)  # no weights asked for


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "arm_registry")
