#!/usr/bin/env python3
"""tools/diagnostics_view.py's table, without ROS.

usage: diagnostics_view_test.py [--xml FILE]   (JUnit XML for ./palcas test)"""
import pathlib
import sys
import unittest

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import diagnostics_view  # noqa: E402
from junit_runner import run_as_junit  # noqa: E402


class Table(unittest.TestCase):
    STATUSES = {
        "rsu_1/rsu: decisions": (1, "stale peers", [("step", "120"), ("stale peers", "1")]),
        "palcas_sumo_bridge: lockstep": (0, "all RSUs answer", [("late steps", "0")]),
    }

    def test_rows_by_name_with_level_message_and_values(self):
        text = diagnostics_view.table(self.STATUSES)
        lines = text.splitlines()
        self.assertEqual(lines[0].split("  ")[0], "palcas_sumo_bridge: lockstep")  # sorted by name
        self.assertIn("OK", lines[0])
        self.assertIn("late steps: 0", lines[1])
        self.assertTrue(lines[2].startswith("rsu_1/rsu: decisions") and "WARN" in lines[2] and "stale peers" in lines[2])
        self.assertEqual(len(lines), 5)

    def test_only_the_keys_asked_for(self):
        lines = diagnostics_view.table(self.STATUSES, keys={"step"}).splitlines()
        self.assertEqual(len(lines), 3)
        self.assertIn("step: 120", lines[2])

    def test_nothing_heard_and_an_unknown_level(self):
        self.assertEqual(diagnostics_view.table({}), "no /diagnostics heard yet\n")
        self.assertIn(" 7 ", diagnostics_view.table({"x": (7, "odd", [])}) + " ")


if __name__ == "__main__":
    run_as_junit(sys.modules[__name__], "diagnostics_view")
