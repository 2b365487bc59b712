#!/usr/bin/env python3
"""Tests of tools/palcas_cli (./palcas run, train, experiment, replay) without a simulation:
option checking and its messages, the dispatch's check, reading a console log (nodes that
died for good), the launch runner against a stand-in roslaunch (console shown and kept,
SIGINT passed on, a run whose node died is no result), and an experiment point run through
run's own functions, not through ./palcas.

usage: palcas_cli_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import contextlib
import io
import json
import os
import pathlib
import re
import shutil
import signal
import stat
import sys
import tempfile
import threading
import time
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
from palcas_cli import Console, commands, experiment, launch, options, replay, run, train  # noqa: E402
from palcas_cli.options import OptionError  # noqa: E402
import palcas_arms  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402

# A stand-in for roslaunch: says what a launch says, writes the bridge's metrics.json into
# out_dir:=, and with FAKE_DIES a node death; with FAKE_WAITS it runs until SIGINT. It notes
# the command line of the process that started it (setpriv execs it: its parent is ours).
FAKE_ROSLAUNCH = r"""#!/bin/bash
out=""
for a in "$@"; do case "$a" in out_dir:=*) out="${a#out_dir:=}" ;; esac; done
tr '\0' ' ' </proc/$PPID/cmdline >"$FAKE_NOTES/parent"
printf '%s\n' "$@" >"$FAKE_NOTES/args"
# Trap first: a test stops it once it has printed that SUMO started.
[ -z "${FAKE_WAITS:-}" ] || trap 'echo "[rsu_0/rsu-2] process has died [pid 9, exit code -2, cmd x]"; exit 0' INT
echo "... logging to $ROS_LOG_DIR (master $ROS_MASTER_URI)"
printf '\033[32mpalcas bridge: SUMO 1.15 started\033[0m\n'
if [ -n "${FAKE_WAITS:-}" ]; then
  while :; do sleep 0.05; done
fi
if [ -n "${FAKE_DIES:-}" ]; then
  echo "[rsu_0/rsu-2] process has died [pid 9, exit code 1, cmd x]"
  printf '\033[31m[FATAL] [12.5]: rsu: zone_m out of the road\033[0m\n'
fi
[ -z "$out" ] || printf '{"sim_seconds": %s, "efficiency_all_mps": 21.5, "cavs_seen": 12}\n' "${FAKE_SECONDS:-60}" >"$out/metrics.json"
echo "palcas bridge: episode 0 done"
"""


def given_fake_roslaunch(test):
    """PATH starts with a folder holding the stand-in roslaunch (undone after the test)."""
    folder = pathlib.Path(tempfile.mkdtemp(prefix="palcas_cli_test_"))
    fake = folder / "bin" / "roslaunch"
    fake.parent.mkdir()
    fake.write_text(FAKE_ROSLAUNCH)
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    saved = {k: os.environ.get(k) for k in ("PATH", "FAKE_NOTES", "FAKE_DIES", "FAKE_WAITS", "FAKE_SECONDS")}
    os.environ.update(PATH="%s:%s" % (fake.parent, os.environ["PATH"]), FAKE_NOTES=str(folder))

    def undo():
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        launch._stopping["signal"] = None  # a test that stopped its launches
        shutil.rmtree(folder, ignore_errors=True)
    test.addCleanup(undo)
    return folder


def refusal(call, *args):
    """The message of the OptionError that call(*args) raises."""
    try:
        call(*args)
    except OptionError as e:
        return str(e)
    raise AssertionError("no OptionError from %s%r" % (call.__name__, args))


class Options(unittest.TestCase):
    def test_numbers_come_in_normal_form(self):
        self.assertEqual(options.number_in("--pr", "60.0", 0, 100), "60")
        self.assertEqual(options.number_in("--duration", ".5", 0, None, open_low=True), "0.5")
        self.assertEqual(options.number_in("--pr", "0.123456789012", 0, 100), "0.123456789")
        self.assertEqual(options.integer_in("--seed", "007", 0, options.MAX_SEED), 7)
        self.assertEqual(options.range_in("--pr-range", "10.0,60", 0, 100), "10,60")

    def test_a_bad_value_is_named_with_its_range(self):
        for call, args, text in (
                (options.number_in, ("--pr", "150", 0, 100), "--pr '150': expected a number in [0, 100]"),
                (options.number_in, ("--pr", "1e2", 0, 100), "--pr '1e2': expected a number in [0, 100]"),
                (options.number_in, ("--duration", "0", 0, None, True), "--duration '0': expected a number greater than 0"),
                (options.number_in, ("--rate", "0", 0, 1000, True), "--rate '0': expected a number in (0, 1000]"),
                (options.integer_in, ("--episodes", "0", 1), "--episodes '0': expected an integer >= 1"),
                (options.integer_in, ("--seed", "-1", 0, 9), "--seed '-1': expected an integer in [0, 9]"),
                (options.range_in, ("--demand-range", "1000", 0, 100000),
                 "--demand-range '1000': expected MIN,MAX (two numbers in [0, 100000])"),
                (options.range_in, ("--pr-range", "10,200", 0, 100),
                 "--pr-range '10,200': MAX '200': expected a number in [0, 100]"),
                (options.range_in, ("--pr-range", "60,10", 0, 100), "--pr-range '60,10': MIN 60 is greater than MAX 10"),
                (options.sumo_outputs_ok, ("fcd,trips",), "--sumo-output 'trips': unknown SUMO output (known: fcd "),
                (options.sumo_outputs_ok, ("ssm,ssm",), "--sumo-output 'ssm': named twice"),
                (options.scenario_ok, ("--scenario", "nope"), "--scenario 'nope': no such road under config/scenarios ("),
                (options.file_ok, ("--v2x", "/nonexistent"), "--v2x '/nonexistent': no such file"),
                (options.policy_ok, ("--policy", "/nonexistent"), "--policy '/nonexistent': no such folder")):
            with self.subTest(args=args):
                self.assertIn(text, refusal(call, *args))

    def test_sumo_outputs_become_a_yaml_list(self):
        self.assertEqual(options.sumo_outputs_ok("fcd,ssm,"), "[fcd, ssm]")

    def test_the_option_loop(self):
        values, flags = {"--pr": "pr", "--out": "out", "--x": "x"}, {"--gui": ("gui", True)}
        self.assertEqual(options.parse("run", ["--pr", "5", "--gui", "--x", "a", "--x", "b"], values, flags,
                                       joined=("x",)), {"pr": "5", "gui": True, "x": "a,b"})
        self.assertEqual(options.parse("run", ["--pr", "5", "--pr", "6"], values), {"pr": "6"})
        self.assertEqual(refusal(options.parse, "run", ["--pr", "--gui"], values, flags), "option --pr needs a value")
        self.assertEqual(refusal(options.parse, "run", ["--out"], values), "option --out needs a value")
        self.assertEqual(refusal(options.parse, "run", ["bag"], values), "run: unknown option 'bag' (see ./palcas run --help)")
        self.assertEqual(refusal(options.parse, "run", ["--bogus=1"], values),
                         "run: unknown option '--bogus=1' (see ./palcas run --help)")
        self.assertEqual(refusal(options.parse, "run", ["--p", "5"], values), "run: unknown option '--p' (see ./palcas run --help)")
        words = []
        self.assertEqual(options.parse("replay", ["a.bag", "--pr", "5", "b.bag"], values, positional=words.append),
                         {"pr": "5"})
        self.assertEqual(words, ["a.bag", "b.bag"])
        self.assertEqual(refusal(options.parse, "replay", ["a.bag", "-x"], values, None, (), words.append),
                         "replay: unknown option '-x' (see ./palcas replay --help)")

    def test_an_option_takes_its_value_after_an_equals_sign(self):
        values, flags = {"--pr": "pr", "--demand": "demand"}, {"--gui": ("gui", True)}
        self.assertEqual(options.parse("run", ["--pr=40", "--gui", "--demand=-5"], values, flags),
                         {"pr": "40", "gui": True, "demand": "-5"})
        self.assertEqual(options.parse("run", ["--demand", "-5"], values), {"demand": "-5"})  # a value, not an option


class RunPlan(unittest.TestCase):
    """The arms of a run come from the registry and the policies it names."""

    def test_the_default_compares_the_shipped_policy_with_keep_and_sumo_native(self):
        p = run.check([])
        self.assertEqual(p.arms, ["palcas", "keep", "sumo_native"])
        self.assertEqual((p.policy, p.scenario, p.pr, p.seed, p.duration), (str(ROOT / "policies" / "palcas"),
                                                                            "paper", "60", 101, "1800"))

    def test_a_learning_arm_takes_its_shipped_policy(self):
        p = run.check(["--arm", "centralized", "--no-compare"])
        self.assertEqual((p.arms, p.policy), (["centralized"], str(ROOT / "policies" / "centralized")))
        self.assertEqual(run.check(["--arm", "keep", "--no-compare"]).arms, ["keep"])
        self.assertEqual(run.check(["--arm", "sumo_native"]).arms, ["keep", "sumo_native"])

    def test_unknown_arms_are_named_with_the_registrys_arms(self):
        self.assertEqual(refusal(run.check, ["--arm", "bogus"]),
                         "--arm 'bogus': unknown arm (%s)" % " | ".join(palcas_arms.ALL_ARMS))
        self.assertEqual(refusal(train.check, ["--arm", "bogus"]),
                         "--arm 'bogus': unknown arm (%s)" % " | ".join(palcas_arms.LEARNING_ARMS))
        self.assertIn("--arm keep: evaluation only", refusal(train.check, ["--arm", "keep"]))

    def test_a_policy_on_a_road_its_networks_do_not_fit_is_refused(self):
        self.assertIn("--scenario tiny: its state has 43 features, the shipped policy",
                      refusal(run.check, ["--scenario", "tiny"]))
        self.assertIn("arm 'keep' learns nothing", refusal(run.check, ["--arm", "keep", "--policy", "x"]))

    def test_the_command_line_is_recorded_as_typed(self):
        self.assertEqual(run.check(["--arm", "keep", "--pr", "40.0"]).command_line, "./palcas run --arm keep --pr 40.0")


class Dispatch(unittest.TestCase):
    def check(self, *argv):
        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            status = commands.main(["check"] + list(argv))
        return status, err.getvalue()

    def test_check_says_whether_the_command_needs_the_workspace(self):
        self.assertEqual(self.check("run", "--arm", "keep"), (commands.BUILD, ""))
        with tempfile.TemporaryDirectory() as d:
            self.assertEqual(self.check("experiment", "--plan", "--arms", "keep", "--out", d)[0], commands.NO_BUILD)
            self.assertFalse(os.path.exists(os.path.join(d, "plan.txt")), "check wrote the plan")

    def test_a_bad_option_exits_2_naming_it(self):
        self.assertEqual(self.check("run", "--pr", "150"), (2, "[palcas] error: --pr '150': expected a number in [0, 100]\n"))
        self.assertEqual(self.check("run", "--pr=150"), (2, "[palcas] error: --pr '150': expected a number in [0, 100]\n"))
        self.assertEqual(self.check("train", "--pr", "40", "--pr-range", "10,60"),
                         (2, "[palcas] error: --pr and --pr-range: give one of them\n"))
        self.assertEqual(self.check("train", "--episodes=0"), (2, "[palcas] error: --episodes '0': expected an integer >= 1\n"))
        status, err = self.check("experiment", "--arms", "keep,bogus", "--out", "/tmp/x")
        self.assertEqual((status, err.startswith("[palcas] error: --arms: unknown arm 'bogus'")), (2, True))
        self.assertEqual(self.check("experiment", "--out", "/tmp/x", "--seeds", "many"),
                         (2, "[palcas] error: experiment: argument --seeds: invalid int value: 'many' "
                             "(see ./palcas experiment --help)\n"))
        self.assertEqual(self.check("replay", "x.bag", "--bogus"),
                         (2, "[palcas] error: replay: unknown option '--bogus' (see ./palcas replay --help)\n"))
        self.assertEqual(self.check("replay", str(ROOT / "README.md"), "--accel-tolerance=tight", "--policy",
                                    str(ROOT / "policies" / "palcas")),
                         (2, "[palcas] error: --accel-tolerance 'tight': expected a number greater than 0\n"))
        self.assertEqual(self.check("bogus")[0], 2)

    def test_every_command_errs_with_one_prefix(self):
        for argv in (["run", "--bogus"], ["train", "--bogus"], ["experiment", "--bogus", "--out", "/tmp/x"],
                     ["replay", "x.bag", "--bogus"], ["run", "--pr"], ["experiment", "--arms", "keep"]):
            with self.subTest(argv=argv):
                status, err = self.check(*argv)
                self.assertEqual(status, 2)
                self.assertTrue(err.startswith("[palcas] error: "), err)
                self.assertEqual(err.count("\n"), 1, err)

    def test_an_option_value_after_an_equals_sign(self):
        self.assertEqual(self.check("run", "--arm=keep", "--pr=40"), (commands.BUILD, ""))
        self.assertEqual(run.check(["--arm=keep", "--pr=40", "--sumo-output=fcd", "--sumo-output=ssm"]).pr, "40")
        self.assertEqual(run.check(["--arm", "keep", "--pr=40"]).command_line, "./palcas run --arm keep --pr=40")
        opts = train.check(["--pr=40", "--episodes=2", "--demand-range=1000,1400"])[0]
        self.assertEqual((opts["pr"], opts["episodes"], opts["demand_range"]), (40.0, 2, [1000, 1400]))
        with tempfile.TemporaryDirectory() as d:
            self.assertEqual(self.check("experiment", "--plan", "--arms=keep", "--prs=40", "--out=" + d)[0],
                             commands.NO_BUILD)


class Help(unittest.TestCase):
    """--help of every command exits 0 and lists every option with its default; `check` with
    --help needs no build (./palcas then runs the command, which prints the help)."""
    # Every option of each command, and defaults its help must name.
    EXPERIMENT_OPTIONS = ("--out", "--plan", "--collect", "--point", "--arms", "--prs", "--demands", "--seeds",
                          "--seed-set", "--duration", "--scenario", "--v2x", "--rsu-params", "--bridge-params",
                          "--policy", "--jobs")
    DEFAULTS = {"run": {"--duration": "1800", "--pr": "60", "--seed": "101", "--arm": "palcas"},
                "train": {"--episodes": "5", "--duration": "3600", "--pr": "60", "--seed": "1",
                          "--explore-fraction": "0.5", "--arm": "palcas", "--scenario": "paper"},
                "experiment": {"--arms": "palcas,keep,sumo_native", "--prs": "5,10,20,40,60", "--seeds": "3",
                               "--seed-set": "test", "--duration": "1800", "--scenario": "paper"},
                "replay": {"--accel-tolerance": "0.001", "--rate": "1"}}

    def help_of(self, command):
        out = io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
            with self.assertRaises(SystemExit) as stop:
                commands.main([command, "--help"])
        self.assertIn(stop.exception.code, (0, None))
        return out.getvalue()

    @staticmethod
    def option_blocks(text):
        """{option: its lines of help} from argparse's options section."""
        blocks, current = {}, None
        for line in text.split("options:", 1)[1].splitlines():
            words = line.split()
            if line.startswith("  -") and words:
                current = words[-1 if words[0] == "-h," else 0].rstrip(",")
                blocks[current] = line
            elif current:
                blocks[current] += " " + line.strip()
        return blocks

    def options_of(self, command):
        if command == "experiment":
            return self.EXPERIMENT_OPTIONS
        module = {"run": run, "train": train, "replay": replay}[command]
        return tuple(module.VALUES) + tuple(module.FLAGS)

    def test_help_exits_0_and_lists_every_option_with_its_default(self):
        for command in commands.COMMANDS:
            with self.subTest(command=command):
                blocks = self.option_blocks(self.help_of(command))
                for option in self.options_of(command):
                    self.assertIn(option, blocks, "%s --help does not list %s" % (command, option))
                    self.assertIn("(default: ", blocks[option], "%s --help: %s has no default" % (command, option))
                for option, default in self.DEFAULTS[command].items():
                    self.assertRegex(blocks[option], r"\(default: [^)]*\b%s\b" % re.escape(default),
                                     "%s --help: %s" % (command, option))

    def test_check_with_help_builds_nothing(self):
        for command in commands.COMMANDS:
            with self.subTest(command=command):
                with contextlib.redirect_stdout(io.StringIO()):
                    self.assertEqual(commands.main(["check", command, "--help"]), commands.NO_BUILD)


class ConsoleLog(unittest.TestCase):
    def test_a_node_that_died_and_came_back_is_not_lost(self):
        text = ("[rsu_0/rsu-4] process has died [pid 1, exit code -9, cmd x]\n"
                "[rsu_0/rsu-4] restarting process\n")
        self.assertEqual(launch.node_deaths(text), [])

    def test_a_death_without_restart_or_a_crash_loop_is_lost(self):
        text = "\x1b[31m[rsu_1/rsu-5] process has died [pid 2, exit code 1, cmd x]\x1b[0m\n"
        loop = "".join("[fedserver-3] process has died [pid %d, exit code -6, cmd x]\n"
                       "[fedserver-3] restarting process\n" % k for k in range(3))
        self.assertEqual(launch.node_deaths(text + loop),
                         ["fedserver-3 (exit code -6, died 3 times)", "rsu_1/rsu-5 (exit code 1)"])

    def test_a_restart_cut_short_by_the_simulations_crash_is_not_lost(self):
        progress = "[ INFO] [1.0, 60.0]: palcas bridge: episode %d/3  t=  60/1200 s\n"
        killed = "[fedserver-2] process has died [pid 7, exit code -9, cmd x]\n"
        crash = "[palcas_sumo_bridge-1] process has died [pid 5, exit code -6, cmd x]\n"
        self.assertEqual(launch.node_deaths(progress % 2 + killed + crash, crashed_by="palcas_sumo_bridge"),
                         ["palcas_sumo_bridge-1 (exit code -6)"], "its restart was pending in the crashed episode")
        self.assertEqual(launch.node_deaths(progress % 2 + killed + crash), ["fedserver-2 (exit code -9)",
                         "palcas_sumo_bridge-1 (exit code -6)"], "without crashed_by as before")
        self.assertEqual(launch.node_deaths(progress % 1 + killed + progress % 2 + crash, crashed_by="palcas_sumo_bridge"),
                         ["fedserver-2 (exit code -9)", "palcas_sumo_bridge-1 (exit code -6)"],
                         "dead for a whole episode the simulation finished: lost")
        loop = "".join("[fedserver-2] process has died [pid %d, exit code -6, cmd x]\n"
                       "[fedserver-2] restarting process\n" % k for k in range(3))
        self.assertIn("fedserver-2 (exit code -6, died 3 times)",
                      launch.node_deaths(progress % 2 + loop + crash, crashed_by="palcas_sumo_bridge"))

    def test_a_clean_exit_is_not_a_death(self):
        self.assertEqual(launch.node_deaths("[rsu_0/rsu-4] process has died [pid 1, exit code 0, cmd x]\n"), [])

    def test_the_simulations_own_error_is_the_crash_reason(self):
        text = ("[rsu_0/rsu-4] process has died [pid 1, exit code -15, cmd x]\n"
                "sumo: MSVehicle.cpp:123: Assertion `myFurtherLanes.size() > 0' failed.\n")
        self.assertIn("myFurtherLanes", launch.crash_reason(text))
        self.assertIn("process has died", launch.crash_reason("[x] process has died [pid 1, exit code 1]"))
        self.assertEqual(launch.crash_reason("all fine"), "")
        self.assertIn("[FATAL]", launch.last_fatal("[ INFO] ok\n[FATAL] [1.0]: bad key\n"))

    def test_an_in_process_rsu_refused_at_start_is_named_once(self):
        # The bridge's FATAL for an RSU whose parameters it refused: every episode would repeat it.
        fatal = ("\x1b[31m[FATAL] [1795843404.68]: palcas bridge: in-process RSU 'rsu_0' (parameters under "
                 "/rsu_0/rsu): parameter '/rsu_0/rsu/rsu/gradient_steps_per_decision' = -1 is outside [0, 1000)\x1b[0m\n")
        self.assertEqual(launch.inprocess_refusals(fatal + fatal), ["rsu_0"])
        self.assertEqual(launch.inprocess_refusals("[FATAL] [1.0]: palcas bridge: in-process RSU 'rsu_2' not "
                                                   "registered: taken\n"), ["rsu_2"])
        # A SUMO abort or a warning that mentions in-process RSUs is no refusal.
        self.assertEqual(launch.inprocess_refusals("[ INFO] palcas bridge: 3 RSU(s) in process, answering by call\n"
                                                   "sumo: MSVehicle.cpp:1: Assertion `x' failed.\n"), [])


class MessageKey(unittest.TestCase):
    """launch/scripts/message_key, which system.launch runs by default and ./palcas calls."""

    def test_a_fresh_key_for_its_owner_only_kept_on_the_next_call(self):
        folder = pathlib.Path(tempfile.mkdtemp(prefix="palcas_key_")) / "run" / "nested"
        self.addCleanup(shutil.rmtree, folder.parents[1], True)
        path = launch.message_key(str(folder))
        self.assertEqual(path, str(folder / "auth.key"), "the path alone, no newline")
        text = pathlib.Path(path).read_text()
        self.assertRegex(text, r"^[0-9a-f]{64}$")
        self.assertEqual(stat.S_IMODE(os.stat(path).st_mode), 0o600)
        self.assertEqual(launch.message_key(str(folder)), path)
        self.assertEqual(pathlib.Path(path).read_text(), text, "an existing key is kept")
        other = pathlib.Path(tempfile.mkdtemp(prefix="palcas_key_"))
        self.addCleanup(shutil.rmtree, other, True)
        self.assertNotEqual(pathlib.Path(launch.message_key(str(other))).read_text(), text, "each run its own")

    def test_a_folder_it_cannot_write_is_an_error_naming_it(self):
        blocker = pathlib.Path(tempfile.mkdtemp(prefix="palcas_key_")) / "a_file"
        self.addCleanup(shutil.rmtree, blocker.parent, True)
        blocker.write_text("not a folder")
        with self.assertRaises(OSError) as caught:
            launch.message_key(str(blocker / "run"))
        self.assertIn("a_file", str(caught.exception))


class LaunchRunner(unittest.TestCase):
    """The runner against a stand-in roslaunch (no ROS needed)."""

    def setUp(self):
        self.notes = given_fake_roslaunch(self)
        self.out = pathlib.Path(tempfile.mkdtemp(prefix="palcas_cli_run_"))
        self.addCleanup(shutil.rmtree, self.out, True)

    def test_the_console_is_kept_whole_and_its_news_shown(self):
        shown = io.StringIO()
        lx = launch.Launch(["palcas_launch", "system.launch"], self.out / "console.log", self.out / "ros_log",
                           show=launch.SHOWN, shown=shown).start()
        self.assertEqual(lx.wait(), 0)
        self.assertEqual(shown.getvalue(), "palcas bridge: SUMO 1.15 started\npalcas bridge: episode 0 done\n")
        console = (self.out / "console.log").read_text()
        self.assertIn("logging to %s (master http://127.0.0.1:%d)" % (self.out / "ros_log", lx.port), console)
        self.assertIn("\x1b[32m", console)  # the log keeps what roslaunch wrote

    def test_a_master_that_lost_its_port_is_told_from_a_run_that_failed(self):
        console = self.out / "console.log"
        console.write_text("an earlier launch's lines: Address already in use, could not contact master\n")
        lx = launch.Launch(["palcas_launch", "system.launch"], console, self.out / "ros_log", append=True).start()
        lx.wait()
        self.assertFalse(lx.lost_its_port())  # only this launch's own lines count
        with open(console, "a") as f:
            f.write("OSError: [Errno 98] Address already in use\nRLException: ERROR: could not contact master "
                    "[http://127.0.0.1:%d/]\n" % lx.port)
        self.assertTrue(lx.lost_its_port())

    def test_sigint_reaches_the_launch_and_the_wait_says_interrupted(self):
        os.environ["FAKE_WAITS"] = "1"
        # As when ./palcas was started with '&' by a non-interactive shell (a CI runner):
        # SIGINT ignored on entry, which the launch must not inherit.
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            lx = launch.Launch(["x"], self.out / "console.log", self.out / "ros_log").start()
        finally:
            signal.signal(signal.SIGINT, previous)

        def stop_once_started():  # a loaded machine may take longer than any fixed delay
            console = self.out / "console.log"
            for _ in range(1200):  # up to 60 s: a CI machine running other jobs was slower than 20
                if console.exists() and "SUMO 1.15 started" in console.read_text():
                    break
                time.sleep(0.05)
            # The stand-in answers SIGINT after its current 0.05 s sleep; SIGKILL (which leaves
            # no "process has died") only if it has not after 30 s.
            launch.stop_all(grace_s=30)
        stopper = threading.Thread(target=stop_once_started)
        stopper.start()
        with self.assertRaises(launch.Interrupted) as e:
            lx.wait()
        stopper.join()
        self.assertEqual(e.exception.status, 130)
        self.assertFalse(lx.running())
        self.assertIn("process has died", (self.out / "console.log").read_text())  # it shut down itself

    def plan(self, *extra):
        return run.check(["--arm", "keep", "--no-compare", "--scenario", "tiny", "--duration", "60",
                          "--no-trajectories", "--out", str(self.out)] + list(extra))

    def test_a_run_gives_its_table(self):
        out, err = io.StringIO(), io.StringIO()
        self.assertEqual(run.execute(self.plan(), Console(out, err), show=None), 0)
        self.assertRegex(out.getvalue(), r"Efficiency, all vehicles \(m/s\) +21.50\n")
        self.assertIn("[palcas] keep -> %s/keep" % self.out, err.getvalue())
        args = (self.notes / "args").read_text().splitlines()
        for arg in ("system.launch", "arm:=keep", "duration:=60", "scenario:=tiny", "trajectory_period_steps:=0",
                    "auth_key_file:=%s/auth.key" % self.out, "command_line:=./palcas run --arm keep --no-compare "
                    "--scenario tiny --duration 60 --no-trajectories --out %s" % self.out):
            self.assertIn(arg, args)

    def test_a_run_whose_node_died_is_no_result(self):
        os.environ["FAKE_DIES"] = "1"
        out, err = io.StringIO(), io.StringIO()
        self.assertEqual(run.execute(self.plan(), Console(out, err), show=None), 1)
        self.assertEqual(out.getvalue(), "")  # no table
        self.assertIn("error: the keep run (seed 101, PR 60%) lost rsu_0/rsu-2 (exit code 1); last error: "
                      "[FATAL] [12.5]: rsu: zone_m out of the road", err.getvalue())
        self.assertTrue((self.out / "keep" / "metrics.invalid.json").is_file())
        self.assertFalse((self.out / "keep" / "metrics.json").exists())

    def test_an_experiment_point_runs_through_run_not_through_palcas(self):
        a = type("Args", (), dict(arms="keep", prs="60", seeds=1, duration=60.0, scenario="tiny", policy=None,
                                  demands=None, v2x="", jobs=1))
        settings = experiment.settings_from_args(a)
        experiment.save_settings(self.out, settings)
        self.assertEqual(experiment.run_point(self.out, "keep_pr60_s1001"), 0)
        record = json.loads((self.out / "points" / "keep_pr60_s1001" / "point.json").read_text())
        self.assertEqual(record["status"], "done")
        # From the repository's folder: its paths are repository-relative (point.json names no
        # folder of this machine), the point's own folder outside it stays absolute.
        self.assertTrue(record["command"].startswith("./palcas run --arm keep --no-compare --pr 60 --seed 1001"))
        self.assertIn("--out %s/points/keep_pr60_s1001" % self.out, record["command"])
        # roslaunch's parent is this process: no ./palcas (bash) in between.
        self.assertIn("palcas_cli_test.py", (self.notes / "parent").read_text())
        self.assertIn("[palcas] results:", (self.out / "points" / "keep_pr60_s1001" / "point.log").read_text())
        plan = experiment.points_of(settings)
        self.assertTrue(experiment.finished(self.out, plan[0], 60.0))


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "palcas_cli")
